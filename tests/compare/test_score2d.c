/* test_score2d.c: `ekmcompare score2d` (compare/score2d.h) against
 * synthetic files with known answers:
 *   - a DEM map (x, z, phi, sxx, szz, sxz, FIELD_se, mask; compression
 *     positive) of fields linear in x and z, its top row empty;
 *   - an ekm run on a coarser, shifted grid (two frames) holding the same
 *     linear fields plus a known offset, its stresses tension positive.
 * Bilinear interpolation is exact for linear fields, so the scores are the
 * offset's: rel_l2 = |delta| sqrt(n) / ||DEM||, noise = |delta| / se; the
 * empty row is outside the common support and the mask's first row outside
 * the interior; a map against itself scores 0; the same fields written as
 * an `ekmcompare cg --axes x,z` output (stresses negative in compression,
 * P as a field) score the same. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include <jansson.h>

#include "h5.h"
#include "score2d.h"
#include "test_util.h"

enum { DNX = 12, DNZ = 6, MNX = 7, MNZ = 4, NT = 2 };
static const char *const FIELDS[4] = {"phi", "sxx", "szz", "sxz"};
/* f = a + b x + c z [field units; x, z in m] */
static const double COEF[4][3] = {
    {0.5, 1.0, 2.0}, {100.0, 1000.0, 500.0}, {200.0, -800.0, 3000.0}, {10.0, 400.0, -50.0}};
static const double SE[4] = {0.01, 2.0, 4.0, 1.0};
static const double DELTA[4] = {0.002, 3.0, -2.0, 0.5}; /* the model's offset (DEM sign) */

static double linear(int k, double x, double z)
{
    return COEF[k][0] + COEF[k][1] * x + COEF[k][2] * z;
}

static void put(ekm_h5_file *w, const char *name, int rank, const size_t *dims, const double *v,
                const char *u)
{
    ekm_error err;
    if (ekm_h5_write_double(w, name, rank, dims, v, u, NULL, &err))
        fail_msg("%s", err.message);
}

static double dem_x(int i)
{
    return 0.002 + 0.004 * i;
}
static double dem_z(int j)
{
    return 0.002 + 0.004 * j;
}

static void write_map(const char *path)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    double x[DNX], z[DNZ], f[DNZ * DNX], mask[DNZ * DNX];
    for (int i = 0; i < DNX; i++)
        x[i] = dem_x(i);
    for (int j = 0; j < DNZ; j++)
        z[j] = dem_z(j);
    const size_t nx = DNX, nz = DNZ, dims[2] = {DNZ, DNX};
    put(w, "x", 1, &nx, x, "m");
    put(w, "z", 1, &nz, z, "m");
    for (int k = 0; k < 4; k++) {
        char se[16];
        for (int j = 0; j < DNZ; j++)
            for (int i = 0; i < DNX; i++)
                f[j * DNX + i] = j == DNZ - 1 ? 0.0 : linear(k, x[i], z[j]); /* the top row empty */
        put(w, FIELDS[k], 2, dims, f, k ? "Pa" : "1");
        for (int c = 0; c < DNZ * DNX; c++)
            f[c] = SE[k];
        snprintf(se, sizeof se, "%s_se", FIELDS[k]);
        put(w, se, 2, dims, f, k ? "Pa" : "1");
    }
    for (int j = 0; j < DNZ; j++)
        for (int i = 0; i < DNX; i++)
            mask[j * DNX + i] = j > 0; /* the plate's row left out */
    put(w, "mask", 2, dims, mask, "1");
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
}

/* The map's fields as a cg 2D output: two windows (the first wrong by 7),
 * stresses negative in compression, P = (sxx + szz)/2 of the map's linear
 * fields with SE 3 (a field the map lacks). */
static void write_cg(const char *path)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "kernel", "gauss", &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double(w, NULL, "snapshots_used", 2.0, &err), EKM_OK);
    double x[DNX], z[DNZ], t[NT] = {0.5, 1.0}, f[NT * DNZ * DNX], se[NT * DNZ * DNX];
    for (int i = 0; i < DNX; i++)
        x[i] = dem_x(i);
    for (int j = 0; j < DNZ; j++)
        z[j] = dem_z(j);
    const size_t nx = DNX, nz = DNZ, nt = NT, dims[3] = {NT, DNZ, DNX};
    put(w, "x", 1, &nx, x, "m");
    put(w, "z", 1, &nz, z, "m");
    put(w, "t", 1, &nt, t, "s");
    const char *names[5] = {"phi", "sxx", "szz", "sxz", "P"};
    for (int k = 0; k < 5; k++) {
        char sen[16];
        for (int n = 0; n < NT; n++)
            for (int j = 0; j < DNZ; j++)
                for (int i = 0; i < DNX; i++) {
                    const double v =
                        k < 4 ? linear(k, x[i], z[j]) : 0.5 * (linear(1, x[i], z[j]) + linear(2, x[i], z[j]));
                    const size_t c = ((size_t)n * DNZ + (size_t)j) * DNX + (size_t)i;
                    f[c] = j == DNZ - 1 ? 0.0 : (k == 0 || k == 4 ? 1.0 : -1.0) * v + (n ? 0.0 : 7.0);
                    se[c] = k < 4 ? SE[k] : 3.0;
                }
        put(w, names[k], 3, dims, f, k ? "Pa" : "1");
        snprintf(sen, sizeof sen, "%s_se", names[k]);
        put(w, sen, 3, dims, se, k ? "Pa" : "1");
    }
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
}

/* frame 0: the fields + 5 (a wrong frame); frame 1 (t = 1 s): + DELTA;
 * P = (sxx + szz)/2 + 1.5 at t = 1 s */
static void write_run(const char *path)
{
    ekm_h5_file *w;
    ekm_error err;
    assert_int_equal(ekm_h5_create(&w, path, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_string(w, NULL, "variant", "full", &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double(w, NULL, "stats.steps", 100.0, &err), EKM_OK);
    double x[MNX], z[MNZ], t[NT] = {0.5, 1.0}, f[NT * MNZ * MNX];
    for (int i = 0; i < MNX; i++)
        x[i] = -0.001 + 0.0085 * i;
    for (int j = 0; j < MNZ; j++)
        z[j] = 0.008 * j;
    const size_t nx = MNX, nz = MNZ, nt = NT, dims[3] = {NT, MNZ, MNX};
    put(w, "x", 1, &nx, x, "m");
    put(w, "z", 1, &nz, z, "m");
    put(w, "t", 1, &nt, t, "s");
    for (int k = 0; k < 4; k++) {
        const double sign = k ? -1.0 : 1.0; /* ekm: tension positive */
        for (int n = 0; n < NT; n++)
            for (int j = 0; j < MNZ; j++)
                for (int i = 0; i < MNX; i++)
                    f[(n * MNZ + j) * MNX + i] = sign * (linear(k, x[i], z[j]) + (n ? DELTA[k] : 5.0));
        put(w, FIELDS[k], 3, dims, f, k ? "Pa" : "1");
    }
    for (int n = 0; n < NT; n++)
        for (int j = 0; j < MNZ; j++)
            for (int i = 0; i < MNX; i++)
                f[(n * MNZ + j) * MNX + i] =
                    0.5 * (linear(1, x[i], z[j]) + linear(2, x[i], z[j])) + (n ? 1.5 : 5.0);
    put(w, "P", 3, dims, f, "Pa");
    assert_int_equal(ekm_h5_commit(w, &err), EKM_OK);
}

static void paths(char *map, char *run, size_t size)
{
    tmp_path(map, size, "score2d_map.h5");
    tmp_path(run, size, "score2d_run.h5");
    write_map(map);
    write_run(run);
}

static void test_known_offsets(void **state)
{
    (void)state;
    char map[512], run[512];
    paths(map, run, sizeof map);
    cg_score2d_opts o = cg_score2d_opts_default();
    o.dem = map;
    o.group = "/";
    o.model = run;
    cg_score2d_row rows[CG_SCORE2D_MAX_ROWS];
    size_t n = 0;
    ekm_error err = {0};
    if (cg_score2d(&o, rows, &n, &err))
        fail_msg("%s", err.message);
    assert_int_equal(n, 8);
    for (size_t r = 0; r < n; r++) {
        const int k = (int)(r / 2), interior = (int)(r % 2);
        assert_string_equal(rows[r].field, FIELDS[k]);
        assert_string_equal(rows[r].region, interior ? "interior" : "support");
        /* support: rows 0..4 (the top row is empty); interior: rows 1..4 */
        const size_t want_points = (size_t)(interior ? 4 : 5) * DNX;
        assert_int_equal(rows[r].m.points, want_points);
        double sum2 = 0.0;
        for (int j = interior; j < DNZ - 1; j++)
            for (int i = 0; i < DNX; i++)
                sum2 += pow(linear(k, dem_x(i), dem_z(j)), 2);
        const double rel = fabs(DELTA[k]) * sqrt((double)want_points / sum2);
        assert_close(rows[r].m.rel_l2, rel, 1e-9 * rel);
        assert_close(rows[r].m.noise, fabs(DELTA[k]) / SE[k], 1e-9 * fabs(DELTA[k]) / SE[k]);
    }
    /* the first frame: offset 5 everywhere */
    o.time = 0.5;
    assert_int_equal(cg_score2d(&o, rows, &n, &err), EKM_OK);
    assert_close(rows[0].m.noise, 5.0 / SE[0], 1e-9 * 5.0 / SE[0]);
    /* no frame at 0.7 s */
    o.time = 0.7;
    assert_int_equal(cg_score2d(&o, rows, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "no output at t = 0.7 s"));
}

/* The DEM as a cg 2D output: its last window, stresses negated, P scored
 * too (offset 1.5, SE 3), no interior region (a cg file has no mask). */
static void test_cg_dem(void **state)
{
    (void)state;
    char map[512], run[512], cg[512], out[512];
    paths(map, run, sizeof map);
    write_cg(tmp_path(cg, sizeof cg, "score2d_cg.h5"));
    cg_score2d_opts o = cg_score2d_opts_default();
    o.dem = cg;
    o.model = run;
    o.json = tmp_path(out, sizeof out, "score2d_cg.json");
    o.dem_sha256 = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
    o.ekm_sha256 = "fedcba9876543210fedcba9876543210fedcba9876543210fedcba9876543210";
    cg_score2d_row rows[CG_SCORE2D_MAX_ROWS];
    size_t n = 0;
    ekm_error err = {0};
    if (cg_score2d(&o, rows, &n, &err))
        fail_msg("%s", err.message);
    assert_int_equal(n, 5); /* phi, P, sxx, szz, sxz over the support */
    const char *order[5] = {"phi", "P", "sxx", "szz", "sxz"};
    for (size_t r = 0; r < n; r++) {
        assert_string_equal(rows[r].field, order[r]);
        assert_string_equal(rows[r].region, "support");
        assert_int_equal(rows[r].m.points, 5 * DNX);
        assert_int_equal(rows[r].left_out, 0);
        const double delta = r == 1 ? 1.5 : DELTA[r == 0 ? 0 : r - 1],
                     se = r == 1 ? 3.0 : SE[r == 0 ? 0 : r - 1];
        assert_close(rows[r].m.noise, fabs(delta) / se, 1e-9 * fabs(delta) / se);
    }
    /* SCORE.json: the support's metric at the field's level, the inputs recorded */
    json_error_t jerr;
    json_t *root = json_load_file(out, 0, &jerr);
    assert_non_null(root);
    json_t *szz = json_object_get(json_object_get(root, "fields"), "szz");
    assert_non_null(szz);
    assert_int_equal(json_integer_value(json_object_get(szz, "points")), 5 * DNX);
    assert_int_equal(json_integer_value(json_object_get(szz, "points_left_out")), 0);
    assert_close(json_real_value(json_object_get(szz, "noise_normalised")), 0.5, 1e-8);
    assert_string_equal(
        json_string_value(json_object_get(json_object_get(json_object_get(root, "inputs"), "dem"), "sha256")),
        o.dem_sha256);
    json_decref(root);
    /* engine against engine: the cg output against itself, the first
     * window against the last (offset 7 in every field but the empty row;
     * SEs in quadrature) */
    o.model = cg;
    o.json = NULL;
    o.dem_sha256 = o.ekm_sha256 = NULL;
    o.time = 0.5;
    if (cg_score2d(&o, rows, &n, &err))
        fail_msg("%s", err.message);
    assert_int_equal(n, 5);
    for (size_t r = 0; r < n; r++) {
        const double se = r == 1 ? 3.0 : SE[r == 0 ? 0 : r - 1];
        assert_close(rows[r].m.noise, 7.0 / (se * sqrt(2.0)), 1e-9 * 7.0 / se);
    }
    /* --noise none (one pile at rest): the same relative L2, no
     * noise-normalised error, no point counted with an SE, and the JSON
     * says so (null, se "none") */
    double rel[CG_SCORE2D_MAX_ROWS];
    for (size_t r = 0; r < n; r++)
        rel[r] = rows[r].m.rel_l2;
    o.no_noise = 1;
    o.json = out;
    if (cg_score2d(&o, rows, &n, &err))
        fail_msg("%s", err.message);
    assert_int_equal(n, 5);
    for (size_t r = 0; r < n; r++) {
        assert_true(rows[r].m.rel_l2 == rel[r]);
        assert_true(isnan(rows[r].m.noise));
        assert_int_equal(rows[r].m.points_se, 0);
    }
    root = json_load_file(out, 0, &jerr);
    assert_non_null(root);
    szz = json_object_get(json_object_get(root, "fields"), "szz");
    assert_true(json_is_null(json_object_get(szz, "noise_normalised")));
    assert_string_equal(json_string_value(json_object_get(szz, "se")), "none");
    assert_int_equal(json_integer_value(json_object_get(szz, "points_with_se")), 0);
    json_decref(root);
}

static void test_map_against_itself(void **state)
{
    (void)state;
    char map[512], run[512];
    paths(map, run, sizeof map);
    cg_score2d_opts o = cg_score2d_opts_default();
    o.dem = map;
    o.group = "/";
    o.model = map;
    o.model_group = "";
    o.fields = "szz,phi";
    cg_score2d_row rows[CG_SCORE2D_MAX_ROWS];
    size_t n = 0;
    ekm_error err = {0};
    if (cg_score2d(&o, rows, &n, &err))
        fail_msg("%s", err.message);
    assert_int_equal(n, 4);
    assert_string_equal(rows[0].field, "szz");
    for (size_t r = 0; r < n; r++) {
        assert_true(rows[r].m.rel_l2 == 0.0);
        assert_true(rows[r].m.noise == 0.0);
    }
}

static void test_refused(void **state)
{
    (void)state;
    char map[512], run[512], out[512];
    paths(map, run, sizeof map);
    cg_score2d_opts o = cg_score2d_opts_default();
    o.dem = map;
    o.group = "/";
    o.model = run;
    size_t n = 0;
    ekm_error err = {0};
    o.fields = "phi,T";
    assert_int_equal(cg_score2d(&o, NULL, &n, &err), EKM_EUSAGE);
    assert_non_null(strstr(err.message, "unknown field 'T'"));
    o.fields = "phi,P"; /* the map has no P */
    assert_int_equal(cg_score2d(&o, NULL, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "expected a dataset P"));
    o.fields = NULL;
    o.model = map; /* a map given as an ekm run */
    assert_int_equal(cg_score2d(&o, NULL, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "--model"));
    o.model = run;
    o.group = "/lammps/plain/hopper";
    assert_int_equal(cg_score2d(&o, NULL, &n, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "no group /lammps/plain/hopper"));
    o.group = "/";
    o.json = run; /* would overwrite an input */
    assert_int_equal(cg_score2d(&o, NULL, &n, &err), EKM_EIO);
    o.json = tmp_path(out, sizeof out, "score2d.json");
    remove(out);
    assert_int_equal(cg_score2d(&o, NULL, &n, &err), EKM_OK);
    FILE *fp = fopen(out, "r");
    assert_non_null(fp);
    fclose(fp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_offsets),
        cmocka_unit_test(test_cg_dem),
        cmocka_unit_test(test_map_against_itself),
        cmocka_unit_test(test_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
