/* ekm_homog_shear (law/homogeneous.c) against the closed forms of
 * docs/model-notes.md section 7 (nu = 1 and general nu, both variants, below and
 * above phi_co), and against the solver's steady state of a wall-driven
 * homogeneous Couette case (scenarios/simple_shear.ini). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fields.h"
#include "homogeneous.h"
#include "testutil.h"

static double rel(double got, double want)
{
    return fabs(got - want) / fabs(want);
}

static void assert_rel(const char *what, double got, double want, double tol)
{
    if (!(rel(got, want) < tol))
        fail_msg("%s: got %.17g, want %.17g (relative error %.3g > %.3g)", what, got, want, rel(got, want),
                 tol);
}

/* docs/model-notes.md section 7, written out independently of model.c. */
static void closed_form(const ekm_material *m, double phi, double gdot, double *T, double *P, double *mu)
{
    const double g = 1.0 / (1.0 - phi / m->phi_cp);
    const double dphi = phi > m->phi_co ? phi - m->phi_co : 0.0;
    *T = 2.0 * m->eta0 * gdot * gdot / (3.0 * phi * m->eps0);
    *P = m->rho_p * g * (2.0 * m->eta0 * gdot * gdot / (3.0 * m->eps0) + m->T0 * dphi);
    const double r = m->T0 * dphi / (phi * *T);
    *mu = sqrt(3.0 * m->eta0 * m->eps0 / (2.0 * phi)) * (1.0 + m->nu * r) / (1.0 + r);
}

static void test_closed_forms(void **state)
{
    (void)state;
    const double nus[] = {1.0, 0.3, 2.5};
    const double phis[] = {0.30, 0.55, 0.60, 0.605, 0.62, 0.635};
    const double gdots[] = {0.1, 10.0, 300.0};
    const ekm_variant variants[] = {EKM_VARIANT_FULL, EKM_VARIANT_THESIS};
    double worst = 0.0;
    int cases = 0;
    for (size_t a = 0; a < 3; a++)
        for (size_t b = 0; b < 6; b++)
            for (size_t c = 0; c < 3; c++)
                for (size_t d = 0; d < 2; d++) {
                    ekm_material m = ekm_material_thesis();
                    m.nu = nus[a];
                    ekm_homog_state h;
                    ekm_error err;
                    assert_int_equal(ekm_homog_shear(&m, variants[d], phis[b], gdots[c], &h, &err), EKM_OK);
                    double T, P, mu;
                    closed_form(&m, phis[b], gdots[c], &T, &P, &mu);
                    assert_rel("T", h.T, T, 1e-12);
                    assert_rel("P", h.P, P, 1e-12);
                    assert_rel("mu", h.mu, mu, 1e-12);
                    assert_rel("sxz", h.sxz, mu * P, 1e-12);
                    assert_rel("P_K + P_Y", h.P_K + h.P_Y, P, 1e-12);
                    worst = fmax(worst, fmax(rel(h.T, T), fmax(rel(h.P, P), rel(h.mu, mu))));
                    /* it is the root of libekm's own temperature source */
                    const double heat = 2.0 / 3.0 * h.sxz * gdots[c];
                    const double S =
                        ekm_temperature_source(&m, variants[d], phis[b], h.T, gdots[c] * gdots[c], 0.0, NULL);
                    assert_true(fabs(S) < 1e-12 * heat);
                    cases++;
                }
    printf("homogeneous shear: %d cases, worst relative error against docs/model-notes.md section 7: %.2e\n",
           cases, worst);
}

static void test_bad_arguments(void **state)
{
    (void)state;
    ekm_material m = ekm_material_thesis();
    ekm_homog_state h;
    ekm_error err;
    assert_int_equal(ekm_homog_shear(&m, EKM_VARIANT_FULL, 0.64, 1.0, &h, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "phi = 0.64"));
    assert_int_equal(ekm_homog_shear(&m, EKM_VARIANT_FULL, 0.5, 0.0, &h, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "gdot = 0"));
}

/* The solver's steady state of scenarios/simple_shear.ini (walls at -V and
 * +V, adiabatic, no gravity) started at rest (u = 0) with T twice the
 * answer: the walls drive the shear in by momentum diffusion (time
 * L^2 rho / (pi^2 eta): 0.6 s at phi = 0.55, 1 ms at 0.62), T relaxes at
 * the rate eps; after t_end (about 25 diffusion times, so that the slowest
 * mode has decayed by e^-25 ~ 1e-11) every cell must equal
 * ekm_homog_shear to tol. */
static void couette_case(double phi, double nu, const char *t_end, double tol)
{
    ekm_scenario tmp;
    ekm_error e;
    assert_int_equal(ekm_scenario_load(&tmp, test_path("scenarios/simple_shear.ini"), NULL, 0, &e), EKM_OK);
    ekm_material m = tmp.material;
    m.nu = nu;
    const double u_bottom = tmp.bottom.velocity, gdot = (tmp.top.velocity - u_bottom) / tmp.length;
    const ekm_variant variant = tmp.variant;
    ekm_scenario_free(&tmp);
    ekm_homog_state h;
    assert_int_equal(ekm_homog_shear(&m, variant, phi, gdot, &h, &e), EKM_OK);

    char set_phi[64], set_rate[64], set_u[64], set_T[64], set_nu[64], set_t[64];
    snprintf(set_phi, sizeof set_phi, "initial.phi=%.17g", phi);
    snprintf(set_rate, sizeof set_rate, "initial.shear_rate=%.17g", 0.0);
    snprintf(set_u, sizeof set_u, "initial.u=%.17g", 0.0);
    snprintf(set_T, sizeof set_T, "initial.T=%.17g", 2.0 * h.T);
    snprintf(set_nu, sizeof set_nu, "material.nu=%.17g", nu);
    snprintf(set_t, sizeof set_t, "run.t_end=%s", t_end);
    const char *sets[] = {set_phi, set_rate,          set_u,           set_T, set_nu,
                          set_t,   "run.output_dt=1", "run.stop=t_end"};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/simple_shear.ini", sets, 8, NULL, NULL), EKM_OK);
    const int n = r.s->n;
    double *buf = calloc((size_t)n * 5, sizeof(double));
    int *regime = calloc((size_t)n, sizeof(int));
    assert_non_null(buf);
    assert_non_null(regime);
    ekm_fields f = {buf, buf + n, buf + 2 * n, buf + 3 * n, buf + 4 * n, regime};
    ekm_fields_compute(&r.sc, r.s, r.s->t, &f);
    double eT = 0, eP = 0, es = 0, emu = 0, ephi = 0;
    for (int j = 0; j < n; j++) {
        eT = fmax(eT, rel(r.s->T[j], h.T));
        eP = fmax(eP, rel(f.P[j], h.P));
        es = fmax(es, rel(fabs(f.sxz[j]), h.sxz));
        emu = fmax(emu, rel(fabs(f.sxz[j]) / f.P[j], h.mu));
        ephi = fmax(ephi, rel(r.s->phi[j], phi));
    }
    printf("couette phi = %.3f nu = %.2f t = %s s, %d cells, %ld steps: max relative errors T %.2e P %.2e "
           "sxz %.2e "
           "mu %.2e phi %.2e (tolerance %.0e)\n",
           phi, nu, t_end, n, r.stats.steps, eT, eP, es, emu, ephi, tol);
    assert_true(eT < tol);
    assert_true(eP < tol);
    assert_true(es < tol);
    assert_true(emu < tol);
    assert_true(ephi < tol);
    free(buf);
    free(regime);
    test_run_free(&r);
}

static void test_couette_dilute(void **state)
{
    (void)state;
    couette_case(0.55, 0.5, "40", 1e-10);
}
static void test_couette_dense(void **state)
{
    (void)state;
    couette_case(0.62, 0.5, "0.5", 1e-10);
}
static void test_couette_dense_nu2(void **state)
{
    (void)state;
    couette_case(0.63, 2.0, "0.5", 1e-10);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_forms),      cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_couette_dilute),    cmocka_unit_test(test_couette_dense),
        cmocka_unit_test(test_couette_dense_nu2),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
