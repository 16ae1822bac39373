/* test_stats.c: block store, blocking standard errors (AR(1) series with a
 * known answer) and the MSER-5 steady-state start. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>

#include "stats.h"
#include "test_util.h"

static void test_blocks(void **state)
{
    (void)state;
    cg_blocks *b;
    ekm_error err;
    assert_int_equal(cg_blocks_alloc(&b, 1, 8, &err), EKM_OK);
    for (int i = 1; i <= 37; i++) {
        double x = i;
        cg_blocks_add(b, &x);
    }
    /* 37 snapshots, at most 8 blocks: the 36th completes a 9th block of 4,
     * so the store merges into 4 blocks of 8 (32 snapshots); 33..37 are the
     * current, incomplete block */
    assert_int_equal(b->bsize, 8);
    assert_int_equal(b->nblocks, 4);
    assert_int_equal(b->ncur, 5);
    double m;
    cg_blocks_mean(b, &m);
    assert_close(m, 19.0, 1e-12);
    cg_blocks_block_mean(b, 0, &m);
    assert_close(m, 4.5, 1e-12);
    cg_blocks_block_mean(b, 3, &m);
    assert_close(m, 28.5, 1e-12);
    cg_blocks_free(b);
}

/* AR(1) x_t = a x_{t-1} + e: SE of the mean = sigma_x sqrt((1+a)/(1-a)/N).
 * Blocking must find it (within 25%) where the naive SE is 3x too small. */
static void test_se_ar1(void **state)
{
    (void)state;
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 1);
    const size_t N = 1 << 16;
    const double a = 0.8;
    cg_blocks *b;
    ekm_error err;
    assert_int_equal(cg_blocks_alloc(&b, 1, 64, &err), EKM_OK);
    double x = 0;
    double ses[20];
    for (int rep = 0; rep < 20; rep++) {
        cg_blocks_reset(b);
        for (size_t t = 0; t < N; t++) {
            x = a * x + gsl_ran_gaussian(r, 1.0);
            cg_blocks_add(b, &x);
        }
        double v[64], work[64];
        for (size_t j = 0; j < b->nblocks; j++)
            cg_blocks_block_mean(b, j, &v[j]);
        ses[rep] = cg_stats_se(v, b->nblocks, work);
    }
    double mean = 0;
    for (int rep = 0; rep < 20; rep++)
        mean += ses[rep] / 20;
    double sx = 1.0 / sqrt(1 - a * a), exact = sx * sqrt((1 + a) / (1 - a) / (double)N);
    assert_close(mean, exact, 0.25 * exact);
    /* NAN blocks are skipped, fewer than 2 values give NAN */
    double v2[3] = {1.0, NAN, 3.0}, w2[3];
    assert_close(cg_stats_se(v2, 3, w2), 1.0, 1e-12);
    assert_true(isnan(cg_stats_se(v2, 1, w2)));
    cg_blocks_free(b);
    gsl_rng_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blocks),
        cmocka_unit_test(test_se_ar1),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
