/* test_score.c: scoring against synthetic ekm outputs (the solver's
 * contract: /z, /t, [nt][nz] fields with units, /regime, root attributes)
 * with known errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <jansson.h>
#include <math.h>
#include <string.h>

#include "h5.h"
#include "schema.h"
#include "score.h"
#include "test_util.h"

/* A [n] (nt == 0) or [nt][n] dataset. */
static void put(ekm_h5_file *w, const char *name, const double *data, size_t nt, size_t n, const char *units)
{
    ekm_error err;
    size_t dims[2] = {nt, n};
    ekm_status st = nt ? ekm_h5_write_double(w, name, 2, dims, data, units, NULL, &err)
                       : ekm_h5_write_double(w, name, 1, &n, data, units, NULL, &err);
    if (st)
        fail_msg("%s", err.message);
}

/* The root attributes that say which tool wrote a file (h5kind.h): a cg
 * output (kind_cg 1) or an ekm run (0); score refuses a file of the wrong
 * kind. */
static void mark_kind(ekm_h5_file *w, int kind_cg)
{
    ekm_error err;
    if (kind_cg) {
        assert_int_equal(ekm_h5_attr_set_string(w, NULL, "kernel", "gauss", &err), EKM_OK);
        assert_int_equal(ekm_h5_attr_set_double(w, NULL, "snapshots_used", 8.0, &err), EKM_OK);
    } else {
        if (!ekm_h5_attr_exists(w, NULL, "variant"))
            assert_int_equal(ekm_h5_attr_set_string(w, NULL, "variant", "full", &err), EKM_OK);
        assert_int_equal(ekm_h5_attr_set_double(w, NULL, "stats.steps", 100.0, &err), EKM_OK);
    }
}

/* An ekm-format file: f(z,t) = a + b z + c t for phi, vx, T (and P); /z
 * a row per frame (the grid does not move). */
static void write_ekm(const char *path, size_t nz, double z0, double z1, size_t nt, double t1, double a,
                      double b, double c)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    double *z = malloc(nz * nt * sizeof *z), *t = malloc(nt * sizeof *t), *f = malloc(nz * nt * sizeof *f);
    for (size_t k = 0; k < nz; k++)
        z[k] = z0 + (z1 - z0) * ((double)k + 0.5) / (double)nz;
    for (size_t i = 0; i < nt; i++)
        t[i] = nt > 1 ? t1 * (double)i / (double)(nt - 1) : t1;
    for (size_t i = 0; i < nt; i++)
        for (size_t k = 0; k < nz; k++) {
            z[i * nz + k] = z[k];
            f[i * nz + k] = a + b * z[k] + c * t[i];
        }
    put(w, "z", z, nt, nz, "m");
    put(w, "t", t, 0, nt, "s");
    const char *names[] = {"phi", "vx", "vz", "T", "P", "sxz", "szz"};
    for (size_t i = 0; i < 7; i++)
        put(w, names[i], f, nt, nz, ekm_field_units(names[i]));
    /* the contract's int32 /regime dataset */
    int *reg = calloc(nt * nz, sizeof *reg);
    size_t dims[2] = {nt, nz};
    assert_int_equal(ekm_h5_write_int(w, "regime", 2, dims, reg, "1", NULL, &err), EKM_OK);
    free(reg);
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "variant", "full", &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double(w, NULL, "gravity_z", -9.81, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "code_version", "test", &err), EKM_OK);
    mark_kind(w, 0);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
    free(z);
    free(t);
    free(f);
}

/* A cg-format file: f = a + b z + c t, SE = se everywhere. */
static void write_dem(const char *path, size_t nz, double z0, double z1, size_t nt, const double *t, double a,
                      double b, double c, double se)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    double *z = malloc(nz * sizeof *z), *f = malloc(nz * nt * sizeof *f), *s = malloc(nz * nt * sizeof *s);
    for (size_t k = 0; k < nz; k++)
        z[k] = z0 + (z1 - z0) * ((double)k + 0.5) / (double)nz;
    for (size_t i = 0; i < nt; i++)
        for (size_t k = 0; k < nz; k++) {
            f[i * nz + k] = a + b * z[k] + c * t[i];
            s[i * nz + k] = se;
        }
    put(w, "z", z, 0, nz, "m");
    put(w, "t", t, 0, nt, "s");
    const char *names[] = {"phi", "vx", "T"};
    char sen[32];
    for (size_t i = 0; i < 3; i++) {
        put(w, names[i], f, nt, nz, ekm_field_units(names[i]));
        snprintf(sen, sizeof sen, "%s_se", names[i]);
        put(w, sen, s, nt, nz, ekm_field_units(names[i]));
    }
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "axis", "z", &err), EKM_OK);
    mark_kind(w, 1);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
    free(z);
    free(f);
    free(s);
}

/* Scores o into r (at most 16 fields); fails the test with the tool's
 * message on any error.  Returns the number of fields. */
static size_t score_ok(const cg_score_opts *o, cg_score_field *r)
{
    size_t n;
    ekm_error err;
    if (cg_score(o, r, &n, &err))
        fail_msg("%s", err.message);
    return n;
}

/* SCORE.json, parsed; NULL fails the test */
static json_t *load_json(const char *path)
{
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root)
        fail_msg("%s:%d: %s", path, jerr.line, jerr.text);
    return root;
}

/* root[a][b] (b NULL: root[a]), which must exist */
static json_t *get(json_t *root, const char *a, const char *b)
{
    json_t *v = json_object_get(root, a);
    if (v && b)
        v = json_object_get(v, b);
    if (!v)
        fail_msg("no %s%s%s in the score's JSON", a, b ? "." : "", b ? b : "");
    return v;
}

/* root[a][b] as a number (integer or real) */
static double num(json_t *root, const char *a, const char *b)
{
    json_t *v = get(root, a, b);
    assert_true(json_is_number(v));
    return json_number_value(v);
}

/* the whole text of a file (fits in the buffer) */
static void slurp(const char *path, char *buf, size_t size)
{
    FILE *fp = fopen(path, "r");
    assert_non_null(fp);
    size_t len = fread(buf, 1, size - 1, fp);
    assert_true(len < size - 1);
    buf[len] = '\0';
    fclose(fp);
}

static void test_known_errors(void **state)
{
    (void)state;
    char ekm[512], dem[512], js[512];
    tmp_path(ekm, sizeof ekm, "score_ekm.h5");
    tmp_path(dem, sizeof dem, "score_dem.h5");
    /* EKM on a finer grid over [0, 1], times 0..2; linear in z and t, so the
     * interpolation is exact. DEM = EKM - 0.01 at t = 0.5 and 1.5. */
    write_ekm(ekm, 50, 0.0, 1.0, 5, 2.0, 1.0, 2.0, 0.5);
    double t[2] = {0.5, 1.5};
    write_dem(dem, 10, 0.0, 1.0, 2, t, 1.0 - 0.01, 2.0, 0.5, 0.02);
    cg_score_opts o = cg_score_opts_default();
    o.dem = dem;
    o.ekm = ekm;
    o.json = tmp_path(js, sizeof js, "score.json");
    cg_score_field r[16];
    size_t n = score_ok(&o, r);
    assert_int_equal(n, 3); /* phi, vx, T: in both files */
    /* DEM centres 0.05..0.95; EKM centres 0.01..0.99: all 10 x 2 inside */
    double sd2 = 0;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 10; k++) {
            double d = 0.99 + 2.0 * (0.05 + 0.1 * k) + 0.5 * t[i];
            sd2 += d * d;
        }
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(r[i].points, 20);
        assert_int_equal(r[i].points_se, 20);
        assert_close(r[i].rel_l2, 0.01 * sqrt(20.0 / sd2), 1e-9);
        assert_close(r[i].noise, 0.5, 1e-9);
    }
    json_t *root = load_json(js);
    json_t *phi = get(root, "fields", "phi");
    assert_int_equal(json_integer_value(json_object_get(phi, "points")), 20);
    assert_true(json_is_integer(json_object_get(phi, "points")));
    assert_close(num(phi, "noise_normalised", NULL), 0.5, 1e-8);
    /* the options that produced it: the fields found in both, the default
     * time matching, no shift, an EKM run as the model */
    json_t *opt = get(root, "options", NULL);
    const char *order[] = {"fields",           "ekm_time", "shift_m",     "model",  "se",
                           "se_floor_rel_rms", "support",  "support_phi", "scalars"};
    size_t k = 0;
    const char *key;
    json_t *val;
    json_object_foreach(opt, key, val)
    {
        assert_true(k < sizeof order / sizeof *order);
        assert_string_equal(key, order[k++]);
    }
    assert_int_equal(k, sizeof order / sizeof *order);
    json_t *fl = get(opt, "fields", NULL);
    assert_int_equal(json_array_size(fl), 3);
    assert_string_equal(json_string_value(json_array_get(fl, 0)), "phi");
    assert_string_equal(json_string_value(json_array_get(fl, 2)), "T");
    assert_string_equal(json_string_value(get(opt, "ekm_time", NULL)), "interp");
    assert_true(num(opt, "shift_m", NULL) == 0.0);
    assert_string_equal(json_string_value(get(opt, "model", NULL)), "ekm");
    assert_string_equal(json_string_value(get(opt, "se", NULL)), "dem");
    assert_true(num(opt, "se_floor_rel_rms", NULL) == 1e-6);
    assert_true(num(opt, "support", NULL) == 0.1);
    /* no checksums given: no inputs record */
    assert_null(json_object_get(root, "inputs"));
    json_decref(root);
    /* reals to 9 significant digits, as the committed results print them */
    char buf[4096];
    slurp(js, buf, sizeof buf);
    assert_non_null(strstr(buf, "\"se_floor_rel_rms\": 1e-6,"));
    assert_non_null(strstr(buf, "\"noise_normalised\": 0.5,"));
    /* the inputs' checksums, given, are recorded with their paths */
    const char *sd = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
    const char *se = "fedcba9876543210fedcba9876543210fedcba9876543210fedcba9876543210";
    o.dem_sha256 = sd;
    o.ekm_sha256 = se;
    score_ok(&o, r);
    root = load_json(js);
    assert_string_equal(json_string_value(get(get(root, "inputs", "dem"), "path", NULL)), dem);
    assert_string_equal(json_string_value(get(get(root, "inputs", "dem"), "sha256", NULL)), sd);
    assert_string_equal(json_string_value(get(get(root, "inputs", "ekm"), "path", NULL)), ekm);
    assert_string_equal(json_string_value(get(get(root, "inputs", "ekm"), "sha256", NULL)), se);
    json_decref(root);
    /* one checksum alone, or one that is not 64 lower-case hex digits, is
     * a usage error and leaves the last JSON as it was */
    ekm_error err;
    size_t nres;
    char before[4096], after[4096];
    slurp(js, before, sizeof before);
    o.ekm_sha256 = NULL;
    assert_int_equal(cg_score(&o, r, &nres, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "both --dem-sha256 and --ekm-sha256"));
    o.ekm_sha256 = "FEDCBA9876543210FEDCBA9876543210FEDCBA9876543210FEDCBA9876543210";
    assert_int_equal(cg_score(&o, r, &nres, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "--ekm-sha256: expected 64 lower-case hexadecimal digits"));
    o.ekm_sha256 = se;
    o.json = NULL; /* checksums with nowhere to record them */
    assert_int_equal(cg_score(&o, r, &nres, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "expected -o"));
    o.json = js;
    slurp(js, after, sizeof after);
    assert_string_equal(before, after);
    o.support = 0.1000000001;
    assert_int_equal(cg_score(&o, r, &nres, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "--support: expected at most 9 significant digits"));
    o.support = 0.1;
    /* an option the JSON cannot record exactly (more than 9 digits) */
    o.shift = 0.1234567891;
    assert_int_equal(cg_score(&o, r, &nres, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "--shift: expected at most 9 significant digits"));
    root = load_json(js);
    assert_true(num(root, "options", "shift_m") == 0.0);
    json_decref(root);
}

/* A layer of phi = 0.6 up to a height h (the bins or cells wholly below it;
 * empty above), vx = 10 z, on nz points over [0, top]; a DEM file (one
 * time, t = 1, with SEs 0.01 and mean_diameter) or an ekm-format one
 * (t = 0 and 1). */
static void write_layer(const char *path, int dem, size_t nz, double top, double h, double diameter)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    size_t nt = dem ? 1 : 2;
    double z[64], t[2] = {dem ? 1.0 : 0.0, 1.0}, phi[128], vx[128], se[128];
    for (size_t k = 0; k < nz; k++)
        z[k] = top * ((double)k + 0.5) / (double)nz;
    for (size_t i = 0; i < nt; i++)
        for (size_t k = 0; k < nz; k++) {
            phi[i * nz + k] = z[k] < h ? 0.6 : 0.0;
            vx[i * nz + k] = 10.0 * z[k];
            se[i * nz + k] = 0.01;
        }
    put(w, "z", z, 0, nz, "m");
    put(w, "t", t, 0, nt, "s");
    put(w, "phi", phi, nt, nz, "1");
    put(w, "vx", vx, nt, nz, "m/s");
    if (dem) {
        put(w, "phi_se", se, nt, nz, "1");
        put(w, "vx_se", se, nt, nz, "m/s");
        assert_int_equal(ekm_h5_attr_set_string(w, NULL, "axis", "z", &err), EKM_OK);
        assert_int_equal(ekm_h5_attr_set_double(w, NULL, "mean_diameter", diameter, &err), EKM_OK);
    }
    mark_kind(w, dem);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
}

/* Common support and the free-surface offset, exactly: the DEM layer
 * (20 bins of 1 mm) fills the bins below 10 mm, the model's (40 cells of
 * 0.5 mm) those below 7 mm. Layer heights (phi crossing 0.3 halfway between
 * a full and an empty point): 9.5 mm + 0.5 x 1 mm = 10 mm and
 * 6.75 mm + 0.5 x 0.5 mm = 7 mm, offset -3 mm = -3 d (d = 1 mm). The
 * threshold is 0.1 x 0.6; the DEM bins at 0.5 .. 6.5 mm have material on
 * both sides (7 points), the other 13 of the 20 (all inside the model's
 * range) are left out. */
static void test_common_support(void **state)
{
    (void)state;
    char dem[512], ekm[512], js[512];
    tmp_path(dem, sizeof dem, "support_dem.h5");
    tmp_path(ekm, sizeof ekm, "support_ekm.h5");
    write_layer(dem, 1, 20, 0.02, 0.0100, 0.001);
    write_layer(ekm, 0, 40, 0.02, 0.0070, 0.0);
    cg_score_opts o = cg_score_opts_default();
    cg_score_summary sm;
    o.dem = dem;
    o.ekm = ekm;
    o.ekm_last = 1;
    o.summary = &sm;
    o.json = tmp_path(js, sizeof js, "support.json");
    cg_score_field r[16];
    size_t n = score_ok(&o, r);
    assert_int_equal(n, 2); /* phi, vx */
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(r[i].points, 7);
        assert_int_equal(r[i].points_left_out, 13);
    }
    /* on the support both layers are full and vx agrees: no error */
    assert_close(r[0].rel_l2, 0.0, 1e-15);
    assert_close(r[1].rel_l2, 0.0, 1e-12);
    assert_close(sm.support_phi, 0.06, 1e-15);
    assert_close(sm.dem_height, 0.010, 1e-15);
    assert_close(sm.model_height, 0.007, 1e-15);
    assert_close(sm.mean_diameter, 0.001, 0);
    json_t *root = load_json(js);
    assert_int_equal(json_integer_value(get(get(root, "fields", "phi"), "points", NULL)), 7);
    assert_int_equal(json_integer_value(get(get(root, "fields", "phi"), "points_with_se", NULL)), 7);
    assert_int_equal(json_integer_value(get(get(root, "fields", "phi"), "points_left_out", NULL)), 13);
    assert_close(num(root, "free_surface", "dem_m"), 0.010, 1e-12);
    assert_close(num(root, "free_surface", "model_m"), 0.007, 1e-12);
    assert_close(num(root, "free_surface", "offset_m"), -0.003, 1e-12);
    assert_close(num(root, "free_surface", "mean_diameter_m"), 0.001, 1e-12);
    assert_close(num(root, "free_surface", "dem_d"), 10, 1e-9);
    assert_close(num(root, "free_surface", "model_d"), 7, 1e-9);
    assert_close(num(root, "free_surface", "offset_d"), -3, 1e-9);
    assert_true(num(root, "options", "support") == 0.1);
    assert_close(num(root, "options", "support_phi"), 0.06, 1e-12);
    json_decref(root);
    /* --support 0: every covered point, none left out */
    o.support = 0.0;
    o.json = NULL;
    n = score_ok(&o, r);
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(r[i].points, 20);
        assert_int_equal(r[i].points_left_out, 0);
    }
    assert_close(sm.dem_height - sm.model_height, 0.003, 1e-15);
    /* a fraction outside [0, 1) is a usage error */
    ekm_error err;
    o.support = 1.0;
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "--support"));
    /* the scalars of both sides; an unknown name is refused */
    o.support = 0.1;
    o.scalars = "layer_height,surface_velocity";
    score_ok(&o, r);
    assert_int_equal(sm.nscalars, 2);
    assert_string_equal(sm.scalar[0].name, "layer_height");
    assert_close(sm.scalar[0].dem, 0.010, 1e-15);
    assert_close(sm.scalar[0].model, 0.007, 1e-15);
    /* phi falls 0.6 -> 0 over 1 mm, crossing halfway: se = 1 mm / 0.6 x
     * sqrt((0.5 x 0.01)^2 + (0.5 x 0.01)^2) */
    assert_close(sm.scalar[0].dem_se, 0.001 / 0.6 * sqrt(0.5) * 0.01, 1e-15);
    assert_true(isnan(sm.scalar[0].model_se));
    assert_close(sm.scalar[1].dem, 10.0 * 0.0095, 1e-14);
    assert_close(sm.scalar[1].model, 10.0 * 0.00675, 1e-14);
    o.scalars = "layer_height,speed";
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "unknown scalar 'speed'"));
}

/* Engine against engine: the second file is coarse-grained DEM with its
 * own standard errors, which add in quadrature. */
static void test_dem_against_dem(void **state)
{
    (void)state;
    char a[512], b[512];
    tmp_path(a, sizeof a, "score_dem_a.h5");
    tmp_path(b, sizeof b, "score_dem_b.h5");
    double t[2] = {0.5, 1.5};
    write_dem(a, 10, 0.0, 1.0, 2, t, 1.0, 2.0, 0.5, 0.02);
    write_dem(b, 10, 0.0, 1.0, 2, t, 1.0 - 0.01, 2.0, 0.5, 0.02);
    char js[512];
    cg_score_opts o = cg_score_opts_default();
    o.dem = a;
    o.ekm = b;
    cg_score_field r[16];
    size_t n = score_ok(&o, r);
    assert_int_equal(n, 3);
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(r[i].se_both, 1);
        /* same grid: all 10 x 2 points compared */
        assert_int_equal(r[i].points, 20);
        assert_close(r[i].noise, 0.5 / sqrt(2.0), 1e-9);
    }
    /* the options as given, the shift as it reads back; the model side is a
     * second DEM run */
    o.fields = "T,phi";
    o.ekm_last = 1;
    o.shift = 0.1;
    o.json = tmp_path(js, sizeof js, "score_dd.json");
    assert_int_equal(score_ok(&o, r), 2);
    json_t *root = load_json(js);
    json_t *opt = get(root, "options", NULL);
    assert_string_equal(json_string_value(json_array_get(get(opt, "fields", NULL), 0)), "T");
    assert_string_equal(json_string_value(json_array_get(get(opt, "fields", NULL), 1)), "phi");
    assert_string_equal(json_string_value(get(opt, "ekm_time", NULL)), "last");
    assert_true(num(opt, "shift_m", NULL) == 0.1);
    assert_string_equal(json_string_value(get(opt, "model", NULL)), "dem");
    assert_string_equal(json_string_value(get(opt, "se", NULL)), "dem and model in quadrature");
    json_decref(root);
}

/* Standard errors of round-off size (a bin one grain crossed once) are not
 * noise: points with SE below 1e-6 of the field's RMS are left out of the
 * noise-normalised error, but still count in the relative L2 error. */
static void test_se_floor(void **state)
{
    (void)state;
    char ekm[512], dem[512];
    tmp_path(ekm, sizeof ekm, "score_floor_ekm.h5");
    tmp_path(dem, sizeof dem, "score_floor_dem.h5");
    write_ekm(ekm, 50, 0.0, 1.0, 5, 2.0, 1.0, 2.0, 0.5);
    double t[2] = {0.5, 1.5};
    write_dem(dem, 10, 0.0, 1.0, 2, t, 1.0 - 0.01, 2.0, 0.5, 1e-12);
    cg_score_opts o = cg_score_opts_default();
    o.dem = dem;
    o.ekm = ekm;
    cg_score_field r[16];
    /* no SE above the floor: the noise-normalised error is undefined, an
     * error naming the field (never a null in the JSON) */
    size_t n;
    ekm_error err;
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_ENUMERIC);
    assert_non_null(strstr(err.message,
                           "field phi: noise_normalised undefined: none of the 20 points compared "
                           "has a standard error above 1e-06 x the field's RMS"));
    /* just above the floor (RMS of the DEM field is about 2.5): counted */
    write_dem(dem, 10, 0.0, 1.0, 2, t, 1.0 - 0.01, 2.0, 0.5, 1e-5);
    n = score_ok(&o, r);
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(r[i].points_se, 20);
        assert_close(r[i].noise, 0.01 / 1e-5, 1e-6);
    }
}

/* Region: DEM points outside the EKM's z range are left out; DEM times
 * outside the EKM's fall back to the EKM's last output. */
static void test_region_and_last(void **state)
{
    (void)state;
    char ekm[512], dem[512];
    tmp_path(ekm, sizeof ekm, "score_ekm2.h5");
    tmp_path(dem, sizeof dem, "score_dem2.h5");
    write_ekm(ekm, 10, 0.0, 0.5, 3, 1.0, 1.0, 0.0, 1.0); /* centres 0.025..0.475 */
    double t[1] = {5.0};
    write_dem(dem, 10, 0.0, 1.0, 1, t, 2.0, 0.0, 0.0, 0.1); /* equals EKM at t = 1 */
    cg_score_opts o = cg_score_opts_default();
    o.dem = dem;
    o.ekm = ekm;
    o.fields = "phi";
    cg_score_field r[16];
    size_t n = score_ok(&o, r);
    assert_int_equal(n, 1);
    assert_int_equal(r[0].points, 5); /* DEM centres 0.05 .. 0.45 */
    assert_close(r[0].rel_l2, 0.0, 1e-14);
    assert_close(r[0].noise, 0.0, 1e-12);
}

static void test_bad_inputs(void **state)
{
    (void)state;
    char ekm[512], dem[512], junk[512];
    tmp_path(ekm, sizeof ekm, "score_ekm3.h5");
    tmp_path(dem, sizeof dem, "score_dem3.h5");
    write_ekm(ekm, 10, 0.0, 1.0, 2, 1.0, 1.0, 0.0, 0.0);
    double t[1] = {0.5};
    write_dem(dem, 10, 0.0, 1.0, 1, t, 1.0, 0.0, 0.0, 0.1);
    cg_score_opts o = cg_score_opts_default();
    cg_score_field r[16];
    size_t n;
    ekm_error err;
    o.dem = dem;
    o.ekm = "/nonexistent/run.h5";
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EIO);
    assert_non_null(strstr(err.message, "/nonexistent/run.h5: cannot open"));
    write_text(tmp_path(junk, sizeof junk, "junk.h5"), "not hdf5\n");
    o.ekm = junk;
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "expected an HDF5 file"));
    o.ekm = ekm;
    o.fields = "phi,P";
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "score_dem3.h5: expected a dataset P"));
    o.fields = "phi,,T";
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EUSAGE);
    /* a name the field schema does not know */
    o.fields = "phi,bogus";
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "--fields: unknown field 'bogus' (the fields are: "));
    assert_non_null(strstr(err.message, " phi "));
    /* units other than the schema's */
    char wrong[512];
    tmp_path(wrong, sizeof wrong, "score_wrong_units.h5");
    ekm_h5_file *w;
    assert_int_equal(ekm_h5_create(&w, wrong, &err), EKM_OK);
    double z[10], tt[2] = {0.0, 1.0}, f[20];
    for (size_t k = 0; k < 10; k++)
        z[k] = ((double)k + 0.5) / 10.0;
    for (size_t k = 0; k < 20; k++)
        f[k] = 1.0;
    put(w, "z", z, 0, 10, "m");
    put(w, "t", tt, 0, 2, "s");
    put(w, "phi", f, 2, 10, "kg");
    int reg[20] = {0};
    size_t dims[2] = {2, 10};
    assert_int_equal(ekm_h5_write_int(w, "regime", 2, dims, reg, "1", NULL, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "variant", "full", &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double(w, NULL, "gravity_z", -9.81, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "code_version", "test", &err), EKM_OK);
    mark_kind(w, 0);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
    o.ekm = wrong;
    o.fields = "phi";
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message,
                           "score_wrong_units.h5: dataset phi: units 'kg', expected '1' (the field schema)"));
}

/* An EKM shear cell with a pressure-held top wall: 4 cells, /gap 20 mm at
 * t = 0 and 10 mm at t = t1, phi 0.6, vx of no-slip Couette flow
 * (0.05 .. 0.35 m/s, the wall at 0.4 m/s: the attribute top.velocity); /z
 * the centres of each frame (per_frame 1), or (0) an output from before /z
 * had a row per frame: the initial grid of 20 mm. */
static void write_pressure_wall(const char *path, double t1, int per_frame)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    double z[8], t[2] = {0.0, t1}, gap[2] = {0.020, 0.010}, phi[8], vx[8];
    for (size_t k = 0; k < 4; k++) {
        for (size_t i = 0; i < 2; i++) {
            z[i * 4 + k] = gap[i] / 4.0 * ((double)k + 0.5);
            phi[i * 4 + k] = 0.6;
            vx[i * 4 + k] = 0.1 * ((double)k + 0.5);
        }
    }
    put(w, "z", z, per_frame ? 2 : 0, 4, "m");
    put(w, "t", t, 0, 2, "s");
    put(w, "gap", gap, 0, 2, "m");
    put(w, "phi", phi, 2, 4, "1");
    put(w, "vx", vx, 2, 4, "m/s");
    assert_int_equal(ekm_h5_attr_set_double(w, NULL, "top.velocity", 0.4, &err), EKM_OK);
    mark_kind(w, 0);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
}

/* The shear-cell scalars through the scorer: the EKM's frame is its /z row
 * of the compared time (or, in an output with one /z for all frames, that
 * stretched by gap(t) / gap[0]), so its gap is the /gap of the compared
 * time (10 mm at its last output, 15 mm halfway), and its extrapolated
 * wall velocity the wall's (slip 0); the wall velocity of the EKM file
 * serves the DEM side too. The DEM layer (write_layer: phi 0.6 below
 * 10 mm on 20 bins of 1 mm, vx = 10 z) starts at the grid's end, z = 0,
 * and ends at the crossing, 10 mm (SE as in test_common_support); vx there
 * is 0.1 m/s: slip 0.3 m/s, SE sqrt(0.01^2 + (10 x se_edge)^2). */
static void test_pressure_wall_scalars(void **state)
{
    (void)state;
    char dem[512], ekm[512];
    tmp_path(dem, sizeof dem, "pwall_dem.h5");
    tmp_path(ekm, sizeof ekm, "pwall_ekm.h5");
    write_layer(dem, 1, 20, 0.02, 0.0100, 0.001);
    cg_score_opts o = cg_score_opts_default();
    cg_score_summary sm;
    cg_score_field r[16];
    o.dem = dem;
    o.ekm = ekm;
    o.summary = &sm;
    o.fields = "phi";
    o.scalars = "gap,wall_slip";
    for (int per_frame = 1; per_frame >= 0; per_frame--) {
        write_pressure_wall(ekm, 1.0, per_frame);
        o.ekm_last = 1;
        score_ok(&o, r);
        assert_int_equal(sm.nscalars, 2);
        double se_edge = 0.001 / 0.6 * sqrt(0.5) * 0.01;
        assert_string_equal(sm.scalar[0].name, "gap");
        assert_close(sm.scalar[0].dem, 0.010, 1e-15);
        assert_close(sm.scalar[0].dem_se, se_edge, 1e-15);
        assert_close(sm.scalar[0].model, 0.010, 1e-15);
        assert_close(sm.scalar[0].model_se, 0.0, 0);
        assert_string_equal(sm.scalar[1].name, "wall_slip");
        assert_close(sm.scalar[1].dem, 0.3, 1e-14);
        assert_close(sm.scalar[1].dem_se, sqrt(1e-4 + pow(10.0 * se_edge, 2)), 1e-15);
        assert_close(sm.scalar[1].model, 0.0, 1e-15);
        /* the DEM time (1 s) halfway between the EKM's outputs at 0 and 2 s:
         * the grid interpolated, gap 15 mm */
        write_pressure_wall(ekm, 2.0, per_frame);
        o.ekm_last = 0;
        score_ok(&o, r);
        assert_close(sm.scalar[0].model, 0.015, 1e-15);
    }
    /* a /gap that does not match /t is refused */
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, ekm, &err), EKM_OK);
    double z[2] = {0.005, 0.015}, t[1] = {1.0}, gap[2] = {0.02, 0.02}, phi[2] = {0.6, 0.6};
    put(w, "z", z, 1, 2, "m");
    put(w, "t", t, 0, 1, "s");
    put(w, "gap", gap, 0, 2, "m");
    put(w, "phi", phi, 1, 2, "1");
    mark_kind(w, 0);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
    size_t n;
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "pwall_ekm.h5: dataset gap: expected [1] positive values"));
    /* so is a /z whose rows are not one per output time */
    assert_int_equal(ekm_h5_create(&w, ekm, &err), EKM_OK);
    double z2[4] = {0.005, 0.015, 0.005, 0.015};
    put(w, "z", z2, 2, 2, "m");
    put(w, "t", t, 0, 1, "s");
    put(w, "phi", phi, 1, 2, "1");
    mark_kind(w, 0);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
    assert_int_equal(cg_score(&o, r, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message,
                           "pwall_ekm.h5: dataset z: expected one row of 2 cell centres per output "
                           "time (1), got 2 rows"));
}

/* An EKM run with a pressure-held wall whose fields are a known function
 * of the moving coordinate: 8 cells, outputs at t = 0 and 2 s with gaps 20
 * and 10 mm; phi, vx, T at cell k and output i are a + b z_ki + c t_i with
 * z_ki = (k + 1/2) gap_i / 8, the cell's position at that time: f(z, t) =
 * a + b z + c t.  The file's /z and /gap by layout:
 *   PW_ROWS   /z [2][8], each frame's centres, and /gap (ekm's layout);
 *   PW_FIRST  /z [8] the first frame's (centres 1.25 .. 18.75 mm) and
 *             /gap (an ekm output from before /z had a row per frame);
 *   PW_FLAT   /z [8] the first frame's, no /gap: the same values on an
 *             unmoving grid (the error of a reader that ignores the motion);
 *   PW_STILL  /z [2][8] both rows the first frame's, with /gap: the rows
 *             are what counts, so this scores as PW_FLAT. */
#define PW_A 0.5
#define PW_B 10.0
#define PW_C 0.01
enum { PW_ROWS, PW_FIRST, PW_FLAT, PW_STILL };
static void write_pwall_fields(const char *path, int layout)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    double z[16], t[2] = {0.0, 2.0}, g[2] = {0.020, 0.010}, f[16];
    for (size_t k = 0; k < 8; k++)
        for (size_t i = 0; i < 2; i++) {
            z[i * 8 + k] = (layout == PW_ROWS ? g[i] : g[0]) / 8.0 * ((double)k + 0.5);
            f[i * 8 + k] = PW_A + PW_B * g[i] / 8.0 * ((double)k + 0.5) + PW_C * t[i];
        }
    put(w, "z", z, layout == PW_ROWS || layout == PW_STILL ? 2 : 0, 8, "m");
    put(w, "t", t, 0, 2, "s");
    if (layout != PW_FLAT)
        put(w, "gap", g, 0, 2, "m");
    const char *names[] = {"phi", "vx", "T"};
    for (size_t i = 0; i < 3; i++)
        put(w, names[i], f, 2, 8, ekm_field_units(names[i]));
    mark_kind(w, 0);
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
}

/* rel. L2 and noise-normalised error of an EKM that is the DEM's
 * f = a + b z + c t with its z scaled by q_j at DEM time t_j, over the DEM
 * points z_k (SE se). */
static void scaled_errors(const double *zk, size_t nz, const double *t, const double *q, size_t nt, double se,
                          double *rel, double *noise)
{
    double e2 = 0, d2 = 0;
    for (size_t j = 0; j < nt; j++)
        for (size_t k = 0; k < nz; k++) {
            double d = PW_A + PW_B * zk[k] + PW_C * t[j], e = PW_B * zk[k] * (q[j] - 1.0);
            e2 += e * e;
            d2 += d * d;
        }
    *rel = sqrt(e2 / d2);
    *noise = sqrt(e2 / (double)(nz * nt)) / se;
}

/* The field scores on the EKM's grid at the compared time (issue 11: the
 * shear cell's EKM was compared on its initial 42 mm grid while its gap was
 * 38.4 mm; issue 32: /z holds each frame's centres). The DEM (10 bins of
 * 1 mm, centres 0.5 .. 9.5 mm, SE 0.01) is sampled from the same f: on the
 * moving grid (ekm's rows of /z, or an older output's /z stretched by its
 * /gap) every field scores 0; on the unmoving grid (no /gap, or rows that
 * do not move) it does not, by exactly the error of the unmoved EKM. */
static void test_pressure_wall_fields(void **state)
{
    (void)state;
    char dem[512], ekm[512], flat[512];
    tmp_path(dem, sizeof dem, "pwf_dem.h5");
    tmp_path(ekm, sizeof ekm, "pwf_ekm.h5");
    tmp_path(flat, sizeof flat, "pwf_flat.h5");
    double zk[10];
    for (size_t k = 0; k < 10; k++)
        zk[k] = 0.001 * ((double)k + 0.5);
    cg_score_opts o = cg_score_opts_default();
    cg_score_field r[16];
    double rel, noise;
    o.dem = dem;
    o.fields = "phi,vx,T";
    for (int moving = PW_ROWS; moving <= PW_FIRST; moving++)
        for (int still = PW_FLAT; still <= PW_STILL; still++) {
            write_pwall_fields(ekm, moving);
            write_pwall_fields(flat, still);
            /* --ekm-time last, the DEM at the EKM's last time (2 s): its
             * centres are 0.625 .. 9.375 mm (gap 10 mm), which cover the
             * DEM's 1.5 .. 8.5 mm: 8 points, error 0; the DEM's 0.5 and
             * 9.5 mm, with material, lie outside them: 2 points left out */
            double t_last[1] = {2.0};
            write_dem(dem, 10, 0.0, 0.01, 1, t_last, PW_A, PW_B, PW_C, 0.01);
            o.ekm_last = 1;
            o.ekm = ekm;
            assert_int_equal(score_ok(&o, r), 3);
            for (size_t i = 0; i < 3; i++) {
                assert_int_equal(r[i].points, 8);
                assert_int_equal(r[i].points_left_out, 2);
                assert_close(r[i].rel_l2, 0.0, 1e-14);
                assert_close(r[i].noise, 0.0, 1e-11);
            }
            /* the unmoved grid (1.25 .. 18.75 mm: 9 points, 1.5 .. 9.5 mm)
             * carries the last output at twice its positions: the EKM there
             * is f(z/2) */
            double q_last[1] = {0.5};
            scaled_errors(zk + 1, 9, t_last, q_last, 1, 0.01, &rel, &noise);
            o.ekm = flat;
            score_ok(&o, r);
            for (size_t i = 0; i < 3; i++) {
                assert_int_equal(r[i].points, 9);
                assert_close(r[i].rel_l2, rel, 1e-12);
                assert_close(r[i].noise, noise, 1e-9);
                assert_true(r[i].rel_l2 > 0.05);
            }
            /* interpolated in time: DEM windows at 0.5 and 1.5 s, the gap
             * 17.5 and 12.5 mm (linear in time as the fields), centres from
             * 1.09 and 0.78 mm: 9 points per time, error 0 */
            double t_mid[2] = {0.5, 1.5};
            write_dem(dem, 10, 0.0, 0.01, 2, t_mid, PW_A, PW_B, PW_C, 0.01);
            o.ekm_last = 0;
            o.ekm = ekm;
            score_ok(&o, r);
            for (size_t i = 0; i < 3; i++) {
                assert_int_equal(r[i].points, 18);
                assert_close(r[i].rel_l2, 0.0, 1e-14);
                assert_close(r[i].noise, 0.0, 1e-11);
            }
            /* unmoved: the EKM at time t is f(z s(t)), s = 1 - t/4 */
            double q_mid[2] = {0.875, 0.625};
            scaled_errors(zk + 1, 9, t_mid, q_mid, 2, 0.01, &rel, &noise);
            o.ekm = flat;
            score_ok(&o, r);
            for (size_t i = 0; i < 3; i++) {
                assert_int_equal(r[i].points, 18);
                assert_close(r[i].rel_l2, rel, 1e-12);
                assert_close(r[i].noise, noise, 1e-9);
                assert_true(r[i].rel_l2 > 0.02);
            }
        }
}

/* The model's cell centres at a time level: a /z row per frame (an ekm
 * output) interpolated in time between the two rows, whatever /gap says;
 * one /z for all frames: itself without /gap, else (an ekm output from
 * before /z had a row per frame) stretched by the gap interpolated in time. */
static void test_cell_centres(void **state)
{
    (void)state;
    const double z0[3] = {0.5, 1.5, 2.5}, gap[3] = {3.0, 1.5, 6.0};
    double z[3];
    cg_score_centres(z0, 0, 3, NULL, 1, 2, 0.5, z);
    for (size_t k = 0; k < 3; k++)
        assert_true(z[k] == z0[k]);
    cg_score_centres(z0, 0, 3, gap, 1, 2, 0.0, z); /* gap 1.5 of 3 */
    for (size_t k = 0; k < 3; k++)
        assert_close(z[k], 0.5 * z0[k], 1e-15);
    cg_score_centres(z0, 0, 3, gap, 1, 2, 0.5, z); /* gap 3.75 of 3 */
    for (size_t k = 0; k < 3; k++)
        assert_close(z[k], 1.25 * z0[k], 1e-15);
    cg_score_centres(z0, 0, 3, gap, 2, 2, 0.0, z); /* the last level: 6 of 3 */
    for (size_t k = 0; k < 3; k++)
        assert_close(z[k], 2.0 * z0[k], 1e-15);
    /* rows of 3 frames (not a uniform stretch: the rows are what count) */
    const double rows[9] = {0.5, 1.5, 2.5, 0.2, 0.4, 1.0, 1.0, 2.0, 5.0};
    cg_score_centres(rows, 1, 3, gap, 1, 2, 0.25, z);
    const double want[3] = {0.4, 0.8, 2.0};
    for (size_t k = 0; k < 3; k++)
        assert_close(z[k], want[k], 1e-15);
    cg_score_centres(rows, 1, 3, NULL, 2, 2, 0.0, z);
    for (size_t k = 0; k < 3; k++)
        assert_true(z[k] == rows[6 + k]);
}

int main(void)
{
    ekm_h5_quiet();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_errors),
        cmocka_unit_test(test_region_and_last),
        cmocka_unit_test(test_dem_against_dem),
        cmocka_unit_test(test_se_floor),
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_common_support),
        cmocka_unit_test(test_pressure_wall_scalars),
        cmocka_unit_test(test_pressure_wall_fields),
        cmocka_unit_test(test_cell_centres),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
