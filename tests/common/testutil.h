/* testutil.h: scratch directories and file helpers for the common/ tests. */
#ifndef EKM_COMMON_TESTUTIL_H
#define EKM_COMMON_TESTUTIL_H

#include <stddef.h>

/* A fresh, empty directory $EKM_TEST_TMPDIR/NAME (removed and recreated);
 * its path in out. 0 on success. */
int tu_fresh_dir(const char *name, char *out, size_t size);

/* Number of entries of dir whose name contains ".tmp." (temporaries). */
int tu_count_temporaries(const char *dir);

/* 1 when path exists. */
int tu_exists(const char *path);

/* The whole file as a NUL-terminated malloc'ed string (NULL on failure). */
char *tu_read_file(const char *path);

/* Write text to path; 0 on success. */
int tu_write_file(const char *path, const char *text);

/* Run fn() with stderr redirected into a malloc'ed string (returned). */
char *tu_capture_stderr(void (*fn)(void *), void *arg);

#endif
