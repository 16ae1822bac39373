/* Numerical options: the TVD convection option and partial-slip walls. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>

#include "testutil.h"

/* A cold inflow front (pure advection at w = -0.01 m/s, thesis 6.5.1
 * geometry, 60 cells) after 15 s: the exact profile is a step at
 * z = 0.3 - 0.15 m.  Second-order TVD must beat first-order upwind in L1
 * (measured 1.5e-3 vs 5.5e-3 m); both conserve mass. */
static double front_l1(const char *convection, const char *limiter)
{
    char set_c[64], set_l[64];
    snprintf(set_c, sizeof set_c, "numerics.convection=%s", convection);
    snprintf(set_l, sizeof set_l, "numerics.limiter=%s", limiter);
    const char *sets[] = {set_c, set_l, "top.T=1e-10", "run.t_end=15", "domain.cells=60"};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/thesis_kinetic_flow.ini", sets, 5, NULL, NULL), EKM_OK);
    double l1 = 0;
    for (int j = 0; j < r.s->n; j++)
        l1 += fabs(r.s->phi[j] - (r.s->z[j] > 0.15 ? 0.3 : 0.0)) * r.s->dz;
    const double balance = fabs(r.stats.mass_final - r.stats.mass_initial - r.stats.mass_in) / r.stats.mass_final;
    printf("front %s/%s: L1 error %.3e m, mass balance %.1e\n", convection, limiter, l1, balance);
    assert_true(balance < 1e-12);
    test_run_free(&r);
    return l1;
}

static void test_tvd_front(void **state)
{
    (void)state;
    const double upwind = front_l1("upwind", "vanleer");
    const char *limiters[] = {"minmod", "vanleer", "superbee", "mc"};
    for (int i = 0; i < 4; i++)
        assert_true(front_l1("tvd", limiters[i]) < 0.7 * upwind);
}

/* Couette flow with a Navier slip length b on both walls: the steady state
 * is homogeneous shear at gdot = V / (L + 2 b). */
static void test_slip_couette(void **state)
{
    (void)state;
    const double L = 0.042, V = 0.42, b = 0.005;
    const double gdot = V / (L + 2 * b);
    char set_rate[64], set_u[64];
    snprintf(set_rate, sizeof set_rate, "initial.shear_rate=%.17g", gdot);
    snprintf(set_u, sizeof set_u, "initial.u=%.17g", gdot * b);
    const char *sets[] = {"bottom.slip_length=0.005", "top.slip_length=0.005", "initial.phi=0.3", "initial.T=1e-4",
                          "run.t_end=10", "domain.cells=10", set_rate, set_u};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/shear_cell.ini", sets, 8, NULL, NULL), EKM_OK);
    double err = 0;
    for (int j = 1; j < r.s->n; j++)
        err = fmax(err, fabs((r.s->u[j] - r.s->u[j - 1]) / r.s->dz / gdot - 1));
    const double slip = r.s->u[0] - gdot * (0.5 * r.s->dz); /* u at the wall surface */
    printf("slip Couette: shear rate error %.2e, wall slip velocity %.4g (expected %.4g)\n", err, slip, gdot * b);
    assert_true(err < 1e-3);
    assert_true(fabs(slip / (gdot * b) - 1) < 1e-3);
    test_run_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tvd_front),
        cmocka_unit_test(test_slip_couette),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
