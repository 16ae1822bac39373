/* test_cell_properties: ekm_cell_properties_at (all of a cell's transport
 * coefficients in one call, model.h) equals the separate functions it
 * replaces in the time step, to round-off, over the whole range of phi
 * (dilute to 0.999 phi_cp) and T (1e-14 to 10 m^2/s^2), in both variants
 * (to 1e-14 + 1e-15 g: 1 - phi/phi_cp loses the digits g counts near
 * phi_cp);
 * and the temperature source from its g and Y equals the one that
 * computes them itself. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "model.h"

static double rel(double a, double b)
{
    const double scale = fmax(fabs(a), fabs(b));
    return scale > 0.0 ? fabs(a - b) / scale : 0.0;
}

static void properties_equal_the_separate_functions(void **state)
{
    (void)state;
    const ekm_material m = ekm_material_thesis();
    const ekm_variant variants[] = {EKM_VARIANT_FULL, EKM_VARIANT_THESIS};
    double worst = 0.0;
    long count = 0;
    for (int v = 0; v < 2; v++)
        for (int i = 0; i <= 200; i++) {
            /* phi from 1e-6 to 0.999 phi_cp, dense near phi_co and phi_cp */
            const double phi = i == 0 ? 1e-6 : m.phi_cp * (1.0 - pow(10.0, -3.0 * i / 200.0)) + 1e-6;
            for (int k = 0; k <= 60; k++) {
                const double T = pow(10.0, -14.0 + 15.0 * k / 60.0);
                const ekm_cell_properties c = ekm_cell_properties_at(&m, variants[v], phi, T);
                const ekm_transport t = ekm_transport_coefficients(&m, variants[v], phi, T);
                const double P = ekm_pressure_kinetic(&m, phi, T) + ekm_pressure_yield(&m, phi);
                const double Y = ekm_yield_temperature(&m, phi);
                const double d[] = {rel(c.g, ekm_g(&m, phi)), rel(c.Y, Y),
                                    rel(c.eta, t.eta),        rel(c.mu_n, t.mu_n),
                                    rel(c.lambda, t.lambda),  rel(c.P, P)};
                const double tol = 1e-14 + 1e-15 * ekm_g(&m, phi);
                for (size_t q = 0; q < sizeof d / sizeof d[0]; q++) {
                    if (d[q] > worst)
                        worst = d[q];
                    if (d[q] > tol)
                        fprintf(stderr,
                                "phi %.17g T %.3g variant %d quantity %zu: relative difference %.3g\n", phi,
                                T, v, q, d[q]);
                    assert_true(d[q] <= tol);
                }
                /* exactly zero below phi_co, as the separate functions */
                if (phi <= m.phi_co)
                    assert_true(c.Y == 0.0);
                count++;
            }
        }
    fprintf(stderr, "  %ld states: largest relative difference %.2e\n", count, worst);
}

static void source_from_g_and_Y_is_the_same(void **state)
{
    (void)state;
    const ekm_material m = ekm_material_thesis();
    for (int v = 0; v < 2; v++)
        for (int i = 1; i < 64; i++) {
            const double phi = 0.01 * i;
            const ekm_source_coeffs a = ekm_temperature_source_coeffs(&m, (ekm_variant)v, phi, 25.0, 4.0);
            const ekm_source_coeffs b = ekm_temperature_source_coeffs_gY(
                &m, (ekm_variant)v, phi, ekm_g(&m, phi), ekm_yield_temperature(&m, phi), 25.0, 4.0);
            assert_true(a.k_heat_a == b.k_heat_a && a.k_heat_y == b.k_heat_y && a.k_diss == b.k_diss &&
                        a.nuY == b.nuY);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(properties_equal_the_separate_functions),
        cmocka_unit_test(source_from_g_and_Y_is_the_same),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
