/* Numerical options: the TVD convection option and partial-slip walls. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
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
    const double balance =
        fabs(r.stats.mass_final - r.stats.mass_initial - r.stats.mass_in) / r.stats.mass_final;
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
    const char *sets[] = {"bottom.slip_length=0.005",
                          "top.slip_length=0.005",
                          "initial.phi=0.3",
                          "initial.T=1e-4",
                          "run.t_end=10",
                          "domain.cells=10",
                          set_rate,
                          set_u,
                          "top.pressure=none",
                          "run.stop=t_end"};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/shear_cell.ini", sets, 10, NULL, NULL), EKM_OK);
    double err = 0;
    for (int j = 1; j < r.s->n; j++)
        err = fmax(err, fabs((r.s->u[j] - r.s->u[j - 1]) / r.s->dz / gdot - 1));
    const double slip = r.s->u[0] - gdot * (0.5 * r.s->dz); /* u at the wall surface */
    printf("slip Couette: shear rate error %.2e, wall slip velocity %.4g (expected %.4g)\n", err, slip,
           gdot * b);
    assert_true(err < 1e-3);
    assert_true(fabs(slip / (gdot * b) - 1) < 1e-3);
    test_run_free(&r);
}

/* ekm_step_apply refuses a step that is not positive and finite (a hard
 * error in err, the state untouched), and takes a valid one. */
static void test_step_refuses_bad_dt(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, test_path("scenarios/chute.ini"), NULL, 0, &err), EKM_OK);
    ekm_state *s = ekm_state_alloc(sc.cells, sc.length);
    assert_non_null(s);
    ekm_stepper *st = ekm_step_alloc(&sc, &err);
    assert_non_null(st);
    ekm_state_init(s, &sc);
    const double bad[] = {0.0, -1e-3, NAN, INFINITY};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        int accepted = -1;
        ekm_error e = {0};
        assert_int_equal(ekm_step_apply(st, s, bad[k], &accepted, &e), EKM_ENUMERIC);
        assert_non_null(strstr(e.message, "chute.ini: t = 0 s: time step dt = "));
        assert_non_null(strstr(e.message, " s is not a positive finite number"));
        assert_int_equal(accepted, -1);
        assert_true(s->t == 0.0 && s->steps == 0);
    }
    int accepted = 0;
    assert_int_equal(ekm_step_apply(st, s, 1e-4, &accepted, &err), EKM_OK);
    assert_int_equal(accepted, 1);
    assert_true(s->t == 1e-4 && s->steps == 1);
    ekm_step_free(st);
    ekm_state_free(s);
    ekm_scenario_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tvd_front),
        cmocka_unit_test(test_slip_couette),
        cmocka_unit_test(test_step_refuses_bad_dt),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
