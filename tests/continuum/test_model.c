/* Constitutive functions against values computed by hand from docs/model-notes.md
 * section 2 (both variants, nu = 0.8 != 1), and the closed forms they
 * must satisfy. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>

#include "model.h"

static void assert_rel(double got, double want, double tol)
{
    double err = fabs(got - want) / fmax(fabs(want), 1e-300);
    if (!(err < tol))
        fail_msg("got %.12g, want %.12g (relative error %.3g > %.3g)", got, want, err, tol);
}

static ekm_material mat_nu08(void)
{
    ekm_material m = ekm_material_thesis();
    m.nu = 0.8;
    return m;
}

/* phi = 0.62 > phi_co (yield part on), T = 0.01 m^2/s^2, u' = 3/s, w' = -2/s. */
static void test_dense_state(void **state)
{
    (void)state;
    ekm_material m = mat_nu08();
    const double phi = 0.62, T = 0.01, du = 3.0, dw = -2.0;
    assert_rel(ekm_g(&m, phi), 32.0, 1e-12);
    assert_rel(ekm_pressure_kinetic(&m, phi, T), 317.44, 1e-12);
    assert_rel(ekm_pressure_yield(&m, phi), 1536.0, 1e-12);
    ekm_transport c = ekm_transport_coefficients(&m, EKM_VARIANT_FULL, phi, T);
    assert_rel(c.eta, 8.85347096774, 1e-10);
    assert_rel(c.zeta, 2.98941935484, 1e-10);
    assert_rel(c.lambda, 10.1640258065, 1e-10);
    assert_rel(c.eps, 7793.5483871, 1e-10);
    assert_rel(c.mu_n, 14.7940473118, 1e-10);
    ekm_slab_stress s = ekm_stress_slab(&m, EKM_VARIANT_FULL, phi, T, du, dw);
    assert_rel(s.sigma_xz, 26.5604129032, 1e-10);
    assert_rel(s.sigma_zz, -1883.02809462, 1e-10);
    assert_rel(s.P, 1859.41883871, 1e-10);
    assert_rel(ekm_temperature_source(&m, EKM_VARIANT_FULL, phi, T, du * du, dw * dw, NULL), -77219.4283814,
               1e-10);
    /* thesis variant: bulk viscosity only in the normal stress */
    ekm_transport ct = ekm_transport_coefficients(&m, EKM_VARIANT_THESIS, phi, T);
    assert_rel(ct.mu_n, 2.98941935484, 1e-10);
    ekm_slab_stress st = ekm_stress_slab(&m, EKM_VARIANT_THESIS, phi, T, du, dw);
    assert_rel(st.sigma_zz, -1859.41883871, 1e-10);
    assert_rel(st.P, 1859.41883871, 1e-10);
    assert_rel(ekm_temperature_source(&m, EKM_VARIANT_THESIS, phi, T, du * du, dw * dw, NULL), -77250.9073892,
               1e-10);
}

/* phi = 0.3 < phi_co (kinetic only), T = 0.04, u' = 5/s, w' = 1.5/s. */
static void test_dilute_state(void **state)
{
    (void)state;
    ekm_material m = mat_nu08();
    const double phi = 0.3, T = 0.04;
    assert_rel(ekm_pressure_kinetic(&m, phi, T), 36.1411764706, 1e-10);
    assert_true(ekm_pressure_yield(&m, phi) == 0.0);
    ekm_transport c = ekm_transport_coefficients(&m, EKM_VARIANT_FULL, phi, T);
    assert_rel(c.eta, 0.213835294118, 1e-10);
    assert_rel(c.eps, 188.235294118, 1e-10);
    assert_rel(c.lambda, 0.2048, 1e-10);
    ekm_slab_stress s = ekm_stress_slab(&m, EKM_VARIANT_FULL, phi, T, 5.0, 1.5);
    assert_rel(s.sigma_zz, -35.6231529412, 1e-10);
    assert_rel(s.P, 36.0508235294, 1e-10);
    assert_rel(ekm_temperature_source(&m, EKM_VARIANT_FULL, phi, T, 25.0, 2.25, NULL), -3610.03570196, 1e-10);
    assert_rel(ekm_temperature_source(&m, EKM_VARIANT_THESIS, phi, T, 25.0, 2.25, NULL), -3610.46337255,
               1e-10);
}

/* dS/dT against a centred difference; the precomputed-coefficient form
 * against the direct one. */
static void test_source_derivative(void **state)
{
    (void)state;
    ekm_material m = mat_nu08();
    const double cases[][4] = {{0.62, 0.01, 9.0, 4.0}, {0.3, 0.04, 25.0, 2.25}, {0.635, 1e-8, 1.0, 0.0}};
    for (int v = 0; v < 2; v++)
        for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            const double phi = cases[i][0], T = cases[i][1], u2 = cases[i][2], w2 = cases[i][3];
            double dS, dS2;
            double S = ekm_temperature_source(&m, (ekm_variant)v, phi, T, u2, w2, &dS);
            const double h = 1e-6 * T;
            double num = (ekm_temperature_source(&m, (ekm_variant)v, phi, T + h, u2, w2, NULL) -
                          ekm_temperature_source(&m, (ekm_variant)v, phi, T - h, u2, w2, NULL)) /
                         (2 * h);
            assert_rel(dS, num, 1e-6);
            ekm_source_coeffs c = ekm_temperature_source_coeffs(&m, (ekm_variant)v, phi, u2, w2);
            assert_rel(ekm_source_eval(&c, T, &dS2), S, 1e-12);
            assert_rel(dS2, dS, 1e-12);
        }
}

/* The local balance is a root of S, and equals the closed forms of
 * docs/model-notes.md section 7 for nu = 1: simple shear T = 2 eta0 gdot^2/(3 phi eps0)
 * at any phi; pure compression T = 2 (4/3 eta0 + zeta0) w'^2/(3 phi eps0). */
static void test_local_balance(void **state)
{
    (void)state;
    ekm_material m = ekm_material_thesis();
    const double gdot = 7.0;
    for (double phi = 0.2; phi < 0.635; phi += 0.05) {
        double T = ekm_temperature_local_balance(&m, EKM_VARIANT_FULL, phi, gdot * gdot, 0.0);
        assert_rel(T, 2 * m.eta0 * gdot * gdot / (3 * phi * m.eps0), 1e-12);
        double S = ekm_temperature_source(&m, EKM_VARIANT_FULL, phi, T, gdot * gdot, 0.0, NULL);
        double scale = m.rho_p * ekm_g(&m, phi) * phi * m.eps0 * pow(T, 1.5);
        assert_true(fabs(S) < 1e-9 * scale);
    }
    const double dw = 3.0, phi = 0.63;
    double T = ekm_temperature_local_balance(&m, EKM_VARIANT_FULL, phi, 0.0, dw * dw);
    assert_rel(T, 2 * (4.0 / 3.0 * m.eta0 + m.zeta0) * dw * dw / (3 * phi * m.eps0), 1e-12);
    T = ekm_temperature_local_balance(&m, EKM_VARIANT_THESIS, phi, 0.0, dw * dw);
    assert_rel(T, 2 * m.zeta0 * dw * dw / (3 * phi * m.eps0), 1e-12);
    /* nu != 1: still a root of S */
    ekm_material m8 = mat_nu08();
    T = ekm_temperature_local_balance(&m8, EKM_VARIANT_FULL, 0.62, 4.0, 1.0);
    double S = ekm_temperature_source(&m8, EKM_VARIANT_FULL, 0.62, T, 4.0, 1.0, NULL);
    assert_true(fabs(S) < 1e-9 * m8.rho_p * 32 * 0.62 * m8.eps0 * pow(T, 1.5) * 10);
}

/* The plane-strain law (the 2D solver's) reduces to the slab law when the
 * flow is uniform in x (e_xx = 0): the heating coefficients equal
 * ekm_temperature_source_coeffs_gY(u2, w2) and the normal stress equals
 * ekm_stress_slab's sigma_zz and P, for both variants, below and above
 * phi_co, to round-off (1e-13 relative); and a pure-shear plane rate
 * (e_xx = -e_zz) heats as 2 eta (e_xx^2 + e_zz^2) + 0 div^2 (full). */
static void test_plane_reduces_to_slab(void **state)
{
    (void)state;
    ekm_material m = ekm_material_thesis();
    m.nu = 0.7;
    const double phis[] = {0.3, 0.59, 0.62};
    const ekm_variant vs[] = {EKM_VARIANT_FULL, EKM_VARIANT_THESIS};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 2; b++) {
            const double phi = phis[a], T = 3e-3, du = 7.0, dw = -2.5;
            const double g = ekm_g(&m, phi), Y = ekm_yield_temperature(&m, phi);
            const ekm_source_coeffs s1 =
                ekm_temperature_source_coeffs_gY(&m, vs[b], phi, g, Y, du * du, dw * dw);
            const ekm_source_coeffs s2 =
                ekm_temperature_source_coeffs_plane(&m, vs[b], phi, g, Y, du * du, 0.0, dw);
            assert_true(fabs(s1.k_heat_a - s2.k_heat_a) <= 1e-13 * fabs(s1.k_heat_a));
            assert_true(fabs(s1.k_heat_y - s2.k_heat_y) <= 1e-13 * fabs(s1.k_heat_y) + 1e-300);
            assert_true(s1.k_diss == s2.k_diss && s1.nuY == s2.nuY);
            const ekm_cell_properties c = ekm_cell_properties_at(&m, vs[b], phi, T);
            const ekm_plane_stress ps = ekm_stress_plane(&c, vs[b], 0.0, dw);
            const ekm_slab_stress ss = ekm_stress_slab(&m, vs[b], phi, T, du, dw);
            assert_true(fabs(ps.szz - ss.sigma_zz) <= 1e-13 * fabs(ss.sigma_zz));
            assert_true(fabs(ps.P - ss.P) <= 1e-13 * fabs(ss.P));
            assert_true(fabs(-(ps.sxx + ps.szz + ps.syy) / 3.0 - ps.P) <= 1e-13 * fabs(ps.P));
        }
    /* pure shear e_xx = -e_zz = e: s2 = 4 e^2 (full), div = 0 */
    const double phi = 0.5, e = 3.0;
    const double g = ekm_g(&m, phi), Y = ekm_yield_temperature(&m, phi);
    const ekm_source_coeffs c =
        ekm_temperature_source_coeffs_plane(&m, EKM_VARIANT_FULL, phi, g, Y, 0.0, e, -e);
    const double want = m.rho_p * g * 2.0 / 3.0 * m.eta0 * 4.0 * e * e;
    assert_true(fabs(c.k_heat_a - want) <= 1e-13 * want);
}

static void test_material_check(void **state)
{
    (void)state;
    ekm_material m = ekm_material_thesis();
    ekm_error err;
    assert_int_equal(ekm_material_check(&m, &err), EKM_OK);
    m.phi_cp = -0.64;
    assert_int_equal(ekm_material_check(&m, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "phi_cp"));
    m = ekm_material_thesis();
    m.phi_co = 0.65;
    assert_int_equal(ekm_material_check(&m, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "phi_co"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dense_state),       cmocka_unit_test(test_dilute_state),
        cmocka_unit_test(test_source_derivative), cmocka_unit_test(test_local_balance),
        cmocka_unit_test(test_material_check),    cmocka_unit_test(test_plane_reduces_to_slab),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
