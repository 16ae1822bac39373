/* The hypoplastic rate law (law/hypo.h): the homogeneous law
 * integrated with GSL odeiv2 (rk8pd, tight tolerances) as the reference,
 * against the closed forms of docs/model-notes.md sections 4 and 7 (thesis 6.2.2). */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>

#include "hypo.h"
#include "model.h"

typedef struct {
    ekm_material m;
    ekm_variant v;
    double phi, du_dz, dw_dz;
} law;

static int rhs(double t, const double y[], double dydt[], void *p)
{
    (void)t;
    const law *L = p;
    const ekm_hypo_stress s = {y[0], y[1], y[2], y[3]};
    const ekm_hypo_stress r = ekm_hypo_rate(&L->m, L->v, L->phi, &s, L->du_dz, L->dw_dz);
    dydt[0] = r.xx;
    dydt[1] = r.yy;
    dydt[2] = r.zz;
    dydt[3] = r.xz;
    return GSL_SUCCESS;
}

/* Integrate the homogeneous law for a time span at constant gradients. */
static void integrate(law *L, ekm_hypo_stress *s, double du_dz, double dw_dz, double span)
{
    L->du_dz = du_dz;
    L->dw_dz = dw_dz;
    const double PY = ekm_pressure_yield(&L->m, L->phi);
    gsl_odeiv2_system sys = {rhs, NULL, 4, L};
    gsl_odeiv2_driver *d =
        gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, span * 1e-6, 1e-14 * PY, 1e-13);
    assert_non_null(d);
    double y[4] = {s->xx, s->yy, s->zz, s->xz}, t = 0.0;
    assert_int_equal(gsl_odeiv2_driver_apply(d, &t, span, y), GSL_SUCCESS);
    gsl_odeiv2_driver_free(d);
    *s = (ekm_hypo_stress){y[0], y[1], y[2], y[3]};
}

static law thesis_law(ekm_variant v)
{
    gsl_set_error_handler_off();
    law L = {.m = ekm_material_thesis(), .v = v, .phi = 0.62};
    return L;
}

static ekm_hypo_stress isotropic(double p)
{
    return (ekm_hypo_stress){p, p, p, 0.0};
}

/* Uniaxial compression saturates at -P_Y (1 + R), both variants; the full
 * variant's state lies on the limit surface. */
static void test_compression_saturates(void **state)
{
    (void)state;
    for (int v = 0; v < 2; v++) {
        law L = thesis_law((ekm_variant)v);
        const double PY = ekm_pressure_yield(&L.m, L.phi), R = ekm_hypo_R(&L.m, L.v, L.phi);
        ekm_hypo_stress s = isotropic(-PY);
        integrate(&L, &s, 0.0, -1.0, 2e-4); /* strain 2e-4: about 80 e-foldings */
        const double target = -PY * (1.0 + R);
        const double err = fabs(s.zz / target - 1.0);
        const double fy = ekm_hypo_yield(&L.m, L.v, L.phi, &s);
        printf("%s: P_Y = %.6g Pa, R = %.6g, sigma_zz = %.10g Pa, -P_Y(1+R) = %.10g Pa, rel err %.2e, f_Y "
               "%.2e\n",
               v ? "thesis" : "full", PY, R, s.zz, target, err, fy);
        assert_true(err < 1e-6);
        assert_true(fabs(fy) < 1e-6);
        /* stays there under further compression */
        integrate(&L, &s, 0.0, -1.0, 1e-4);
        assert_true(fabs(s.zz / target - 1.0) < 1e-6);
    }
}

/* Loading stiffness A_h (1 + q/R), unloading A_h (1 - q/R), q = (sigma+P_Y)/P_Y
 * (thesis); after compression (q < 0) unloading is stiffer. */
static void test_unloading_stiffer(void **state)
{
    (void)state;
    law L = thesis_law(EKM_VARIANT_THESIS);
    const double PY = ekm_pressure_yield(&L.m, L.phi), R = ekm_hypo_R(&L.m, L.v, L.phi);
    ekm_hypo_stress s = isotropic(-PY);
    integrate(&L, &s, 0.0, -1.0, 2e-6); /* load part of the way to the limit */
    const double q = (s.zz + PY) / PY;
    assert_true(q < 0.0 && q > -R);
    const double k_load = ekm_hypo_rate(&L.m, L.v, L.phi, &s, 0.0, -1.0).zz / -1.0;
    const double k_unload = ekm_hypo_rate(&L.m, L.v, L.phi, &s, 0.0, 1.0).zz / 1.0;
    printf("thesis: q = %.4f: loading stiffness %.6g Pa, unloading %.6g Pa (A_h = %.3g)\n", q, k_load,
           k_unload, L.m.A_h);
    assert_true(fabs(k_load / (L.m.A_h * (1.0 + q / R)) - 1.0) < 1e-12);
    assert_true(fabs(k_unload / (L.m.A_h * (1.0 - q / R)) - 1.0) < 1e-12);
    assert_true(k_unload > k_load);
    /* the same from the integrated path: secant stiffness of a small increment */
    const double de = 1e-9;
    ekm_hypo_stress a = s, b = s;
    integrate(&L, &a, 0.0, -1.0, de);
    integrate(&L, &b, 0.0, 1.0, de);
    const double ks_load = (a.zz - s.zz) / -de, ks_unload = (b.zz - s.zz) / de;
    printf("thesis: secant stiffness over strain 1e-9: loading %.6g Pa, unloading %.6g Pa\n", ks_load,
           ks_unload);
    assert_true(ks_unload > ks_load);
    /* full variant: the axial stiffness, same statement */
    law F = thesis_law(EKM_VARIANT_FULL);
    ekm_hypo_stress sf = isotropic(-PY);
    integrate(&F, &sf, 0.0, -1.0, 2e-6);
    const double kf_load = -ekm_hypo_rate(&F.m, F.v, F.phi, &sf, 0.0, -1.0).zz;
    const double kf_unload = ekm_hypo_rate(&F.m, F.v, F.phi, &sf, 0.0, 1.0).zz;
    printf("full: loading stiffness %.6g Pa, unloading %.6g Pa\n", kf_load, kf_unload);
    assert_true(kf_unload > kf_load);
}

/* A strain cycle inside the limit surface (compress by e, extend by e).
 * The law is not elastic: from a generic start the stress ratchets, and
 * only the closed cycle of the law returns to its start.  For the thesis
 * law it is known in closed form: with k = A_h e/(R P_Y), the start
 * q0 = R tanh(k/2) (q = (sigma + P_Y)/P_Y) returns to itself. */
static void test_cycle_returns(void **state)
{
    (void)state;
    law L = thesis_law(EKM_VARIANT_THESIS);
    const double PY = ekm_pressure_yield(&L.m, L.phi), R = ekm_hypo_R(&L.m, L.v, L.phi);
    const double e = R * PY / L.m.A_h; /* k = 1 */
    const double q0 = R * tanh(0.5);
    ekm_hypo_stress s = isotropic(-PY * (1.0 - q0));
    const ekm_hypo_stress start = s;
    integrate(&L, &s, 0.0, -1.0, e);
    const double f_mid = ekm_hypo_yield(&L.m, L.v, L.phi, &s);
    integrate(&L, &s, 0.0, 1.0, e);
    const double ret = fabs(s.zz - start.zz) / fabs(start.zz);
    printf("thesis closed cycle: sigma %.12g -> %.12g Pa (f_Y at turn %.3f), relative change %.2e\n",
           start.zz, s.zz, f_mid, ret);
    assert_true(f_mid < 0.0);
    assert_true(ret < 1e-10);
    /* a generic start (sigma = -P_Y) does not return: ratcheting */
    ekm_hypo_stress g = isotropic(-PY);
    integrate(&L, &g, 0.0, -1.0, e);
    integrate(&L, &g, 0.0, 1.0, e);
    printf("thesis cycle from -P_Y: ends at %.6g P_Y (ratchets towards q0 = %.4f)\n", g.zz / PY, q0);
    assert_true(fabs(g.zz / -PY - 1.0) > 1e-2);
    /* full variant: repeated cycles shake down to a closed loop */
    law F = thesis_law(EKM_VARIANT_FULL);
    ekm_hypo_stress f = isotropic(-PY);
    double change = INFINITY;
    for (int c = 0; c < 40; c++) {
        const ekm_hypo_stress before = f;
        integrate(&F, &f, 0.0, -1.0, e);
        assert_true(ekm_hypo_yield(&F.m, F.v, F.phi, &f) < 0.0);
        integrate(&F, &f, 0.0, 1.0, e);
        change = fabs(f.zz - before.zz) / fabs(before.zz) + fabs(f.xx - before.xx) / fabs(before.xx);
    }
    printf("full: after 40 cycles the cycle changes the stress by %.2e relative\n", change);
    assert_true(change < 1e-9);
}

/* Simple shear at constant volume (full): the stress goes to the critical
 * state: on the limit surface with tr(sigma) = -3 P_Y. */
static void test_shear_critical_state(void **state)
{
    (void)state;
    law L = thesis_law(EKM_VARIANT_FULL);
    const double PY = ekm_pressure_yield(&L.m, L.phi);
    ekm_hypo_stress s = isotropic(-PY);
    integrate(&L, &s, 1.0, 0.0, 5e-4);
    const double fy = ekm_hypo_yield(&L.m, L.v, L.phi, &s);
    const double tr = s.xx + s.yy + s.zz;
    const double mu = fabs(s.xz) / PY, mu_exact = sqrt(3.0 * L.m.eta0 * L.m.eps0 / (2.0 * L.phi));
    printf(
        "full shear: sigma_xz/P_Y = %.10g (sqrt(3 eta0 eps0/(2 phi)) = %.10g), f_Y %.2e, tr/(3P_Y) %.10g\n",
        mu, mu_exact, fy, tr / (3 * PY));
    assert_true(fabs(fy) < 1e-6);
    assert_true(fabs(tr / (-3.0 * PY) - 1.0) < 1e-6);
    assert_true(fabs(mu / mu_exact - 1.0) < 1e-6); /* docs/model-notes.md section 7: the EKM's friction */
}

/* The stepper's linearly implicit step: fixed point exactly the limit
 * state, first-order convergence to the ODE solution. */
static void test_implicit_step(void **state)
{
    (void)state;
    for (int v = 0; v < 2; v++) {
        law L = thesis_law((ekm_variant)v);
        const double PY = ekm_pressure_yield(&L.m, L.phi), R = ekm_hypo_R(&L.m, L.v, L.phi);
        double err_prev = 0.0;
        for (int level = 0; level < 3; level++) {
            const int steps = 50 << level;
            const double span = 4e-6, dt = span / steps;
            ekm_hypo_stress s = isotropic(-PY);
            for (int i = 0; i < steps; i++) {
                const ekm_hypo_implicit c = ekm_hypo_prepare(&L.m, L.v, L.phi, dt, &s, 0.0, -1.0);
                s = ekm_hypo_finish(&c, s.xz, 0.0, -1.0);
            }
            ekm_hypo_stress ref = isotropic(-PY);
            integrate(&L, &ref, 0.0, -1.0, span);
            const double err = fabs(s.zz - ref.zz) / PY;
            printf("%s implicit step, %d steps: error %.3e P_Y\n", v ? "thesis" : "full", steps, err);
            if (level > 0)
                assert_true(err < 0.6 * err_prev);
            err_prev = err;
        }
        /* huge steps: stable, and the fixed point is the limit stress */
        ekm_hypo_stress s = isotropic(-PY);
        for (int i = 0; i < 200; i++) {
            const ekm_hypo_implicit c = ekm_hypo_prepare(&L.m, L.v, L.phi, 1e-3, &s, 0.0, -1.0);
            s = ekm_hypo_finish(&c, s.xz, 0.0, -1.0);
        }
        printf("%s implicit, dt = 1e-3 s: sigma_zz/(-P_Y(1+R)) - 1 = %.2e\n", v ? "thesis" : "full",
               s.zz / (-PY * (1 + R)) - 1);
        assert_true(fabs(s.zz / (-PY * (1.0 + R)) - 1.0) < 1e-10);
    }
}

/* Continuity: the EKM stress at its quasi-static temperature lies on the
 * limit surface (f_Y -> 0 as the rate -> 0), for compression, extension and
 * shear: this is what makes the switches continuous. */
static void test_flow_stress_on_limit_surface(void **state)
{
    (void)state;
    for (int v = 0; v < 2; v++) {
        law L = thesis_law((ekm_variant)v);
        const double cases[3][2] = {{0.0, -1e-3}, {0.0, 1e-3}, {1e-3, 0.0}};
        for (int k = 0; k < (v ? 2 : 3); k++) {
            const double du = cases[k][0], dw = cases[k][1];
            const double T = ekm_temperature_local_balance(&L.m, L.v, L.phi, du * du, dw * dw);
            const ekm_hypo_stress s = ekm_hypo_from_flow(&L.m, L.v, L.phi, T, du, dw);
            const double fy = ekm_hypo_yield(&L.m, L.v, L.phi, &s);
            printf("%s: u' = %g, w' = %g: T_qs = %.3e, f_Y of the EKM stress = %.2e\n", v ? "thesis" : "full",
                   du, dw, T, fy);
            assert_true(fabs(fy) < 1e-3);
        }
    }
}

/* The stepper's accuracy limit for solid cells, ekm_hypo_relaxation_rate,
 * is the relaxation of the linearly implicit step per unit time: dt times
 * it equals the largest of the step's relaxation factors (c_d deviatoric,
 * c_p or c_z volumetric, recovered from the prepared coefficients), for
 * compression, extension, shear and mixed rates in both variants; it is
 * linear in the rate, 0 at rest and 0 below phi_co (no plastic part). */
static void test_relaxation_rate(void **state)
{
    (void)state;
    const double rates[4][2] = {{0.0, -1.0}, {0.0, 0.5}, {2.0, 0.0}, {1.0, -0.3}};
    for (int v = 0; v < 2; v++) {
        law L = thesis_law((ekm_variant)v);
        const double PY = ekm_pressure_yield(&L.m, L.phi), dt = 1e-9;
        const double fdt = ekm_hypo_density_factor(&L.m, L.phi) * dt;
        const ekm_hypo_stress s = isotropic(-PY);
        for (int k = 0; k < 4; k++) {
            const double du = rates[k][0], dw = rates[k][1];
            const ekm_hypo_implicit c = ekm_hypo_prepare(&L.m, L.v, L.phi, dt, &s, du, dw);
            const double c_d = 1.0 / c.xz_scale - 1.0;
            double c_vol;
            if (L.v == EKM_VARIANT_THESIS) {
                c_vol = fdt * L.m.A_h / c.Vzz - 1.0;
            } else {
                const double Viso = c.Vxx + fdt * 2.0 * L.m.B_h / (3.0 * (1.0 + c_d));
                c_vol = fdt * (3.0 * L.m.A_h + 2.0 * L.m.B_h) / (3.0 * Viso) - 1.0;
            }
            const double r = ekm_hypo_relaxation_rate(&L.m, L.v, L.phi, du, dw);
            printf("%s: u' = %g, w' = %g: relaxation rate %.4e 1/s; step factors c_d %.4e, volumetric %.4e\n",
                   v ? "thesis" : "full", du, dw, r, c_d / dt, c_vol / dt);
            assert_true(r > 0.0);
            assert_true(fabs(r * dt / fmax(c_d, c_vol) - 1.0) < 1e-6);
            assert_true(fabs(ekm_hypo_relaxation_rate(&L.m, L.v, L.phi, 3.0 * du, 3.0 * dw) / (3.0 * r) -
                             1.0) < 1e-12);
        }
        assert_true(ekm_hypo_relaxation_rate(&L.m, L.v, L.phi, 0.0, 0.0) == 0.0);
        assert_true(ekm_hypo_relaxation_rate(&L.m, L.v, L.m.phi_co - 0.01, 1.0, -1.0) == 0.0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_compression_saturates), cmocka_unit_test(test_unloading_stiffer),
        cmocka_unit_test(test_cycle_returns),         cmocka_unit_test(test_shear_critical_state),
        cmocka_unit_test(test_implicit_step),         cmocka_unit_test(test_flow_stress_on_limit_surface),
        cmocka_unit_test(test_relaxation_rate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
