/* The flow <-> solid switching rules (law/switching.h), one rule per
 * case, on the default [hypo] thresholds (scenario.c) and the material of
 * scenarios/settled_layer_2d's kind (phi_co 0.60, phi_cp 0.64). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "hypo.h"
#include "model.h"
#include "scenario.h"
#include "switching.h"

/* |a - b| <= tol (cmocka 1.1 has no double comparison) */
#define assert_close(a, b, tol) assert_true(fabs((a) - (b)) <= (tol))

static ekm_scenario defaults(void)
{
    ekm_scenario sc;
    ekm_scenario_init_defaults(&sc);
    sc.material.rho_p = 1600.0;
    sc.material.phi_co = 0.60;
    sc.material.phi_cp = 0.64;
    sc.material.T0 = 1.5;
    return sc;
}

/* Compression: tr < 0 with gamma / sqrt 2 <= -tr; rest: every rate <= rest_rate;
 * the slab's rates (exx = 0) give the same as the plane's. */
static void test_rates(void **state)
{
    (void)state;
    const ekm_scenario sc = defaults();
    const ekm_hypo_params *h = &sc.hypo;
    ekm_switch_rates r = ekm_switch_rates_of(h, 0.0, -1e-3, 1.4e-3);
    assert_true(r.compress); /* 1.4e-3 / sqrt 2 = 0.99e-3 <= 1e-3 */
    assert_false(r.at_rest);
    r = ekm_switch_rates_of(h, 0.0, -1e-3, 1.42e-3);
    assert_false(r.compress); /* 1.004e-3 > 1e-3 */
    r = ekm_switch_rates_of(h, -0.5e-3, -0.5e-3, 1.4e-3);
    assert_true(r.compress); /* the plane trace counts both */
    r = ekm_switch_rates_of(h, 2e-3, -1e-3, 0.0);
    assert_false(r.compress); /* the trace is positive */
    r = ekm_switch_rates_of(h, 0.5 * h->rest_rate, -h->rest_rate, h->rest_rate);
    assert_true(r.at_rest);
    assert_close(r.rate, h->rest_rate * 1.5, 1e-18);
    r = ekm_switch_rates_of(h, 1.01 * h->rest_rate, 0.0, 0.0);
    assert_false(r.at_rest); /* exx counts in the plane */
}

/* Loose below phi_co + phi_margin; a loose cell's Y is the solid cell's below. */
static void test_loose_and_yield_temperature(void **state)
{
    (void)state;
    ekm_scenario sc = defaults();
    const ekm_material *m = &sc.material;
    assert_true(ekm_switch_loose(m, &sc.hypo, 0.59));
    assert_true(ekm_switch_loose(m, &sc.hypo, 0.60));
    assert_false(ekm_switch_loose(m, &sc.hypo, 0.61));
    sc.hypo.phi_margin = 0.02;
    assert_true(ekm_switch_loose(m, &sc.hypo, 0.61));
    assert_close(ekm_switch_yield_temperature(m, 0, 0.62, 1, 0.61), ekm_yield_temperature(m, 0.62), 0.0);
    assert_close(ekm_switch_yield_temperature(m, 1, 0.55, 1, 0.61), ekm_yield_temperature(m, 0.61), 0.0);
    assert_close(ekm_switch_yield_temperature(m, 1, 0.55, 0, 0.61), 0.0, 0.0);
}

/* solid -> flow: empty goes; loose goes when unloaded or unsupported; a
 * dense cell is checked on the limit surface unless it compresses. */
static void test_to_flow(void **state)
{
    (void)state;
    const ekm_scenario sc = defaults();
    const ekm_hypo_params *h = &sc.hypo;
    const ekm_switch_rates shear = ekm_switch_rates_of(h, 0.0, 0.0, 1e-2);
    const ekm_switch_rates squeeze = ekm_switch_rates_of(h, 0.0, -1e-2, 0.0);
    assert_int_equal(ekm_switch_to_flow(h, 0, 0, 1e-3, -100.0, -1.0, &shear), EKM_SWITCH_GO);
    assert_int_equal(ekm_switch_to_flow(h, 1, 1, 1e-3, -100.0, NAN, &shear), EKM_SWITCH_STAY);
    assert_int_equal(ekm_switch_to_flow(h, 1, 1, 1e-3, 0.0, NAN, &shear), EKM_SWITCH_GO);
    assert_int_equal(ekm_switch_to_flow(h, 1, 1, 0.0, -100.0, NAN, &shear), EKM_SWITCH_GO);
    assert_int_equal(ekm_switch_to_flow(h, 1, 0, 1e-3, -100.0, -2.0 * h->yield_tol, &shear), EKM_SWITCH_STAY);
    assert_int_equal(ekm_switch_to_flow(h, 1, 0, 1e-3, -100.0, -0.5 * h->yield_tol, &shear),
                     EKM_SWITCH_CHECK);
    assert_int_equal(ekm_switch_to_flow(h, 1, 0, 1e-3, -100.0, 0.0, &squeeze), EKM_SWITCH_STAY);
    assert_true(ekm_switch_jump_passes(h, h->jump_tol));
    assert_false(ekm_switch_jump_passes(h, 2.0 * h->jump_tol));
}

/* flow -> solid: cold (T < T_ratio Y), dense enough, compressing or at
 * rest; at rest with growing rates only after the limit-surface check. */
static void test_to_solid(void **state)
{
    (void)state;
    const ekm_scenario sc = defaults();
    const ekm_hypo_params *h = &sc.hypo;
    const double Y = 1e-2, cold = 0.5 * h->T_ratio * Y, warm = 2.0 * h->T_ratio * Y;
    const ekm_switch_rates squeeze = ekm_switch_rates_of(h, 0.0, -1e-2, 0.0);
    const ekm_switch_rates rest = ekm_switch_rates_of(h, 0.0, 0.0, 0.5 * h->rest_rate);
    const ekm_switch_rates shear = ekm_switch_rates_of(h, 0.0, 0.0, 1e-2);
    assert_int_equal(ekm_switch_to_solid(h, 1, 0, Y, cold, 0.61, &squeeze, 1.0), EKM_SWITCH_GO);
    assert_int_equal(ekm_switch_to_solid(h, 1, 0, Y, warm, 0.61, &squeeze, 1.0), EKM_SWITCH_STAY);
    assert_int_equal(ekm_switch_to_solid(h, 1, 0, Y, cold, 0.61, &shear, 1.0), EKM_SWITCH_STAY);
    assert_int_equal(ekm_switch_to_solid(h, 0, 0, Y, cold, 0.61, &squeeze, 1.0), EKM_SWITCH_STAY);
    assert_int_equal(ekm_switch_to_solid(h, 1, 1, 0.0, cold, 0.55, &squeeze, 1.0), EKM_SWITCH_STAY);
    assert_int_equal(ekm_switch_to_solid(h, 1, 1, Y, cold, 0.5 * h->phi_loose, &squeeze, 1.0),
                     EKM_SWITCH_STAY);
    assert_int_equal(ekm_switch_to_solid(h, 1, 0, Y, cold, 0.61, &rest, 1.0), EKM_SWITCH_GO);
    assert_int_equal(ekm_switch_to_solid(h, 1, 0, Y, cold, 0.61, &rest, 0.0), EKM_SWITCH_CHECK);
    assert_int_equal(ekm_switch_to_solid(h, 1, 1, Y, cold, 0.55, &rest, 0.0), EKM_SWITCH_GO);
    assert_true(ekm_switch_inside_passes(h, -11.0 * h->yield_tol));
    assert_false(ekm_switch_inside_passes(h, -9.0 * h->yield_tol));
}

/* The T of a cell turning flow: T_qs when dense; when loose, the T whose
 * flow stress is its sigma_zz, never below T_floor. */
static void test_flow_temperature(void **state)
{
    (void)state;
    const ekm_scenario sc = defaults();
    const ekm_material *m = &sc.material;
    assert_close(ekm_switch_flow_temperature(m, sc.variant, 0, 0.61, -1e-3, -50.0, 3e-9, 1e-20), 3e-9, 0.0);
    const double T = ekm_switch_flow_temperature(m, sc.variant, 1, 0.55, -1e-3, -50.0, 3e-9, 1e-20);
    const double T_direct = ekm_hypo_flow_T_for_stress(m, sc.variant, 0.55, -1e-3, -50.0);
    assert_true(T_direct >= 0.0);
    assert_close(T, fmax(T_direct, 1e-20), 0.0);
    assert_true(ekm_switch_flow_temperature(m, sc.variant, 1, 0.55, -1e-3, -50.0, 3e-9, 1.0) >= 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rates),
        cmocka_unit_test(test_loose_and_yield_temperature),
        cmocka_unit_test(test_to_flow),
        cmocka_unit_test(test_to_solid),
        cmocka_unit_test(test_flow_temperature),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
