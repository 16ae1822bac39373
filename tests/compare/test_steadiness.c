/* test_steadiness.c: the one definition of steady (steadiness.h): the drift
 * criterion on series worked out by hand, the monitor reader, and MSER-5. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>

#include "steadiness.h"
#include "test_util.h"

static void test_drift(void **state)
{
    (void)state;
    /* n = 8, q = 2: a = mean(v4, v5) = 1, b = mean(v6, v7) = 1.05; the first
     * half does not count. drift = 0.05 / (0.5 x 2.05) = 0.0487804..., 0.04878
     * to 4 digits */
    double v[9] = {9, 9, 9, 9, 1.0, 1.0, 1.05, 1.05, 0};
    cg_steadiness_verdict r = cg_steadiness_drift(v, 8, 0.05);
    assert_int_equal(r.samples, 8);
    assert_true(r.known);
    assert_true(r.drift == 0.04878);
    assert_true(r.steady);
    /* the verdict is on the 4-digit drift: 0.04878 <= 0.04878 although the
     * unrounded drift is above */
    assert_true(cg_steadiness_drift(v, 8, 0.04878).steady);
    assert_false(cg_steadiness_drift(v, 8, 0.04877).steady);
    /* fewer than 8 samples: no verdict */
    r = cg_steadiness_drift(v, 7, 0.05);
    assert_int_equal(r.samples, 7);
    assert_false(r.known);
    assert_false(r.steady);
    /* n = 9, q = 2: v5, v6 against v7, v8: a = 1.025, b = 0.525;
     * drift = 0.5 / (0.5 x 1.55) = 0.645161... -> 0.6452 */
    v[8] = 0.0;
    r = cg_steadiness_drift(v, 9, 0.05);
    assert_true(r.known);
    assert_true(r.drift == 0.6452);
    assert_false(r.steady);
    /* zero means: drift 0; a sign change: |b - a| / mean of |a| and |b| */
    double z[8] = {5, 5, 5, 5, 0, 0, 0, 0};
    r = cg_steadiness_drift(z, 8, 0.0);
    assert_true(r.known && r.drift == 0.0 && r.steady);
    double s[8] = {0, 0, 0, 0, -1, -1, 1, 1};
    r = cg_steadiness_drift(s, 8, 0.05);
    assert_true(r.drift == 2.0);
    double neg[12] = {0, 0, 0, 0, 0, 0, -2, -2, -2, -1, -1, -1}; /* q = 3 */
    r = cg_steadiness_drift(neg, 12, 1.0);
    assert_true(r.drift == 0.6667); /* 1 / (0.5 x 3) */
    assert_true(r.steady);
}

static void test_monitor_read(void **state)
{
    (void)state;
    char path[512];
    tmp_path(path, sizeof path, "monitor.txt");
    /* comments only at the start of a line; lines of fewer than 2 fields
     * do not count; blanks and tabs separate; CRLF is fine */
    write_text(path, "# step ke\n100 1.5\n\n7\n200\t2.5 x\r\n  300   3e0\n#400 9\n");
    double *v;
    size_t n;
    ekm_error err;
    assert_int_equal(cg_steadiness_monitor_read(path, 2, &v, &n, &err), EKM_OK);
    assert_int_equal(n, 3);
    assert_true(v[0] == 1.5 && v[1] == 2.5 && v[2] == 3.0);
    free(v);
    assert_int_equal(cg_steadiness_monitor_read(path, 1, &v, &n, &err), EKM_OK);
    assert_int_equal(n, 3); /* "7" alone is still left out (fewer than 2 fields) */
    assert_true(v[0] == 100 && v[1] == 200 && v[2] == 300);
    free(v);
    /* a data line (2 fields or more) without the column is bad input, not left out */
    assert_int_equal(cg_steadiness_monitor_read(path, 3, &v, &n, &err), EKM_EINPUT);
    assert_non_null(
        strstr(err.message, "monitor.txt:2: column 3: missing (expected at least 3 columns, got 2)"));
    write_text(path, "# step ke x\n100 1.5 1\n\n200\t2.5 x\r\n");
    assert_int_equal(cg_steadiness_monitor_read(path, 3, &v, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "monitor.txt:4: column 3: expected a finite number, got 'x'"));
    write_text(path, "1 2\n2 nan\n");
    assert_int_equal(cg_steadiness_monitor_read(path, 2, &v, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "monitor.txt:2: column 2: expected a finite number, got 'nan'"));
    assert_int_equal(cg_steadiness_monitor_read("/nonexistent/monitor.txt", 2, &v, &n, &err), EKM_EIO);
    assert_non_null(strstr(err.message, "/nonexistent/monitor.txt: cannot open"));
}

static void test_mser(void **state)
{
    (void)state;
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 2);
    double x[400];
    /* transient: exponential approach over ~60 samples, then noise */
    for (int i = 0; i < 400; i++)
        x[i] = 5.0 * exp(-i / 20.0) + gsl_ran_gaussian(r, 0.1);
    size_t k = cg_steadiness_mser(x, 400);
    assert_true(k >= 40 && k <= 150);
    for (int i = 0; i < 400; i++)
        x[i] = gsl_ran_gaussian(r, 0.1);
    assert_true(cg_steadiness_mser(x, 400) <= 100);
    assert_int_equal(cg_steadiness_mser(x, 7), 0);
    gsl_rng_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drift),
        cmocka_unit_test(test_monitor_read),
        cmocka_unit_test(test_mser),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
