/* ekmcompare fit --rheology with a closure style other than the EKM
 * (law/closure.h): the mu_i style's parameters recovered from synthetic
 * data made with it (within 3 SE), the refusals (T of a closure without
 * a temperature, a parameter the closure does not read), and the
 * yardstick the issue asks for: on data made with one closure, that
 * closure wins on chi2/dof against the other. */
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "closure.h"
#include "fit.h"
#include "fit_data.h"

#define REL_SE 0.02 /* stated SE of every synthetic observable: 2% of its value */

static void set_law_p(ekm_material *m, const char *key, double v)
{
    const ekm_closure *c;
    size_t k;
    assert_int_equal(ekm_closure_param_find(key, &c, &k), 0);
    *ekm_closure_param_ptr(c, k, m) = v;
}

/* mu_i with the given parameters on the DEM grains' density. */
static ekm_material mu_i_material(double mu_s, double mu_2, double I_0, double phi_max, double phi_min)
{
    ekm_material m = ekm_material_thesis();
    m.rho_p = 2500.0;
    set_law_p(&m, "mu_s", mu_s);
    set_law_p(&m, "mu_2", mu_2);
    set_law_p(&m, "I_0", I_0);
    set_law_p(&m, "phi_max", phi_max);
    set_law_p(&m, "phi_min", phi_min);
    set_law_p(&m, "d", 0.002);
    return m;
}

/* Noisy P, sxz (and T where the closure has one) of closure c at m on a
 * phi x gdot grid. */
static size_t synth(const ekm_closure *c, const ekm_material *m, const double *phis, size_t nphi,
                    const double *gdots, size_t ngdot, unsigned long seed, cg_fit_point *pts)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    size_t n = 0;
    for (size_t a = 0; a < nphi; a++)
        for (size_t b = 0; b < ngdot; b++) {
            ekm_homog_state h;
            ekm_error e;
            assert_int_equal(ekm_closure_homog(c, m, phis[a], gdots[b], &h, &e), EKM_OK);
            cg_fit_point *pt = &pts[n++];
            memset(pt, 0, sizeof *pt);
            snprintf(pt->file, sizeof pt->file, "synthetic %s phi %.3f gdot %g", c->name, phis[a], gdots[b]);
            pt->phi = phis[a];
            pt->gdot = gdots[b];
            pt->nbins = 8;
            pt->r2 = 1.0;
            const double v[CG_FIT_NFIELD] = {h.P, h.sxz, h.T, h.mu};
            for (int f = 0; f < CG_FIT_NFIELD; f++) {
                pt->se[f] = isfinite(v[f]) ? REL_SE * v[f] : NAN;
                pt->value[f] = isfinite(v[f]) ? v[f] + gsl_ran_gaussian(rng, pt->se[f]) : NAN;
            }
        }
    gsl_rng_free(rng);
    return n;
}

static void set_params(cg_fit_problem *pb, const char *const *names, size_t n)
{
    pb->nparams = n;
    for (size_t j = 0; j < n; j++) {
        pb->param[j] = cg_fit_param_lookup(names[j]);
        assert_true(pb->param[j] >= 0);
    }
}

static const double PHIS[] = {0.46, 0.50, 0.53, 0.56, 0.58};
static const double GDOTS[] = {5.0, 20.0, 60.0};
#define NPTS 15

/* The five mu_i parameters from P and sxz, from a start 10-25% off. */
static void test_mu_i_recovers(void **state)
{
    (void)state;
    const ekm_material truth = mu_i_material(0.38, 0.64, 0.28, 0.60, 0.42);
    cg_fit_point pts[NPTS];
    cg_fit_problem pb = {.pts = pts,
                         .npts = synth(&ekm_closure_mu_i, &truth, PHIS, 5, GDOTS, 3, 4242, pts),
                         .fields = 1u << CG_FIT_P | 1u << CG_FIT_SXZ,
                         .start = mu_i_material(0.33, 0.75, 0.35, 0.62, 0.38),
                         .closure = &ekm_closure_mu_i,
                         .nstarts = 6,
                         .seed = 7};
    const char *names[] = {"mu_s", "mu_2", "I_0", "phi_max", "phi_min"};
    set_params(&pb, names, 5);
    cg_fit_result res;
    ekm_error err;
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_OK);
    printf("mu_i: chi2/dof = %.3f (dof %ld)\n", res.chi2_dof, res.dof);
    assert_int_equal(res.nfree, 5);
    assert_int_equal(res.dof, NPTS * 2 - 5);
    for (size_t j = 0; j < res.nparams; j++) {
        const double want = cg_fit_param_get(&truth, res.param[j]);
        printf("  %-7s truth %-8.4g fit %-10.6g SE %.3g\n", cg_fit_param_name(res.param[j]), want,
               res.value[j], res.se[j]);
        assert_true(res.identifiable[j]);
        assert_true(res.se[j] > 0.0);
        assert_true(fabs(res.value[j] - want) < 3.0 * res.se[j]);
    }
    assert_true(res.chi2_dof > 0.4 && res.chi2_dof < 1.8);
    /* the model values of the fitted closure: T is n/a */
    for (size_t k = 0; k < pb.npts; k++)
        assert_true(isnan(res.model[k * CG_FIT_NFIELD + CG_FIT_T]));
    cg_fit_result_free(&res);
}

/* ekm_jam's density factor from P, sxz and T below phi_co: eta0, eps0,
 * phi_J and beta within 3 SE. */
static void test_ekm_jam_recovers(void **state)
{
    (void)state;
    ekm_material truth = ekm_material_thesis();
    truth.rho_p = 2500.0;
    truth.phi_co = 0.58;
    truth.eta0 = 5e-4;
    truth.eps0 = 320.0;
    set_law_p(&truth, "phi_J", 0.6);
    set_law_p(&truth, "beta", 2.0);
    ekm_material start = truth;
    start.eta0 = 4e-4;
    start.eps0 = 250.0;
    set_law_p(&start, "phi_J", 0.62);
    set_law_p(&start, "beta", 1.5);
    const double phis[] = {0.45, 0.50, 0.53, 0.55, 0.57};
    cg_fit_point pts[NPTS];
    cg_fit_problem pb = {.pts = pts,
                         .npts = synth(&ekm_closure_ekm_jam, &truth, phis, 5, GDOTS, 3, 31, pts),
                         .fields = 1u << CG_FIT_P | 1u << CG_FIT_SXZ | 1u << CG_FIT_T,
                         .start = start,
                         .closure = &ekm_closure_ekm_jam,
                         .nstarts = 6,
                         .seed = 7};
    const char *names[] = {"eta0", "eps0", "phi_J", "beta"};
    set_params(&pb, names, 4);
    cg_fit_result res;
    ekm_error err;
    if (cg_fit_run(&pb, &res, &err) != EKM_OK)
        fail_msg("%s", err.message);
    printf("ekm_jam: chi2/dof = %.3f (dof %ld)\n", res.chi2_dof, res.dof);
    assert_int_equal(res.nfree, 4);
    for (size_t j = 0; j < res.nparams; j++) {
        const double want = cg_fit_param_get(&truth, res.param[j]);
        printf("  %-7s truth %-8.4g fit %-10.6g SE %.3g\n", cg_fit_param_name(res.param[j]), want,
               res.value[j], res.se[j]);
        assert_true(fabs(res.value[j] - want) < 3.0 * res.se[j]);
    }
    assert_true(res.chi2_dof > 0.4 && res.chi2_dof < 1.8);
    cg_fit_result_free(&res);
}

static void test_refusals(void **state)
{
    (void)state;
    const ekm_material truth = mu_i_material(0.38, 0.64, 0.28, 0.60, 0.42);
    cg_fit_point pts[NPTS];
    cg_fit_problem pb = {.pts = pts,
                         .npts = synth(&ekm_closure_mu_i, &truth, PHIS, 5, GDOTS, 3, 1, pts),
                         .fields = 1u << CG_FIT_P | 1u << CG_FIT_T,
                         .start = truth,
                         .closure = &ekm_closure_mu_i,
                         .nstarts = 1,
                         .seed = 7};
    const char *names[] = {"mu_s"};
    set_params(&pb, names, 1);
    cg_fit_result res;
    ekm_error err;
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "--fields T: closure mu_i has no granular temperature"));
    cg_fit_result_free(&res);
    pb.fields = 1u << CG_FIT_P;
    const char *ekm_names[] = {"mu_s", "eta0"};
    set_params(&pb, ekm_names, 2);
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "--params: eta0: not a parameter of closure mu_i"));
    cg_fit_result_free(&res);
    /* and the other way round: the EKM does not read mu_s */
    pb.closure = &ekm_closure_ekm_full;
    pb.start = ekm_material_thesis();
    set_params(&pb, names, 1);
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "--params: mu_s: not a parameter of closure ekm_full"));
    cg_fit_result_free(&res);
    /* a point the start cannot describe (phi above phi_max) is named */
    pb.closure = &ekm_closure_mu_i;
    pb.start = mu_i_material(0.38, 0.64, 0.28, 0.55, 0.42);
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_EINPUT);
    assert_non_null(
        strstr(err.message, "synthetic mu_i phi 0.560 gdot 5: closure mu_i at the start material"));
    cg_fit_result_free(&res);
}

/* chi2/dof of closure c fitted to the points with the given parameters. */
static double fitted_chi2_dof(const cg_fit_point *pts, size_t n, const ekm_closure *c, ekm_material start,
                              const char *const *names, size_t nnames)
{
    cg_fit_problem pb = {.pts = pts,
                         .npts = n,
                         .fields = 1u << CG_FIT_P | 1u << CG_FIT_SXZ,
                         .start = start,
                         .closure = c,
                         .variant = c->is_ekm ? c->variant : EKM_VARIANT_FULL,
                         .nstarts = 6,
                         .seed = 7};
    set_params(&pb, names, nnames);
    cg_fit_result res;
    ekm_error err;
    if (cg_fit_run(&pb, &res, &err) != EKM_OK)
        fail_msg("%s: %s", c->name, err.message);
    const double v = res.chi2_dof;
    printf("  %s: chi2/dof %.4g (dof %ld)\n", c->name, v, res.dof);
    cg_fit_result_free(&res);
    return v;
}

/* Data made with mu_i: mu_i wins over the EKM (five parameters each);
 * data made with the EKM: the EKM wins over mu_i. */
static void test_own_closure_wins(void **state)
{
    (void)state;
    const char *mu_names[] = {"mu_s", "mu_2", "I_0", "phi_max", "phi_min"};
    const char *ekm_names[] = {"T0", "phi_co", "phi_cp", "eta0", "eps0"};
    ekm_material ekm_start = ekm_material_thesis();
    ekm_start.rho_p = 2500.0;
    ekm_start.phi_cp = 0.66;
    ekm_start.phi_co = 0.52; /* below some points: T0 and phi_co act at the start */
    const ekm_material mu_start = mu_i_material(0.35, 0.7, 0.3, 0.62, 0.40);
    cg_fit_point pts[NPTS];
    const ekm_material mu_truth = mu_i_material(0.38, 0.64, 0.28, 0.60, 0.42);
    size_t n = synth(&ekm_closure_mu_i, &mu_truth, PHIS, 5, GDOTS, 3, 77, pts);
    printf("data made with mu_i:\n");
    const double own = fitted_chi2_dof(pts, n, &ekm_closure_mu_i, mu_start, mu_names, 5);
    const double other = fitted_chi2_dof(pts, n, &ekm_closure_ekm_full, ekm_start, ekm_names, 5);
    assert_true(own < 2.0 && other > 3.0 * own);
    ekm_material ekm_truth = ekm_start;
    ekm_truth.T0 = 2.2;
    ekm_truth.phi_co = 0.55;
    ekm_truth.phi_cp = 0.64;
    ekm_truth.eta0 = 5e-4;
    ekm_truth.eps0 = 320.0;
    n = synth(&ekm_closure_ekm_full, &ekm_truth, PHIS, 5, GDOTS, 3, 78, pts);
    printf("data made with ekm_full:\n");
    const double own_e = fitted_chi2_dof(pts, n, &ekm_closure_ekm_full, ekm_start, ekm_names, 5);
    const double other_e = fitted_chi2_dof(pts, n, &ekm_closure_mu_i, mu_start, mu_names, 5);
    assert_true(own_e < 2.0 && other_e > 3.0 * own_e);
}

/* Pressure-controlled points: closure c's state at each P and gdot, the
 * data phi and |sxz| with noise (phi SE 5e-4, |sxz| SE 2 %), P exact. */
static size_t synth_at_pressure(const ekm_closure *c, const ekm_material *m, const double *Ps, size_t nP,
                                const double *gdots, size_t ngdot, unsigned long seed, cg_fit_point *pts)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    size_t n = 0;
    for (size_t a = 0; a < nP; a++)
        for (size_t b = 0; b < ngdot; b++) {
            ekm_homog_state h;
            ekm_error e;
            assert_int_equal(ekm_closure_homog_at_pressure(c, m, Ps[a], gdots[b], &h, &e), EKM_OK);
            cg_fit_point *pt = &pts[n++];
            memset(pt, 0, sizeof *pt);
            snprintf(pt->file, sizeof pt->file, "synthetic %s P %g gdot %g", c->name, Ps[a], gdots[b]);
            pt->at_pressure = 1;
            pt->phi_se = 5e-4;
            pt->phi = h.phi + gsl_ran_gaussian(rng, pt->phi_se);
            pt->gdot = gdots[b];
            pt->nbins = 8;
            pt->r2 = 1.0;
            pt->value[CG_FIT_P] = Ps[a];
            pt->se[CG_FIT_P] = REL_SE * Ps[a];
            pt->se[CG_FIT_SXZ] = REL_SE * h.sxz;
            pt->value[CG_FIT_SXZ] = h.sxz + gsl_ran_gaussian(rng, pt->se[CG_FIT_SXZ]);
            pt->value[CG_FIT_T] = pt->value[CG_FIT_MU] = pt->se[CG_FIT_T] = pt->se[CG_FIT_MU] = NAN;
        }
    gsl_rng_free(rng);
    return n;
}

/* Under pressure control (phi the response, in the P residual) each
 * closure's parameters come back within 3 SE, and the model's phi is
 * reported per point. */
static void test_at_pressure_recovers(void **state)
{
    (void)state;
    const double Ps[] = {10.0, 100.0, 1000.0};
    const double gdots[] = {1.0, 3.0, 10.0, 30.0};
    cg_fit_point pts[12];
    const ekm_material mu_truth = mu_i_material(0.38, 0.64, 0.28, 0.60, 0.42);
    ekm_material ekm_truth = ekm_material_thesis();
    ekm_truth.rho_p = 2500.0;
    ekm_truth.T0 = 0.02;
    ekm_truth.phi_co = 0.55;
    ekm_truth.phi_cp = 0.6;
    ekm_truth.eta0 = 5e-4;
    ekm_truth.eps0 = 320.0;
    ekm_material ekm_start = ekm_truth;
    ekm_start.T0 = 0.03;
    ekm_start.phi_co = 0.53;
    ekm_start.phi_cp = 0.62;
    ekm_start.eta0 = 4e-4;
    ekm_start.eps0 = 250.0;
    const struct {
        const ekm_closure *c;
        const ekm_material *truth, *start;
        const char *names[5];
    } cases[] = {
        {&ekm_closure_mu_i, &mu_truth, NULL, {"mu_s", "mu_2", "I_0", "phi_max", "phi_min"}},
        {&ekm_closure_ekm_full, &ekm_truth, &ekm_start, {"T0", "phi_co", "phi_cp", "eta0", "eps0"}},
    };
    const ekm_material mu_start = mu_i_material(0.33, 0.75, 0.35, 0.62, 0.38);
    for (size_t c = 0; c < 2; c++) {
        cg_fit_problem pb = {.pts = pts,
                             .npts =
                                 synth_at_pressure(cases[c].c, cases[c].truth, Ps, 3, gdots, 4, 99 + c, pts),
                             .fields = 1u << CG_FIT_P | 1u << CG_FIT_SXZ,
                             .start = cases[c].start ? *cases[c].start : mu_start,
                             .closure = cases[c].c,
                             .nstarts = 6,
                             .seed = 7};
        set_params(&pb, cases[c].names, 5);
        cg_fit_result res;
        ekm_error err;
        if (cg_fit_run(&pb, &res, &err) != EKM_OK)
            fail_msg("%s: %s", cases[c].c->name, err.message);
        printf("%s at pressure: chi2/dof %.3f (dof %ld)\n", cases[c].c->name, res.chi2_dof, res.dof);
        for (size_t j = 0; j < res.nparams; j++) {
            const double want = cg_fit_param_get(cases[c].truth, res.param[j]);
            printf("  %-7s truth %-8.4g fit %-10.6g SE %.3g %s\n", cg_fit_param_name(res.param[j]), want,
                   res.value[j], res.se[j], res.why_not[j]);
            if (res.identifiable[j])
                assert_true(fabs(res.value[j] - want) < 3.0 * res.se[j]);
        }
        assert_true(res.nfree >= 4);
        assert_true(res.chi2_dof > 0.3 && res.chi2_dof < 2.0);
        for (size_t k = 0; k < pb.npts; k++)
            assert_true(fabs(res.model_phi[k] - pts[k].phi) < 5.0 * pts[k].phi_se);
        cg_fit_result_free(&res);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mu_i_recovers),
        cmocka_unit_test(test_ekm_jam_recovers),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_own_closure_wins),
        cmocka_unit_test(test_at_pressure_recovers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
