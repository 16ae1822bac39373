/* test_metric.c: the scoring metric (metric.h) on points worked out by
 * hand: which points count, the SE floor, and the two errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>

#include "metric.h"
#include "test_util.h"

/* Six candidates; the last two are out (a non-finite model or DEM value).
 * Counted: d = 4, 3, 0, 0 and m - d = -1, 0, 2, 0, so
 *   rel_l2 = sqrt((1 + 0 + 4 + 0) / (16 + 9 + 0 + 0)) = sqrt(1/5);
 * RMS(d) = sqrt(25/4) = 2.5, floor = 0.1 x 2.5 = 0.25: se = 0.5 and 1 count,
 * 0.25 (at the floor) and NaN do not, so
 *   noise = sqrt(((-1/0.5)^2 + (0/1)^2) / 2) = sqrt(2). */
static void test_hand_computed(void **state)
{
    (void)state;
    const double m[6] = {3.0, 3.0, 2.0, 0.0, NAN, 1.0};
    const double d[6] = {4.0, 3.0, 0.0, 0.0, 1.0, INFINITY};
    const double se[6] = {0.5, 1.0, 0.25, NAN, 1.0, 1.0};
    cg_metric r = cg_metric_compute(m, d, se, 6, 0.1);
    assert_int_equal(r.points, 4);
    assert_int_equal(r.points_se, 2);
    assert_close(r.se_floor, 0.25, 1e-15);
    assert_close(r.rel_l2, sqrt(0.2), 1e-15);
    assert_close(r.noise, sqrt(2.0), 1e-15);
    /* a lower floor lets the se = 0.25 point in: (2/0.25)^2 = 64 more */
    r = cg_metric_compute(m, d, se, 6, 0.01);
    assert_int_equal(r.points_se, 3);
    assert_close(r.noise, sqrt((4.0 + 0.0 + 64.0) / 3.0), 1e-14);
    /* a negative or zero SE never counts */
    const double se0[6] = {0.0, -1.0, 0.5, 0.5, 1.0, 1.0};
    r = cg_metric_compute(m, d, se0, 6, 0.0);
    assert_int_equal(r.points_se, 2);
    assert_close(r.noise, sqrt((16.0 + 0.0) / 2.0), 1e-14);
}

/* Undefined errors are NaN: no point at all, or a DEM field that is zero
 * everywhere (no relative error; the noise-normalised one still exists). */
static void test_undefined(void **state)
{
    (void)state;
    const double m[3] = {NAN, 1.0, 2.0};
    const double d[3] = {0.0, NAN, -INFINITY};
    const double se[3] = {1.0, 1.0, 1.0};
    cg_metric r = cg_metric_compute(m, d, se, 3, 1e-6);
    assert_int_equal(r.points, 0);
    assert_int_equal(r.points_se, 0);
    assert_true(isnan(r.rel_l2));
    assert_true(isnan(r.noise));
    assert_true(r.se_floor == 0.0);
    r = cg_metric_compute(m, d, se, 0, 1e-6);
    assert_int_equal(r.points, 0);
    const double m2[2] = {0.5, -0.5}, d2[2] = {0.0, 0.0}, se2[2] = {0.25, 0.5};
    r = cg_metric_compute(m2, d2, se2, 2, 1e-6);
    assert_int_equal(r.points, 2);
    assert_true(isnan(r.rel_l2));
    assert_int_equal(r.points_se, 2); /* the floor is 0: every positive SE counts */
    assert_close(r.noise, sqrt((4.0 + 1.0) / 2.0), 1e-15);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_computed),
        cmocka_unit_test(test_undefined),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
