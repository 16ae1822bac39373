/* test_kernel.c: kernel normalisation, width, walls and periodic wrap. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cg_keys.h"
#include "kernel.h"
#include "test_util.h"

static double weight_sum(const cg_kernel *k, const cg_grid *g, double s, double R)
{
    size_t bin[512];
    double w[512];
    size_t n = cg_kernel_weights(k, g, s, R, bin, w);
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += w[i] * g->dz;
    return sum;
}

static void test_normalised(void **state)
{
    (void)state;
    const char *names[] = {"gauss", "lucy", "bins"};
    cg_grid g = {.n = 100, .lo = 0.0, .hi = 0.1, .dz = 0.001, .periodic = 0, .reflect = 1};
    for (int i = 0; i < 3; i++) {
        cg_kernel *k;
        ekm_error err;
        assert_int_equal(cg_kernel_alloc(&k, names[i], 0.002, &err), EKM_OK);
        /* interior, near a wall (reflected), on the wall */
        double pos[] = {0.05, 0.0513, 0.001, 0.0999, 0.0};
        for (size_t j = 0; j < sizeof pos / sizeof *pos; j++)
            assert_close(weight_sum(k, &g, pos[j], 0.001), 1.0, 1e-12);
        /* periodic wrap */
        cg_grid gp = g;
        gp.periodic = 1;
        gp.reflect = 0;
        assert_close(weight_sum(k, &gp, 0.0005, 0.001), 1.0, 1e-12);
        assert_close(weight_sum(k, &gp, 0.1003, 0.001), 1.0, 1e-12);
        /* open ends: a kernel leaking out is cut */
        cg_grid go = g;
        go.reflect = 0;
        assert_true(weight_sum(k, &go, 0.0, 0.001) < 0.6);
        cg_kernel_free(k);
    }
}

/* Gaussian and Lucy have standard deviation w (Gaussian: of the cut one,
 * 0.9733 w); the sphere-slab kernel gives exact slice volumes. */
static void test_moments(void **state)
{
    (void)state;
    ekm_error err;
    cg_kernel *k;
    double w = 0.01;
    assert_int_equal(cg_kernel_alloc(&k, "lucy", w, &err), EKM_OK);
    double var = 0, h = 1e-5, prev = 0;
    for (double x = -0.05; x < 0.05; x += h) {
        double F = cg_kernel_cdf(k, x + h, 0), p = F - prev;
        var += p * (x + 0.5 * h) * (x + 0.5 * h);
        prev = F;
    }
    assert_close(sqrt(var), w, 1e-3 * w);
    cg_kernel_free(k);
    assert_int_equal(cg_kernel_alloc(&k, "gauss", w, &err), EKM_OK);
    assert_close(cg_kernel_cdf(k, 0, 0), 0.5, 1e-9);
    assert_close(cg_kernel_cdf(k, w, 0), (0.8413447460685429 - 0.0013498980316301) / 0.9973002039367398,
                 1e-7);
    cg_kernel_free(k);
    assert_int_equal(cg_kernel_alloc(&k, "bins", 0, &err), EKM_OK);
    /* sphere of radius 1 cut at its centre: half; cap of height 1/2 */
    assert_close(cg_kernel_cdf(k, 0.0, 1.0), 0.5, 1e-15);
    assert_close(cg_kernel_cdf(k, -0.5, 1.0), 0.25 * 2.5 / 4.0, 1e-15);
    cg_kernel_free(k);
    assert_int_equal(cg_kernel_alloc(&k, "tophat", w, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "expected gauss, lucy or bins"));
}

/* The kernels the cg options' table accepts (EKM_CG_KERNELS, what a
 * scenario's [compare] cg_options is checked against) are the ones
 * kernel.c makes, and the table refuses a name as kernel.c does. */
static void test_table_names_the_kernels(void **state)
{
    (void)state;
    char list[64];
    snprintf(list, sizeof list, "%s", EKM_CG_KERNELS);
    int n = 0;
    for (char *name = strtok(list, " "); name; name = strtok(NULL, " ")) {
        cg_kernel *k = NULL;
        ekm_error err = {0};
        assert_int_equal(cg_kernel_alloc(&k, name, 1e-3, &err), EKM_OK);
        cg_kernel_free(k);
        n++;
    }
    assert_int_equal(n, 3);
    const ekm_cg_key *key = ekm_cg_keys_find("--kernel");
    assert_non_null(key);
    ekm_cg_value v;
    ekm_error e1 = {0}, e2 = {0};
    assert_int_equal(ekm_cg_keys_parse(key, "tophat", &v, &e1), EKM_EUSAGE);
    cg_kernel *k = NULL;
    assert_int_equal(cg_kernel_alloc(&k, "tophat", 1e-3, &e2), EKM_EUSAGE);
    assert_string_equal(e1.message, e2.message);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_normalised),
        cmocka_unit_test(test_moments),
        cmocka_unit_test(test_table_names_the_kernels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
