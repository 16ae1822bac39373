/* test_util.h: helpers shared by the ekmcompare tests (header-only). */
#ifndef TEST_UTIL_H
#define TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

/* Path of a scratch file in the test's build directory. */
static inline const char *tmp_path(char *buf, size_t size, const char *name)
{
    const char *dir = getenv("CG_TMPDIR");
    snprintf(buf, size, "%s/%s", dir ? dir : "/tmp", name);
    return buf;
}

/* Write a string to a file; 0 on success. */
static inline int write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        return 1;
    fputs(text, fp);
    return fclose(fp);
}

/* |a - b| <= tol, with the values in the failure message. */
#define assert_close(a, b, tol)                                             \
    do {                                                                    \
        double a_ = (a), b_ = (b), t_ = (tol);                              \
        if (!(fabs(a_ - b_) <= t_))                                         \
            fail_msg("%s = %.10g, expected %.10g +- %.3g", #a, a_, b_, t_); \
    } while (0)

#endif
