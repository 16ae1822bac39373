/* implicit.c: the tridiagonal solves against known solutions (the
 * right-hand side built from the documented equation, implicit.h, and a
 * chosen solution, which the solve must return to round-off), and singular
 * systems refused with an error rather than a NaN. */
#include <gsl/gsl_errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "implicit.h"

#define N 7

static void assert_solution(const double *got, const double *want, int from, int to, const char *what)
{
    for (int i = from; i <= to; i++)
        if (!(fabs(got[i] - want[i]) <= 1e-13 * fmax(1.0, fabs(want[i]))))
            fail_msg("%s, unknown %d: got %.17g, want %.17g", what, i, got[i], want[i]);
}

/* Shear solve with face stresses:
 *   rho_j u_j - dt/dz (tau_{j+1} - tau_j) = rhs_j,  tau_f = k_f (u_f - u_{f-1}) + t0_f,
 *   tau_0 = k_0 (u_0 - u_wall_bottom) + t0_0,  tau_n = k_n (u_wall_top - u_{n-1}) + t0_n. */
static void test_shear_faces_known_solution(void **state)
{
    (void)state;
    const double dt = 0.01, dz = 0.05, ub = 0.3, ut = -0.2;
    double rho[N], k[N + 1], t0[N + 1], u_exact[N], rhs[N], u[N], tau[N + 1];
    unsigned char dry[N] = {0};
    for (int j = 0; j < N; j++) {
        rho[j] = 1000.0 + 150.0 * j;
        u_exact[j] = sin(0.7 * j) + 0.1 * j;
    }
    for (int f = 0; f <= N; f++) {
        k[f] = 2e4 * (1.0 + 0.3 * f * f); /* a stiff solid-like face: dt k / (dz rho) ~ 5-60 */
        t0[f] = 50.0 * cos(f);
    }
    tau[0] = k[0] * (u_exact[0] - ub) + t0[0];
    tau[N] = k[N] * (ut - u_exact[N - 1]) + t0[N];
    for (int f = 1; f < N; f++)
        tau[f] = k[f] * (u_exact[f] - u_exact[f - 1]) + t0[f];
    for (int j = 0; j < N; j++)
        rhs[j] = rho[j] * u_exact[j] - dt / dz * (tau[j + 1] - tau[j]);
    ekm_implicit_work *wk = ekm_implicit_alloc(N);
    assert_non_null(wk);
    ekm_error err = {0};
    assert_int_equal(ekm_implicit_shear_faces(wk, N, dt, dz, rho, rhs, k, t0, dry, ub, ut, u, &err), EKM_OK);
    assert_solution(u, u_exact, 0, N - 1, "shear faces");
    ekm_implicit_free(wk);
}

/* The vacuum rule's heating (ekm_implicit_vapour_heating): below
 * phi_vacuum a cell's local balance temperature (S = 0) under a given
 * strain rate is that of a cell at phi_vacuum (the kinetic heating does not
 * fall with phi, the dissipation does: without the rule it grows as
 * 1/phi); at or above phi_vacuum, and with phi_vacuum = 0, the
 * coefficients are untouched.  The thesis material, below phi_co (no
 * yield terms), simple shear 50 1/s with a compression of 5 1/s. */
static void test_temperature_vapour_heating(void **state)
{
    (void)state;
    const ekm_material m = ekm_material_thesis();
    const double vac = 0.05;
    const ekm_variant variants[2] = {EKM_VARIANT_THESIS, EKM_VARIANT_FULL};
    for (int v = 0; v < 2; v++) {
        ekm_source_coeffs at =
            ekm_temperature_source_coeffs_plane(&m, variants[v], vac, ekm_g(&m, vac), 0.0, 2500.0, -5.0, 0.0);
        ekm_implicit_vapour_heating(&at, vac, vac);
        const double T_vac = ekm_source_balance(&at);
        assert_true(T_vac > 0.0);
        const double phis[] = {1e-6, 2e-4, 1e-3, 0.02, 0.0499, 0.05, 0.3};
        for (size_t k = 0; k < sizeof phis / sizeof *phis; k++) {
            const double phi = phis[k];
            const ekm_source_coeffs raw = ekm_temperature_source_coeffs_plane(
                &m, variants[v], phi, ekm_g(&m, phi), 0.0, 2500.0, -5.0, 0.0);
            ekm_source_coeffs off = raw, on = raw;
            ekm_implicit_vapour_heating(&off, phi, 0.0);
            ekm_implicit_vapour_heating(&on, phi, vac);
            assert_memory_equal(&off, &raw, sizeof raw);
            if (phi >= vac) {
                assert_memory_equal(&on, &raw, sizeof raw);
                continue;
            }
            const double T_raw = ekm_source_balance(&raw), T_on = ekm_source_balance(&on);
            if (!(fabs(T_on - T_vac) <= 1e-12 * T_vac))
                fail_msg("phi %g: balance T %.17g with the rule, want phi_vacuum's %.17g", phi, T_on, T_vac);
            if (!(fabs(T_raw * phi / vac - T_vac) <= 1e-12 * T_vac))
                fail_msg("phi %g: balance T %.17g without the rule, want %.17g x phi_vacuum/phi", phi, T_raw,
                         T_vac);
        }
    }
}

/* Temperature, conduction only (no source), adiabatic ends: a dense bed
 * (cells 0-1, phi 0.6, T 1e-8 m^2/s^2) under a hot dilute vapour (cells
 * 2-3, phi 0.01, T 1e-3), every lambda 1 kg/(m s).  Without the vacuum
 * rule heat flows into the bed and sum rho T is conserved; with
 * phi_vacuum = 0.05 the face between bed and vapour conducts nothing:
 * each part keeps its T. */
static void test_temperature_vacuum_insulates(void **state)
{
    (void)state;
    enum { M = 4 };
    const double rho_p = 1600.0, dt = 1e-3, dz = 2.5e-3;
    const double phi[M] = {0.6, 0.6, 0.01, 0.01}, T0[M] = {1e-8, 1e-8, 1e-3, 1e-3}, lambda[M] = {1, 1, 1, 1};
    double rhoT[M], T[M];
    ekm_source_coeffs src[M];
    memset(src, 0, sizeof src);
    unsigned char dry[M] = {0};
    double energy = 0.0;
    for (int j = 0; j < M; j++) {
        rhoT[j] = rho_p * phi[j] * T0[j];
        energy += rhoT[j];
    }
    ekm_implicit_work *wk = ekm_implicit_alloc(M);
    assert_non_null(wk);
    ekm_error err = {0};
    for (int rule = 0; rule < 2; rule++) {
        memcpy(T, T0, sizeof T);
        int its = 0;
        assert_int_equal(ekm_implicit_temperature(wk, M, dt, dz, rho_p, phi, rhoT, lambda, src, dry,
                                                  rule ? 0.05 : 0.0, 1e-16, 1e-12, 20, T, &its, &err),
                         EKM_OK);
        double e = 0.0;
        for (int j = 0; j < M; j++)
            e += rho_p * phi[j] * T[j];
        if (!(fabs(e - energy) <= 1e-12 * energy))
            fail_msg("vacuum rule %d: sum rho T %.17g, want %.17g", rule, e, energy);
        if (rule) {
            for (int j = 0; j < M; j++)
                if (!(fabs(T[j] - T0[j]) <= 1e-12 * T0[j]))
                    fail_msg("vacuum rule: cell %d: T %.17g, want %.17g (each part keeps its T)", j, T[j],
                             T0[j]);
        } else if (!(T[1] > 100.0 * T0[1])) {
            fail_msg("no vacuum rule: the bed's top cell should heat (T %.3g from %.3g)", T[1], T0[1]);
        }
    }
    ekm_implicit_free(wk);
}

/* Normal solve: rho_f w_f - dt/dz^2 (mu_f (w_{f+1} - w_f) - mu_{f-1} (w_f - w_{f-1})) = rhs_f
 * at the interior faces, mu_j the viscosity of cell j (between faces j and
 * j+1), w_0 and w_n prescribed. */
static void test_normal_velocity_known_solution(void **state)
{
    (void)state;
    const double dt = 0.02, dz = 0.1;
    double rho[N + 1], mu[N], w_exact[N + 1], rhs[N + 1], w[N + 1];
    unsigned char dry_face[N + 1] = {0};
    for (int f = 0; f <= N; f++) {
        rho[f] = 800.0 + 40.0 * f;
        w_exact[f] = 0.05 * cos(0.9 * f) - 0.01 * f;
    }
    for (int j = 0; j < N; j++)
        mu[j] = 300.0 + 1e3 * j; /* dt mu / (dz^2 rho) ~ 1-10 */
    for (int f = 1; f < N; f++)
        rhs[f] = rho[f] * w_exact[f] -
                 dt / (dz * dz) *
                     (mu[f] * (w_exact[f + 1] - w_exact[f]) - mu[f - 1] * (w_exact[f] - w_exact[f - 1]));
    const ekm_implicit_end bottom = {.follows = 0, .value = w_exact[0]};
    const ekm_implicit_end top = {.follows = 0, .value = w_exact[N]};
    ekm_implicit_work *wk = ekm_implicit_alloc(N);
    assert_non_null(wk);
    ekm_error err = {0};
    assert_int_equal(
        ekm_implicit_normal_velocity(wk, N, dt, dz, rho, rhs, mu, dry_face, bottom, top, NULL, w, &err),
        EKM_OK);
    assert_solution(w, w_exact, 0, N, "normal velocity");
    ekm_implicit_free(wk);
}

/* A massless layer (rho = 0) held by no wall (k_0 = k_n = 0): only the
 * differences of u are fixed, the system is singular.  Refused with
 * EKM_ENUMERIC naming the solve; u is left as it was (no NaN). */
static void test_singular_refused(void **state)
{
    (void)state;
    const double dt = 0.01, dz = 0.05;
    double rho[N] = {0}, rhs[N] = {0}, k[N + 1], t0[N + 1] = {0}, u[N];
    unsigned char dry[N] = {0};
    for (int f = 0; f <= N; f++)
        k[f] = f == 0 || f == N ? 0.0 : 1e3;
    for (int j = 0; j < N; j++)
        u[j] = 0.5;
    ekm_implicit_work *wk = ekm_implicit_alloc(N);
    assert_non_null(wk);
    ekm_error err = {0};
    assert_int_equal(ekm_implicit_shear_faces(wk, N, dt, dz, rho, rhs, k, t0, dry, 0.0, 0.0, u, &err),
                     EKM_ENUMERIC);
    printf("singular %d x %d: %s\n", N, N, err.message);
    assert_non_null(strstr(err.message, "shear momentum: tridiagonal solve failed"));
    for (int j = 0; j < N; j++)
        assert_true(u[j] == 0.5);
    /* one cell without walls: the 1x1 system 0 u = 0 */
    const double k1[2] = {0.0, 0.0};
    ekm_error err1 = {0};
    assert_int_equal(ekm_implicit_shear_faces(wk, 1, dt, dz, rho, rhs, k1, t0, dry, 0.0, 0.0, u, &err1),
                     EKM_ENUMERIC);
    assert_string_equal(err1.message, "shear momentum: singular 1x1 system");
    assert_true(u[0] == 0.5);
    ekm_implicit_free(wk);
}

int main(void)
{
    gsl_set_error_handler_off(); /* as the programs do: GSL's default handler aborts */
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shear_faces_known_solution),
        cmocka_unit_test(test_normal_velocity_known_solution),
        cmocka_unit_test(test_singular_refused),
        cmocka_unit_test(test_temperature_vacuum_insulates),
        cmocka_unit_test(test_temperature_vapour_heating),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
