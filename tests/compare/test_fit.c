/* ekmcompare fit --rheology: parameter recovery from synthetic rheology
 * (ekm_homog_shear plus Gaussian noise of a stated SE, gsl_rng with a
 * fixed seed), identifiability, the profile reduction, and the command
 * end to end through CG-like HDF5 files, including its bad inputs. */
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <jansson.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "cg_run.h"
#include "closure.h"
#include "fit.h"
#include "fit_data.h"
#include "h5.h"
#include "homogeneous.h"
#include "scenario.h"
#include "synth.h"
#include "test_util.h"

#define REL_SE 0.02 /* stated SE of every synthetic observable: 2% of its value */

/* The start: the thesis material with the DEM grains' density of
 * scenarios/simple_shear.ini (the end-to-end test's --start file). */
static ekm_material start_material(void)
{
    ekm_material m = ekm_material_thesis();
    m.rho_p = 2500.0;
    return m;
}

/* The truth differs from the start in every fitted parameter. */
static ekm_material truth_material(void)
{
    ekm_material m = start_material();
    m.T0 = 2.2;
    m.phi_co = 0.585;
    m.eta0 = 5.0e-4;
    m.eps0 = 320.0;
    m.nu = 0.6;
    return m;
}

/* Points on a phi x gdot grid with noisy P, sxz, T (SE = REL_SE x value). */
static size_t synth_points(const ekm_material *m, const double *phis, size_t nphi, const double *gdots,
                           size_t ngdot, unsigned long seed, cg_fit_point *pts)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    size_t n = 0;
    for (size_t a = 0; a < nphi; a++)
        for (size_t b = 0; b < ngdot; b++) {
            ekm_homog_state h;
            ekm_error e;
            assert_int_equal(ekm_homog_shear(m, EKM_VARIANT_FULL, phis[a], gdots[b], &h, &e), EKM_OK);
            cg_fit_point *pt = &pts[n++];
            memset(pt, 0, sizeof *pt);
            snprintf(pt->file, sizeof pt->file, "synthetic phi %.3f gdot %g", phis[a], gdots[b]);
            pt->phi = phis[a];
            pt->gdot = gdots[b];
            pt->nbins = 8;
            pt->r2 = 1.0;
            const double v[CG_FIT_NFIELD] = {h.P, h.sxz, h.T, h.mu};
            for (int f = 0; f < CG_FIT_NFIELD; f++) {
                pt->se[f] = REL_SE * v[f];
                pt->value[f] = v[f] + gsl_ran_gaussian(rng, pt->se[f]);
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

/* chi2 of the points at material m (the fit must reach at most this at the truth). */
static double chi2_at(const cg_fit_problem *pb, const ekm_material *m)
{
    double chi2 = 0.0;
    for (size_t k = 0; k < pb->npts; k++) {
        ekm_homog_state h;
        ekm_error e;
        assert_int_equal(ekm_homog_shear(m, EKM_VARIANT_FULL, pb->pts[k].phi, pb->pts[k].gdot, &h, &e),
                         EKM_OK);
        const double v[CG_FIT_NFIELD] = {h.P, h.sxz, h.T, h.mu};
        for (int f = 0; f < CG_FIT_NFIELD; f++)
            if (pb->fields & (1u << f))
                chi2 += pow((v[f] - pb->pts[k].value[f]) / pb->pts[k].se[f], 2);
    }
    return chi2;
}

static void print_result(const char *title, const cg_fit_result *res, const ekm_material *truth)
{
    printf("%s: chi2/dof = %.3f (dof %ld), starts %d/%d\n", title, res->chi2_dof, res->dof,
           res->starts_converged, res->starts_run);
    for (size_t j = 0; j < res->nparams; j++)
        printf("  %-7s truth %-10.5g fit %-10.5g SE %-9.3g (%+.2f SE) %s\n", cg_fit_param_name(res->param[j]),
               cg_fit_param_get(truth, res->param[j]), res->value[j], res->se[j],
               (res->value[j] - cg_fit_param_get(truth, res->param[j])) / res->se[j],
               res->identifiable[j] ? "" : res->why_not[j]);
}

/* Dense and dilute points: all five parameters identifiable and recovered. */
static void test_recovers_parameters(void **state)
{
    (void)state;
    const ekm_material truth = truth_material();
    const double phis[] = {0.50, 0.55, 0.59, 0.60, 0.61, 0.62, 0.63};
    const double gdots[] = {2.0, 8.0, 30.0, 100.0};
    cg_fit_point pts[28];
    cg_fit_problem pb = {.pts = pts,
                         .npts = synth_points(&truth, phis, 7, gdots, 4, 1233, pts),
                         .fields = 1u << CG_FIT_P | 1u << CG_FIT_SXZ | 1u << CG_FIT_T,
                         .start = start_material(),
                         .variant = EKM_VARIANT_FULL,
                         .nstarts = 8,
                         .seed = 7};
    const char *names[] = {"T0", "phi_co", "eta0", "eps0", "nu"};
    set_params(&pb, names, 5);
    cg_fit_result res;
    ekm_error err;
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_OK);
    print_result("dense and dilute", &res, &truth);
    printf("  chi2 %.6g, at the truth %.6g\n", res.chi2, chi2_at(&pb, &truth));
    assert_true(res.chi2 <= chi2_at(&pb, &truth));
    assert_int_equal(res.nfree, 5);
    assert_int_equal(res.dof, 28 * 3 - 5);
    for (size_t j = 0; j < res.nparams; j++) {
        assert_true(res.identifiable[j]);
        assert_true(res.se[j] > 0.0);
        assert_true(fabs(res.value[j] - cg_fit_param_get(&truth, res.param[j])) < 3.0 * res.se[j]);
        assert_true(fabs(res.corr[j][j] - 1.0) < 1e-12);
    }
    assert_true(res.chi2_dof > 0.5 && res.chi2_dof < 1.5);
    cg_fit_result_free(&res);
}

/* Every point below phi_co: T0 and phi_co (and nu, through r = 0) have no
 * effect and are held at their start values; eta0, eps0 are recovered. */
static void test_dilute_only(void **state)
{
    (void)state;
    const ekm_material truth = truth_material();
    const double phis[] = {0.40, 0.45, 0.50, 0.54, 0.57};
    const double gdots[] = {3.0, 10.0, 40.0};
    cg_fit_point pts[15];
    cg_fit_problem pb = {.pts = pts,
                         .npts = synth_points(&truth, phis, 5, gdots, 3, 99, pts),
                         .fields = 1u << CG_FIT_P | 1u << CG_FIT_SXZ | 1u << CG_FIT_T,
                         .start = start_material(),
                         .variant = EKM_VARIANT_FULL,
                         .nstarts = 4,
                         .seed = 7};
    const char *names[] = {"T0", "phi_co", "eta0", "eps0", "nu"};
    set_params(&pb, names, 5);
    cg_fit_result res;
    ekm_error err;
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_OK);
    print_result("dilute only", &res, &truth);
    for (size_t j = 0; j < 5; j++) {
        const char *name = cg_fit_param_name(res.param[j]);
        const int yield = !strcmp(name, "T0") || !strcmp(name, "phi_co") || !strcmp(name, "nu");
        assert_int_equal(res.identifiable[j], !yield);
        if (yield) {
            assert_non_null(strstr(res.why_not[j], "every point has phi < phi_co"));
            assert_true(res.value[j] == res.start[j]);
            assert_true(isnan(res.se[j]));
        } else {
            assert_true(fabs(res.value[j] - cg_fit_param_get(&truth, res.param[j])) < 3.0 * res.se[j]);
        }
    }
    assert_int_equal(res.nfree, 2);
    assert_true(res.chi2_dof > 0.5 && res.chi2_dof < 1.5);
    cg_fit_result_free(&res);
}

/* eta0 and eps0 from P alone: P depends on eta0/eps0 only, so the two are
 * fully correlated: eps0 (listed second) is held; a key the shear does
 * not depend on (zeta0) is held too. */
static void test_correlated_and_absent(void **state)
{
    (void)state;
    const ekm_material truth = truth_material();
    const double phis[] = {0.45, 0.50, 0.55};
    const double gdots[] = {5.0, 20.0};
    cg_fit_point pts[6];
    cg_fit_problem pb = {.pts = pts,
                         .npts = synth_points(&truth, phis, 3, gdots, 2, 5, pts),
                         .fields = 1u << CG_FIT_P,
                         .start = start_material(),
                         .variant = EKM_VARIANT_FULL,
                         .nstarts = 2,
                         .seed = 7};
    const char *names[] = {"eta0", "eps0", "zeta0"};
    set_params(&pb, names, 3);
    cg_fit_result res;
    ekm_error err;
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_OK);
    print_result("P only", &res, &truth);
    assert_true(res.identifiable[0]);
    assert_false(res.identifiable[1]);
    assert_non_null(strstr(res.why_not[1], "correlation with eta0"));
    assert_false(res.identifiable[2]);
    assert_non_null(strstr(res.why_not[2], "does not depend on zeta0"));
    /* with eps0 held at the start, eta0 absorbs the ratio eta0/eps0 of P */
    assert_true(fabs(res.value[0] / res.start[1] / (truth.eta0 / truth.eps0) - 1.0) <
                5.0 * res.se[0] / res.value[0]);
    cg_fit_result_free(&res);
}

static void test_fewer_points_than_params(void **state)
{
    (void)state;
    const ekm_material truth = truth_material();
    const double phis[] = {0.50, 0.62};
    const double gdots[] = {10.0};
    cg_fit_point pts[2];
    cg_fit_problem pb = {.pts = pts,
                         .npts = synth_points(&truth, phis, 2, gdots, 1, 5, pts),
                         .fields = 1u << CG_FIT_P | 1u << CG_FIT_SXZ | 1u << CG_FIT_T,
                         .start = start_material(),
                         .nstarts = 1,
                         .seed = 7};
    const char *names[] = {"T0", "phi_co", "eta0"};
    set_params(&pb, names, 3);
    cg_fit_result res;
    ekm_error err;
    assert_int_equal(cg_fit_run(&pb, &res, &err), EKM_EINPUT);
    assert_string_equal(err.message,
                        "2 points for 3 parameters: expected at least as many points (input files) as "
                        "parameters");
    cg_fit_result_free(&res);
}

/* ---- profiles -> point ---- */

#define NB 8

typedef struct {
    double z[NB], phi[NB], phi_se[NB], vx[NB], vx_se[NB], f[CG_FIT_NFIELD][NB], se[CG_FIT_NFIELD][NB];
} profiles;

/* Homogeneous shear of the truth at (phi, gdot) over z in (0, 0.016),
 * with bin-to-bin scatter of 0.5% around the mean (alternating sign) and
 * vx = -0.08 + gdot z (+ shape: 0 linear, 1 Bagnold-like). */
static void make_profiles(profiles *p, double phi, double gdot, int shape)
{
    const ekm_material m = truth_material();
    ekm_homog_state h;
    ekm_error e;
    assert_int_equal(ekm_homog_shear(&m, EKM_VARIANT_FULL, phi, gdot, &h, &e), EKM_OK);
    const double v[CG_FIT_NFIELD] = {h.P, h.sxz, h.T, h.mu};
    const double L = 0.016;
    for (int k = 0; k < NB; k++) {
        const double z = (k + 0.5) * L / NB, s = k % 2 ? 1.005 : 0.995;
        p->z[k] = z;
        p->phi[k] = phi * s;
        p->phi_se[k] = 1e-3;
        p->vx[k] = shape == 0 ? -0.08 + gdot * z : gdot * L * (1.0 - pow(1.0 - z / L, 1.5));
        p->vx_se[k] = 1e-3;
        for (int f = 0; f < CG_FIT_NFIELD; f++) {
            p->f[f][k] = v[f] * s;
            p->se[f][k] = REL_SE * v[f] * (1.0 + 0.1 * k); /* mean of the SEs: REL_SE v (1 + 0.35) */
        }
    }
}

static cg_fit_profiles view(const profiles *p)
{
    cg_fit_profiles pr = {
        .n = NB, .z = p->z, .phi = p->phi, .phi_se = p->phi_se, .vx = p->vx, .vx_se = p->vx_se};
    for (int f = 0; f < CG_FIT_NFIELD; f++) {
        pr.f[f] = p->f[f];
        pr.se[f] = p->se[f];
    }
    return pr;
}

static void test_profile_reduction(void **state)
{
    (void)state;
    profiles p;
    make_profiles(&p, 0.55, 12.5, 0);
    const cg_fit_profiles pr = view(&p);
    cg_fit_point pt;
    ekm_error err;
    const unsigned all = 1u << CG_FIT_P | 1u << CG_FIT_SXZ | 1u << CG_FIT_T;
    assert_int_equal(cg_fit_point_from_profiles("a.h5", &pr, all, &pt, &err), EKM_OK);
    assert_close(pt.phi, 0.55, 1e-15);
    assert_close(pt.gdot, 12.5, 1e-12);
    assert_close(pt.gdot_se, 0.0, 1e-12);
    assert_close(pt.r2, 1.0, 1e-12);
    assert_close(pt.se[CG_FIT_P] / pt.value[CG_FIT_P], REL_SE * 1.35, 1e-12);
    /* a Bagnold-like vx is refused */
    make_profiles(&p, 0.55, 12.5, 1);
    const cg_fit_profiles pb = view(&p);
    assert_int_equal(cg_fit_point_from_profiles("chute.h5", &pb, all, &pt, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "chute.h5: vx is not linear in the axis coordinate (R^2 = 0.98"));
    /* a missing SE */
    make_profiles(&p, 0.55, 12.5, 0);
    p.se[CG_FIT_T][3] = NAN;
    const cg_fit_profiles pn = view(&p);
    assert_int_equal(cg_fit_point_from_profiles("b.h5", &pn, all, &pt, &err), EKM_EINPUT);
    assert_string_equal(err.message,
                        "b.h5: T_se: bin 3 is nan: expected standard errors > 0 (a window of at least "
                        "two snapshots)");
}

/* A real `ekmcompare cg` output (synthetic dump: uniform density,
 * vx = gdot (z - lz/2) + thermal noise, contact stress P0, S0) reads as
 * the point it describes. */
static void test_real_cg_output(void **state)
{
    (void)state;
    synth_opts o = synth_default();
    o.nsnap = 12;
    o.gdot = 10.0;
    o.with_stress = 1;
    o.P0 = 1000.0;
    o.S0 = 300.0;
    char dump[512], out[512];
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "fit_shear.dump"), &o), 0);
    cg_run_opts ro = cg_opts_default();
    const char *in[1] = {dump};
    ro.inputs = in;
    ro.ninputs = 1;
    ro.out = tmp_path(out, sizeof out, "fit_shear.h5");
    ro.width = 0.002;
    ro.bins = 8;
    ro.have_range = 1; /* the interior: no wall reflection of vx */
    ro.range_lo = 0.008;
    ro.range_hi = 0.032;
    ro.nstress = 6;
    const char *names[6] = {"c_s[1]", "c_s[2]", "c_s[3]", "c_s[4]", "c_s[5]", "c_s[6]"};
    for (int c = 0; c < 6; c++)
        ro.stress[c] = names[c];
    ekm_error ce = {0};
    if (cg_run(&ro, &ce))
        fail_msg("%s", ce.message);
    cg_fit_point pt;
    ekm_error err;
    const unsigned all = 1u << CG_FIT_P | 1u << CG_FIT_SXZ | 1u << CG_FIT_T | 1u << CG_FIT_MU;
    if (cg_fit_point_read(out, all, &pt, &err) != EKM_OK)
        fail_msg("%s", err.message);
    printf("cg output: phi %.4f +- %.4f  gdot %.4f +- %.4f (R^2 %.5f)  P %.1f +- %.1f  sxz %.1f +- %.1f  T "
           "%.3g +- %.2g\n",
           pt.phi, pt.phi_se, pt.gdot, pt.gdot_se, pt.r2, pt.value[CG_FIT_P], pt.se[CG_FIT_P],
           pt.value[CG_FIT_SXZ], pt.se[CG_FIT_SXZ], pt.value[CG_FIT_T], pt.se[CG_FIT_T]);
    assert_int_equal(pt.nbins, 8);
    assert_true(pt.r2 > CG_FIT_MIN_R2);
    assert_close(pt.gdot, o.gdot, 4.0 * pt.gdot_se);
    assert_close(pt.value[CG_FIT_P], o.P0 * pt.phi + o.rho_p * pt.phi * o.T0, 4.0 * pt.se[CG_FIT_P]);
    assert_close(pt.value[CG_FIT_SXZ], o.S0 * pt.phi, 4.0 * pt.se[CG_FIT_SXZ]);
    assert_close(pt.value[CG_FIT_T], o.T0, 4.0 * pt.se[CG_FIT_T]);
}

/* ---- end to end through files and the ekmcompare binary ---- */

/* A dataset as ekmcompare cg writes it: [n] (nt = 0) or [nt][n]. */
static ekm_status write_ds(ekm_h5_file *w, const char *name, const double *data, size_t nt, size_t n,
                           const char *units, ekm_error *err)
{
    const size_t dims[2] = {nt ? nt : n, n};
    return ekm_h5_write_double(w, name, nt ? 2 : 1, dims, data, units, NULL, err);
}

/* A CG-like file: one window ([1][NB]), or two (a time series) with
 * time_series set (phi written twice). */
static void write_cg_windows(const char *path, const profiles *p, int time_series)
{
    ekm_h5_file *w;
    ekm_error ce;
    double phi2[2 * NB];
    memcpy(phi2, p->phi, sizeof p->phi);
    memcpy(phi2 + NB, p->phi, sizeof p->phi);
    assert_int_equal(ekm_h5_create(&w, path, &ce), EKM_OK);
    assert_int_equal(write_ds(w, "z", p->z, 0, NB, "m", &ce), EKM_OK);
    assert_int_equal(write_ds(w, "phi", phi2, time_series ? 2 : 1, NB, "1", &ce), EKM_OK);
    assert_int_equal(write_ds(w, "phi_se", p->phi_se, 1, NB, "1", &ce), EKM_OK);
    assert_int_equal(write_ds(w, "vx", p->vx, 1, NB, "m/s", &ce), EKM_OK);
    assert_int_equal(write_ds(w, "vx_se", p->vx_se, 1, NB, "m/s", &ce), EKM_OK);
    const char *units[CG_FIT_NFIELD] = {"Pa", "Pa", "m^2/s^2", "1"};
    for (int f = 0; f < CG_FIT_NFIELD; f++) {
        char se_name[16];
        snprintf(se_name, sizeof se_name, "%s_se", cg_fit_field_name(f));
        assert_int_equal(write_ds(w, cg_fit_field_name(f), p->f[f], 1, NB, units[f], &ce), EKM_OK);
        assert_int_equal(write_ds(w, se_name, p->se[f], 1, NB, units[f], &ce), EKM_OK);
    }
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "axis", "z", &ce), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "kernel", "gauss", &ce), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double(w, NULL, "snapshots_used", 1.0, &ce), EKM_OK);
    assert_int_equal(ekm_h5_commit(w, &ce), EKM_OK);
}

static void write_cg(const char *path, const profiles *p)
{
    write_cg_windows(path, p, 0);
}

/* Run the binary; returns its exit code, stderr into errbuf. */
static int run_fit(const char *args, char *errbuf, size_t size)
{
    char errfile[512], cmd[8192];
    tmp_path(errfile, sizeof errfile, "fit_stderr.txt");
    snprintf(cmd, sizeof cmd, "%s fit %s > /dev/null 2> %s", EKMCOMPARE_BINARY, args, errfile);
    const int status = system(cmd);
    FILE *fp = fopen(errfile, "r");
    errbuf[0] = '\0';
    if (fp) {
        const size_t n = fread(errbuf, 1, size - 1, fp);
        errbuf[n] = '\0';
        fclose(fp);
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static int count_lines(const char *s)
{
    int n = 0;
    for (; *s; s++)
        n += *s == '\n';
    return n;
}

static int exists(const char *path)
{
    return access(path, F_OK) == 0;
}

/* dst: the scenario file src with its [material] section replaced by
 * `material` (the text of a [material] section). */
static void with_material(const char *src, const char *dst, const char *material)
{
    char line[1024];
    FILE *in = fopen(src, "r"), *out = fopen(dst, "w");
    assert_non_null(in);
    assert_non_null(out);
    int skip = 0;
    while (fgets(line, sizeof line, in)) {
        if (line[0] == '[')
            skip = !strncmp(line, "[material]", 10);
        if (!skip)
            fputs(line, out);
    }
    fputs(material, out);
    fclose(in);
    assert_int_equal(fclose(out), 0);
}

static void test_end_to_end(void **state)
{
    (void)state;
    char files[4096] = "", path[512], out[512], ini[512], args[8192], errbuf[4096];
    const double phis[] = {0.52, 0.57, 0.605, 0.615, 0.625, 0.632};
    const double gdots[] = {4.0, 15.0, 60.0};
    for (int a = 0; a < 6; a++)
        for (int b = 0; b < 3; b++) {
            profiles p;
            make_profiles(&p, phis[a], gdots[b], 0);
            char name[64];
            snprintf(name, sizeof name, "fit_cg_%d_%d.h5", a, b);
            write_cg(tmp_path(path, sizeof path, name), &p);
            snprintf(files + strlen(files), sizeof files - strlen(files), " %s", path);
        }
    tmp_path(out, sizeof out, "fit_out.json");
    tmp_path(ini, sizeof ini, "fit_out.ini");
    unlink(out);
    unlink(ini);
    char start[512];
    snprintf(start, sizeof start, "%s/scenarios/simple_shear.ini", EKM_SOURCE_DIR);
    snprintf(args, sizeof args, "--rheology%s --params T0,phi_co,eta0,eps0,nu --start %s -o %s --ini %s",
             files, start, out, ini);
    assert_int_equal(run_fit(args, errbuf, sizeof errbuf), 0);
    json_error_t je;
    json_t *root = json_load_file(out, 0, &je);
    assert_non_null(root);
    const ekm_material truth = truth_material();
    const char *names[] = {"T0", "phi_co", "eta0", "eps0", "nu"};
    for (int j = 0; j < 5; j++) {
        json_t *pj = json_object_get(json_object_get(root, "params"), names[j]);
        assert_non_null(pj);
        assert_true(json_is_true(json_object_get(json_object_get(root, "identifiable"), names[j])));
        const double v = json_real_value(json_object_get(pj, "value"));
        const double se = json_real_value(json_object_get(pj, "se"));
        /* the profiles are exact (scatter averages out): the truth to 1e-6 */
        assert_true(fabs(v / cg_fit_param_get(&truth, cg_fit_param_lookup(names[j])) - 1.0) < 1e-6);
        assert_true(se > 0.0);
        if (j)
            assert_true(json_is_real(
                json_object_get(json_object_get(json_object_get(root, "correlation"), names[j]), names[0])));
    }
    assert_int_equal(json_array_size(json_object_get(root, "points")), 18);
    json_t *p0 = json_array_get(json_object_get(root, "points"), 0);
    assert_true(fabs(json_real_value(json_object_get(p0, "gdot")) - 4.0) < 1e-12);
    assert_true(json_is_real(json_object_get(json_object_get(p0, "residuals"), "sxz")));
    assert_true(json_is_string(json_object_get(root, "code_version")));
    assert_true(json_is_integer(json_object_get(root, "dof")));
    json_decref(root);

    /* the INI's [material] replaces simple_shear.ini's: the fitted values load */
    char merged[512], line[1024];
    tmp_path(merged, sizeof merged, "fit_merged.ini");
    FILE *fi = fopen(ini, "r");
    assert_non_null(fi);
    char material[16384] = "";
    while (fgets(line, sizeof line, fi))
        snprintf(material + strlen(material), sizeof material - strlen(material), "%s", line);
    fclose(fi);
    with_material(start, merged, material);
    ekm_scenario sc;
    ekm_error e;
    assert_int_equal(ekm_scenario_load(&sc, merged, NULL, 0, &e), EKM_OK);
    assert_true(fabs(sc.material.T0 / truth.T0 - 1.0) < 1e-6);
    assert_true(fabs(sc.material.nu / truth.nu - 1.0) < 1e-6);
    assert_true(sc.material.rho_p == 2500.0); /* not fitted: the start file's */
    ekm_scenario_free(&sc);

    /* bad inputs: one error line, the documented exit code, no output */
    unlink(out);
    unlink(ini);
    char first[512], bagnold[512], series[512];
    tmp_path(first, sizeof first, "fit_cg_0_0.h5");
    profiles p;
    make_profiles(&p, 0.55, 12.5, 1);
    write_cg(tmp_path(bagnold, sizeof bagnold, "fit_cg_bagnold.h5"), &p);
    make_profiles(&p, 0.55, 12.5, 0);
    write_cg_windows(tmp_path(series, sizeof series, "fit_cg_series.h5"), &p, 1);
    struct {
        const char *what;
        char args[8192];
        int code;
        const char *message;
    } bad[6];
    snprintf(bad[0].args, sizeof bad[0].args, "--rheology%s %s --params T0,eta0 -o %s --ini %s", files,
             bagnold, out, ini);
    bad[0].what = "not simple shear", bad[0].code = 2, bad[0].message = "vx is not linear";
    snprintf(bad[1].args, sizeof bad[1].args, "--rheology%s --params T0,eta1 -o %s --ini %s", files, out,
             ini);
    bad[1].what = "unknown parameter", bad[1].code = 2, bad[1].message = "--params: unknown parameter 'eta1'";
    snprintf(bad[2].args, sizeof bad[2].args, "--rheology %s --params T0,eta0 -o %s --ini %s", first, out,
             ini);
    bad[2].what = "fewer points", bad[2].code = 2, bad[2].message = "1 point for 2 parameters";
    snprintf(bad[3].args, sizeof bad[3].args, "--rheology%s %s/missing.h5 --params T0 -o %s --ini %s", files,
             getenv("CG_TMPDIR") ? getenv("CG_TMPDIR") : "/tmp", out, ini);
    bad[3].what = "missing file", bad[3].code = 3, bad[3].message = "missing.h5: cannot open: No such file";
    snprintf(bad[4].args, sizeof bad[4].args, "--rheology%s --params T0 --ini %s", files, ini);
    bad[4].what = "no -o", bad[4].code = 1, bad[4].message = "expected -o FIT.json";
    snprintf(bad[5].args, sizeof bad[5].args, "--rheology%s %s --params T0 -o %s --ini %s", files, series,
             out, ini);
    bad[5].what = "time series", bad[5].code = 2,
    bad[5].message = "fit_cg_series.h5: dataset phi has 2 windows";
    for (int k = 0; k < 6; k++) {
        const int rc = run_fit(bad[k].args, errbuf, sizeof errbuf);
        printf("bad input (%s): exit %d: %s", bad[k].what, rc, errbuf);
        assert_int_equal(rc, bad[k].code);
        assert_int_equal(count_lines(errbuf), 1);
        assert_non_null(strstr(errbuf, bad[k].message));
        /* usage errors name the subcommand; the others come through ekm_error_print */
        const char *prefix = bad[k].code == 1 ? "ekmcompare fit: " : "ekmcompare: ";
        assert_int_equal(strncmp(errbuf, prefix, strlen(prefix)), 0);
        assert_false(exists(out));
        assert_false(exists(ini));
    }
}

/* The mu_i closure through the command: --closure mu_i with a start
 * scenario of that closure, P and |sxz| of mu_i in DEM-like profiles (T
 * there too, not fitted); its five parameters to 1e-6 (the profiles are
 * exact but for a scatter that averages out), FIT.json's closure and
 * FIT.ini's keys (those mu_i reads), which load as a --material file;
 * --fields T and --closure mu_i without --start refused. */
static void test_end_to_end_mu_i(void **state)
{
    (void)state;
    ekm_material truth = truth_material();
    const char *keys[] = {"mu_s", "mu_2", "I_0", "phi_max", "phi_min", "d"};
    const double values[] = {0.36, 0.7, 0.25, 0.65, 0.45, 0.002};
    for (int i = 0; i < 6; i++)
        cg_fit_param_set(&truth, cg_fit_param_lookup(keys[i]), values[i]);
    char files[4096] = "", path[512], out[512], ini[512], start[512], args[8192], errbuf[4096];
    const double phis[] = {0.52, 0.57, 0.605, 0.615, 0.625, 0.632};
    const double gdots[] = {4.0, 15.0, 60.0};
    for (int a = 0; a < 6; a++)
        for (int b = 0; b < 3; b++) {
            profiles p;
            make_profiles(&p, phis[a], gdots[b], 0);
            ekm_homog_state h;
            ekm_error e;
            assert_int_equal(ekm_closure_homog(&ekm_closure_mu_i, &truth, phis[a], gdots[b], &h, &e), EKM_OK);
            const double v[CG_FIT_NFIELD] = {h.P, h.sxz, NAN, h.mu};
            for (int k = 0; k < NB; k++)
                for (int f = 0; f < CG_FIT_NFIELD; f++)
                    if (f != CG_FIT_T) {
                        p.f[f][k] = v[f] * (k % 2 ? 1.005 : 0.995);
                        p.se[f][k] = REL_SE * v[f];
                    }
            char name[64];
            snprintf(name, sizeof name, "fit_mu_i_%d_%d.h5", a, b);
            write_cg(tmp_path(path, sizeof path, name), &p);
            /* the densest six under pressure control: phi is their response */
            snprintf(files + strlen(files), sizeof files - strlen(files), "%s %s",
                     a == 4 && b == 0 ? " --control pressure" : "", path);
        }
    /* the start: simple_shear.ini with a mu_i [material] (10-30% off) */
    char src[512];
    snprintf(src, sizeof src, "%s/scenarios/simple_shear.ini", EKM_SOURCE_DIR);
    tmp_path(start, sizeof start, "fit_mu_i_start.ini");
    with_material(
        src, start,
        "[material]\nrho_p = 2500\nmu_s = 0.4\nmu_2 = 0.6\nI_0 = 0.3\nphi_max = 0.66\nphi_min = 0.4\n"
        "d = 0.002\n");
    tmp_path(out, sizeof out, "fit_mu_i.json");
    tmp_path(ini, sizeof ini, "fit_mu_i.ini");
    unlink(out);
    unlink(ini);
    snprintf(
        args, sizeof args,
        "--rheology%s --closure mu_i --params mu_s,mu_2,I_0,phi_max,phi_min --fields P,sxz --start %s -o %s "
        "--ini %s",
        files, start, out, ini);
    if (run_fit(args, errbuf, sizeof errbuf) != 0)
        fail_msg("ekmcompare fit %s: %s", args, errbuf);
    json_error_t je;
    json_t *root = json_load_file(out, 0, &je);
    assert_non_null(root);
    assert_string_equal(json_string_value(json_object_get(root, "closure")), "mu_i");
    assert_true(json_is_null(json_object_get(root, "variant")));
    for (int j = 0; j < 5; j++) {
        json_t *pj = json_object_get(json_object_get(root, "params"), keys[j]);
        assert_non_null(pj);
        const double v = json_real_value(json_object_get(pj, "value"));
        if (!(fabs(v / values[j] - 1.0) < 1e-6))
            fail_msg("%s: fitted %.9g, truth %.9g", keys[j], v, values[j]);
    }
    assert_int_equal(json_object_size(json_object_get(root, "material")), 7);
    const json_t *points = json_object_get(root, "points");
    assert_int_equal(json_array_size(points), 18);
    for (size_t k = 0; k < 18; k++) {
        const json_t *pk = json_array_get(points, k);
        assert_string_equal(json_string_value(json_object_get(pk, "control")),
                            k >= 12 ? "pressure" : "volume");
        const double phi_model = json_real_value(json_object_get(json_object_get(pk, "model"), "phi"));
        assert_true(fabs(phi_model - json_real_value(json_object_get(pk, "phi"))) < 1e-6);
    }
    json_decref(root);
    /* FIT.ini is a --material file of a mu_i scenario */
    ekm_scenario sc;
    ekm_error e;
    const char *sets[] = {"model.closure=mu_i"};
    assert_int_equal(ekm_scenario_load_material(&sc, src, ini, sets, 1, &e), EKM_OK);
    assert_true(fabs(cg_fit_param_get(&sc.material, cg_fit_param_lookup("I_0")) / 0.25 - 1.0) < 1e-6);
    ekm_scenario_free(&sc);
    /* the same start as a material file beside the unchanged scenario
     * (--material, as the campaign's closure sets start): the same fit */
    char mat[512], out2[512];
    tmp_path(mat, sizeof mat, "fit_mu_i_material.ini");
    FILE *fm = fopen(mat, "w");
    assert_non_null(fm);
    fputs("; mu_i start\n[material]\nrho_p = 2500\nmu_s = 0.4\nmu_2 = 0.6\nI_0 = 0.3\nphi_max = 0.66\n"
          "phi_min = 0.4\nd = 0.002\n",
          fm);
    fclose(fm);
    tmp_path(out2, sizeof out2, "fit_mu_i_material.json");
    unlink(out2);
    snprintf(args, sizeof args,
             "--rheology%s --closure mu_i --params mu_s,mu_2,I_0,phi_max,phi_min --fields P,sxz --start %s "
             "--material %s -o %s",
             files, src, mat, out2);
    if (run_fit(args, errbuf, sizeof errbuf) != 0)
        fail_msg("ekmcompare fit %s: %s", args, errbuf);
    json_t *r1 = json_load_file(out, 0, &je), *r2 = json_load_file(out2, 0, &je);
    assert_non_null(r1);
    assert_non_null(r2);
    for (int j = 0; j < 5; j++) {
        const double v1 = json_real_value(
            json_object_get(json_object_get(json_object_get(r1, "params"), keys[j]), "value"));
        const double v2 = json_real_value(
            json_object_get(json_object_get(json_object_get(r2, "params"), keys[j]), "value"));
        assert_true(v1 == v2);
    }
    assert_non_null(strstr(json_string_value(json_object_get(json_object_get(r2, "start"), "source")),
                           "with [material] of"));
    json_decref(r1);
    json_decref(r2);
    snprintf(args, sizeof args, "--rheology%s --closure mu_i --params mu_s --fields P --material %s -o %s",
             files, mat, out2);
    assert_int_equal(run_fit(args, errbuf, sizeof errbuf), 1);
    assert_non_null(strstr(errbuf, "--material M.ini: for --rheology with --start FILE.ini"));
    /* refusals: one line, exit 2, no output */
    unlink(out);
    snprintf(args, sizeof args, "--rheology%s --closure mu_i --params mu_s --fields P,sxz,T --start %s -o %s",
             files, start, out);
    assert_int_equal(run_fit(args, errbuf, sizeof errbuf), 2);
    assert_non_null(strstr(errbuf, "--fields T: closure mu_i has no granular temperature"));
    assert_int_equal(count_lines(errbuf), 1);
    snprintf(args, sizeof args, "--rheology%s --closure mu_i --params mu_s --fields P -o %s", files, out);
    assert_int_equal(run_fit(args, errbuf, sizeof errbuf), 2);
    assert_non_null(strstr(errbuf, "--closure mu_i: its parameters have no defaults: give --start FILE.ini"));
    snprintf(args, sizeof args, "--rheology%s --control temperature --params mu_s --fields P -o %s", files,
             out);
    assert_int_equal(run_fit(args, errbuf, sizeof errbuf), 1);
    assert_non_null(strstr(errbuf, "--control temperature: expected volume or pressure"));
    snprintf(args, sizeof args, "--rheology%s --closure mu_i --params mu_s --fields sxz --start %s -o %s",
             files, start, out);
    assert_int_equal(run_fit(args, errbuf, sizeof errbuf), 2);
    assert_non_null(strstr(errbuf, "a pressure-controlled point needs --fields P"));
    snprintf(args, sizeof args, "--rheology%s --closure mu --params mu_s --fields P -o %s", files, out);
    assert_int_equal(run_fit(args, errbuf, sizeof errbuf), 2);
    assert_non_null(
        strstr(errbuf, "unknown closure 'mu': expected one of ekm_full, ekm_thesis, mu_i, ekm_jam"));
    assert_false(exists(out));
}

int main(void)
{
    ekm_h5_quiet();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_recovers_parameters),
        cmocka_unit_test(test_dilute_only),
        cmocka_unit_test(test_correlated_and_absent),
        cmocka_unit_test(test_fewer_points_than_params),
        cmocka_unit_test(test_profile_reduction),
        cmocka_unit_test(test_real_cg_output),
        cmocka_unit_test(test_end_to_end),
        cmocka_unit_test(test_end_to_end_mu_i),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
