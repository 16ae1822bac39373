/* control.c: the step limit on states with a closed-form answer (acoustic,
 * compression, solid cells at rest, the restart step) and where a step must
 * end (inflow closing, tilt start, piston reversals, the next output). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "control.h"
#include "testutil.h"

static void assert_rel(double got, double want, const char *what)
{
    if (!(fabs(got - want) <= 1e-14 * fabs(want)))
        fail_msg("%s: got %.17g, want %.17g", what, got, want);
}

/* chute.ini with walls at both ends, no tilt, dt_max 0.5 s, and a uniform
 * state phi = 0.5, T = 1e-3 m^2/s^2 at rest. */
static ekm_state *uniform_state(ekm_scenario *sc)
{
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(sc, test_path("scenarios/chute.ini"), NULL, 0, &err), EKM_OK);
    sc->bottom = (ekm_bc){.kind = EKM_BC_WALL};
    sc->top = (ekm_bc){.kind = EKM_BC_WALL};
    sc->angle_rate = 0.0;
    sc->numerics.dt_max = 0.5;
    /* the acoustic limits below are the explicit coupling's (the implicit
     * coupling's limits: test_coupling.c) */
    sc->numerics.normal_coupling = EKM_COUPLING_EXPLICIT;
    ekm_state *s = ekm_state_alloc(sc->cells, sc->length);
    assert_non_null(s);
    ekm_state_init(s, sc);
    for (int j = 0; j < s->n; j++) {
        s->phi[j] = 0.5;
        s->T[j] = 1e-3;
        s->u[j] = 0.0;
        s->solid[j] = 0;
    }
    for (int f = 0; f <= s->n; f++)
        s->w[f] = 0.0;
    return s;
}

static void test_max_dt(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_state *s = uniform_state(&sc);
    const double c = sqrt(ekm_sound_speed_squared(&sc.material, 0.5, 1e-3));
    /* at rest: the acoustic step cfl dz / c */
    assert_rel(ekm_control_max_dt(&sc, s, NULL), fmin(sc.numerics.cfl * s->dz / c, sc.numerics.dt_max),
               "acoustic");
    /* face 3 moves up at 0.01 m/s: cell 3 compresses at -phi w' = 0.5 * 0.01/dz;
     * half of phi_step_max of its gap phi_cp - phi per step */
    s->w[3] = 0.01;
    const double rate = 0.5 * 0.01 / s->dz / (sc.material.phi_cp - 0.5);
    const double want =
        fmin(fmin(sc.numerics.cfl * s->dz / (0.01 + c), 0.5 * sc.numerics.phi_step_max / rate),
             sc.numerics.dt_max);
    printf("acoustic %.6g s, compression %.6g s, dt_max %.6g s\n", sc.numerics.cfl * s->dz / (0.01 + c),
           0.5 * sc.numerics.phi_step_max / rate, sc.numerics.dt_max);
    assert_rel(ekm_control_max_dt(&sc, s, NULL), want, "compression");
    ekm_state_free(s);
    ekm_scenario_free(&sc);
}

/* Solid cells at rest do not limit the step (their law's relaxation rate
 * is zero: dt_max), but the restart step after a change of the driving is
 * their acoustic one. */
static void test_solid_and_restart(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_state *s = uniform_state(&sc);
    sc.hypo.enabled = 1;
    for (int j = 0; j < s->n; j++)
        s->solid[j] = 1;
    const double c = sqrt(ekm_sound_speed_squared(&sc.material, 0.5, 1e-3));
    assert_rel(ekm_control_max_dt(&sc, s, NULL), sc.numerics.dt_max, "solid at rest");
    assert_rel(ekm_control_restart_dt(&sc, s), fmin(sc.numerics.cfl * s->dz / c, sc.numerics.dt_max),
               "restart");
    ekm_state_free(s);
    ekm_scenario_free(&sc);
}

static void check_target(const ekm_scenario *sc, double t, double t_out, double want, int want_event)
{
    int at_event = -1;
    const double got = ekm_control_target(sc, t, t_out, &at_event);
    if (!(fabs(got - want) <= 1e-15 * want) || at_event != want_event)
        fail_msg("target from t = %g s (next output %g s): got %.17g s, event %d; want %.17g s, event %d", t,
                 t_out, got, at_event, want, want_event);
}

static void test_targets(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_state *s = uniform_state(&sc);
    /* no events: the next output */
    check_target(&sc, 0.3, 1.0, 1.0, 0);
    /* the bottom inflow closes at 2 s, the top one at 2.5 s */
    sc.bottom = (ekm_bc){.kind = EKM_BC_INFLOW, .t_stop = 2.0};
    sc.top = (ekm_bc){.kind = EKM_BC_INFLOW, .t_stop = 2.5};
    check_target(&sc, 1.0, 3.0, 2.0, 1);
    check_target(&sc, 1.0, 1.5, 1.5, 0); /* the output comes first */
    check_target(&sc, 2.0, 3.0, 2.5, 1); /* at 2 s the first has passed */
    check_target(&sc, 2.5, 3.0, 3.0, 0);
    check_target(&sc, 1.0, 2.0, 2.0, 1); /* an output at the event: still an event */
    /* the base starts tilting at 5 s (only with a tilt rate) */
    sc.bottom = sc.top = (ekm_bc){.kind = EKM_BC_WALL};
    sc.angle_start = 5.0;
    check_target(&sc, 1.0, 10.0, 10.0, 0);
    sc.angle_rate = 0.1;
    check_target(&sc, 1.0, 10.0, 5.0, 1);
    check_target(&sc, 5.0, 10.0, 10.0, 0);
    /* a piston of period 2 s reverses every second */
    sc.angle_rate = 0.0;
    sc.top = (ekm_bc){.kind = EKM_BC_PISTON, .w = 0.01, .period = 2.0, .w_return = NAN};
    check_target(&sc, 0.3, 10.0, 1.0, 1);
    check_target(&sc, 1.0, 10.0, 2.0, 1);
    check_target(&sc, 1.2, 1.5, 1.5, 0);
    ekm_state_free(s);
    ekm_scenario_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_max_dt),
        cmocka_unit_test(test_solid_and_restart),
        cmocka_unit_test(test_targets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
