/* The 2D run's output writer (continuum/twod/out2d.h): a 3-frame run on
 * 4 x 3 cells read back with the HDF5 API (shapes, values, units, root
 * attributes) and its XDMF sidecar naming the 2D grid; a value that is not
 * finite is EKM_ENUMERIC and, like an abort, leaves no file. */
#include <dirent.h>
#include <hdf5.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <cmocka.h>

#include "out2d.h"
#include "schema.h"

enum { NX = 4, NZ = 3, NT = 3 };

static const char *const NAMES[EKM2D_NFIELDS] = {"phi", "vx", "vz", "T", "P", "sxx", "szz", "sxz", "regime"};
static const char *const UNITS[EKM2D_NFIELDS] = {"1", "m/s", "m/s", "m^2/s^2", "Pa", "Pa", "Pa", "Pa", "1"};

typedef struct {
    char dir[512];
    ekm_scenario sc;
    double values[EKM2D_NFIELDS][NZ * NX];
} fixture;

/* The value of field k at cell (ix, iz) of frame it: distinct everywhere;
 * the regime a small integer. */
static double value(int k, int it, int iz, int ix)
{
    if (k == EKM2D_REGIME)
        return (double)((ix + iz + it) % 4);
    return 1000.0 * k + 100.0 * it + 10.0 * iz + ix + 0.25;
}

static void fill_frame(fixture *fx, int it, const double *fields[EKM2D_NFIELDS])
{
    for (int k = 0; k < EKM2D_NFIELDS; k++) {
        for (int iz = 0; iz < NZ; iz++)
            for (int ix = 0; ix < NX; ix++)
                fx->values[k][iz * NX + ix] = value(k, it, iz, ix);
        fields[k] = fx->values[k];
    }
}

static int setup(void **state)
{
    fixture *fx = calloc(1, sizeof *fx);
    if (!fx)
        return -1;
    snprintf(fx->dir, sizeof fx->dir, "%s/out2d_test", EKM_BINARY_DIR);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", fx->dir, fx->dir);
    if (system(cmd) != 0) {
        free(fx);
        return -1;
    }
    char ini[600];
    snprintf(ini, sizeof ini, "%s/scenarios/sandpile.ini", EKM_SOURCE_DIR);
    /* the scenario's plate (0.204 m) is wider than this box: the whole floor */
    const char *sets[] = {"domain.cells_x=4",   "domain.cells=3",     "domain.width=0.2",
                          "domain.length=0.06", "bottom.plate_x=0.1", "bottom.plate_width=0.2"};
    ekm_error err = {0};
    if (ekm_scenario_load(&fx->sc, ini, sets, sizeof sets / sizeof sets[0], &err) != EKM_OK) {
        fprintf(stderr, "%s\n", err.message);
        ekm_scenario_free(&fx->sc);
        free(fx);
        return -1;
    }
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    fixture *fx = *state;
    if (!fx) /* setup failed (and freed it) */
        return 0;
    ekm_scenario_free(&fx->sc);
    free(fx);
    return 0;
}

/* Files of dir whose name starts with prefix (the output, its sidecar and
 * their temporaries). */
static int files_named(const char *dir, const char *prefix)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    closedir(d);
    return n;
}

static void dims_of(hid_t f, const char *name, int want_rank, const hsize_t *want)
{
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    hid_t s = H5Dget_space(d);
    hsize_t dims[3] = {0};
    assert_int_equal(H5Sget_simple_extent_ndims(s), want_rank);
    H5Sget_simple_extent_dims(s, dims, NULL);
    for (int i = 0; i < want_rank; i++)
        assert_int_equal(dims[i], want[i]);
    H5Sclose(s);
    H5Dclose(d);
}

static void string_attr(hid_t obj, const char *name, char *buf, size_t size)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(a >= 0);
    hid_t t = H5Aget_type(a);
    assert_int_equal(H5Tget_class(t), H5T_STRING);
    size_t n = H5Tget_size(t);
    assert_true(n < size);
    assert_true(H5Aread(a, t, buf) >= 0);
    buf[n] = '\0';
    H5Tclose(t);
    H5Aclose(a);
}

static double double_attr(hid_t obj, const char *name)
{
    double v = NAN;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(a >= 0);
    assert_true(H5Aread(a, H5T_NATIVE_DOUBLE, &v) >= 0);
    H5Aclose(a);
    return v;
}

static void read_all(hid_t f, const char *name, hid_t type, void *buf)
{
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    assert_true(H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    H5Dclose(d);
}

static void write_run(fixture *fx, const char *path)
{
    ekm_error err = {0};
    ekm2d_writer *w = NULL;
    assert_int_equal(ekm2d_writer_open(&w, path, &fx->sc, 2, NT, &err), EKM_OK);
    for (int it = 0; it < NT; it++) {
        const double *fields[EKM2D_NFIELDS];
        fill_frame(fx, it, fields);
        assert_int_equal(ekm2d_writer_append(w, 0.5 * it, fx->sc.length / fx->sc.cells, fields, &err),
                         EKM_OK);
    }
    assert_int_equal(ekm2d_writer_set_attr(w, "stats.steps", 42.0, &err), EKM_OK);
    /* no file before commit */
    struct stat sb;
    assert_int_not_equal(stat(path, &sb), 0);
    assert_int_equal(ekm2d_writer_commit(w, &err), EKM_OK);
}

static void test_layout(void **state)
{
    fixture *fx = *state;
    char path[700];
    snprintf(path, sizeof path, "%s/run2d.h5", fx->dir);
    write_run(fx, path);

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    const hsize_t nx[1] = {NX}, nz[1] = {NZ}, nt[1] = {NT}, frames[3] = {NT, NZ, NX};
    dims_of(f, "x", 1, nx);
    dims_of(f, "z", 1, nz);
    dims_of(f, "t", 1, nt);
    char units[128];
    double x[NX], z[NZ], t[NT];
    read_all(f, "x", H5T_NATIVE_DOUBLE, x);
    read_all(f, "z", H5T_NATIVE_DOUBLE, z);
    read_all(f, "t", H5T_NATIVE_DOUBLE, t);
    for (int i = 0; i < NX; i++)
        assert_float_equal(x[i], (i + 0.5) * 0.05, 1e-15); /* width 0.2 m / 4 */
    for (int i = 0; i < NZ; i++)
        assert_float_equal(z[i], (i + 0.5) * 0.02, 1e-15); /* length 0.06 m / 3 */
    for (int i = 0; i < NT; i++)
        assert_float_equal(t[i], 0.5 * i, 0.0);
    const char *coords[] = {"x", "z", "t"}, *coord_units[] = {"m", "m", "s"};
    for (int i = 0; i < 3; i++) {
        hid_t d = H5Dopen2(f, coords[i], H5P_DEFAULT);
        string_attr(d, "units", units, sizeof units);
        assert_string_equal(units, coord_units[i]);
        H5Dclose(d);
    }

    for (int k = 0; k < EKM2D_NFIELDS; k++) {
        dims_of(f, NAMES[k], 3, frames);
        hid_t d = H5Dopen2(f, NAMES[k], H5P_DEFAULT);
        string_attr(d, "units", units, sizeof units);
        /* the schema's units; the regime's are "1" with its codes */
        assert_string_equal(units, ekm_field_units(NAMES[k]));
        assert_true(strncmp(units, UNITS[k], strlen(UNITS[k])) == 0);
        hid_t type = H5Dget_type(d);
        if (k == EKM2D_REGIME) {
            assert_int_equal(H5Tget_class(type), H5T_INTEGER);
            assert_int_equal(H5Tget_size(type), 4);
            int buf[NT * NZ * NX];
            assert_true(H5Dread(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
            for (int it = 0; it < NT; it++)
                for (int c = 0; c < NZ * NX; c++)
                    assert_int_equal(buf[it * NZ * NX + c], (int)value(k, it, c / NX, c % NX));
        } else {
            assert_int_equal(H5Tget_class(type), H5T_FLOAT);
            double buf[NT * NZ * NX];
            assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
            for (int it = 0; it < NT; it++)
                for (int c = 0; c < NZ * NX; c++) /* x fastest */
                    assert_float_equal(buf[it * NZ * NX + c], value(k, it, c / NX, c % NX), 0.0);
        }
        H5Tclose(type);
        H5Dclose(d);
    }

    /* the 1D file's root attributes, ranks and the caller's statistics */
    char s[1024];
    assert_float_equal(double_attr(f, "domain.cells_x"), 4.0, 0.0);
    assert_float_equal(double_attr(f, "domain.cells"), 3.0, 0.0);
    assert_float_equal(double_attr(f, "domain.width"), 0.2, 0.0);
    assert_float_equal(double_attr(f, "stats.steps"), 42.0, 0.0);
    assert_true(isfinite(double_attr(f, "gravity_x")));
    assert_true(isfinite(double_attr(f, "gravity_z")));
    int ranks = 0;
    hid_t a = H5Aopen(f, "ranks", H5P_DEFAULT);
    assert_true(a >= 0);
    assert_true(H5Aread(a, H5T_NATIVE_INT, &ranks) >= 0);
    H5Aclose(a);
    assert_int_equal(ranks, 2);
    string_attr(f, "scenario", s, sizeof s);
    assert_string_equal(s, "sandpile");
    string_attr(f, "scenario_file", s, sizeof s);
    assert_non_null(strstr(s, "scenarios/sandpile.ini"));
    string_attr(f, "variant", s, sizeof s);
    assert_true(strcmp(s, "full") == 0 || strcmp(s, "thesis") == 0);
    const char *present[] = {"code_version", "created"};
    for (int i = 0; i < 2; i++)
        assert_true(H5Aexists(f, present[i]) > 0);
    /* the sidecar's view of the last frame */
    const hsize_t view[2] = {NZ, NX};
    dims_of(f, "xdmf/phi/2", 2, view);
    H5Fclose(f);

    /* the sidecar: the 2D grid of 4 x 3 cells (nodes 3+1, 2, 4+1 in Z Y X) */
    char xdmf[700];
    snprintf(xdmf, sizeof xdmf, "%s/run2d.xdmf", fx->dir);
    FILE *fp = fopen(xdmf, "r");
    assert_non_null(fp);
    static char text[1 << 16];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    text[n] = '\0';
    fclose(fp);
    assert_non_null(strstr(text, "2D grid"));
    assert_non_null(
        strstr(text, "<Grid Name=\"sandpile\" GridType=\"Collection\" CollectionType=\"Temporal\">"));
    assert_non_null(strstr(text, "TopologyType=\"3DCoRectMesh\" Dimensions=\"4 2 5\""));
    assert_non_null(strstr(text, "<Time Value=\"1\"/>"));
    assert_non_null(strstr(text, "run2d.h5:/xdmf/sxx/2"));
    assert_non_null(strstr(
        text,
        "Dimensions=\"3 1 4\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">run2d.h5:/xdmf/regime/0"));
    assert_null(strstr(text, "frame3"));
    assert_int_equal(files_named(fx->dir, "run2d"), 2); /* the pair, no temporary */
}

static void test_not_finite(void **state)
{
    fixture *fx = *state;
    char path[700];
    snprintf(path, sizeof path, "%s/nan2d.h5", fx->dir);
    ekm_error err = {0};
    ekm2d_writer *w = NULL;
    assert_int_equal(ekm2d_writer_open(&w, path, &fx->sc, 1, NT, &err), EKM_OK);
    const double *fields[EKM2D_NFIELDS];
    fill_frame(fx, 0, fields);
    assert_int_equal(ekm2d_writer_append(w, 0.0, fx->sc.length / fx->sc.cells, fields, &err), EKM_OK);
    fill_frame(fx, 1, fields);
    fx->values[EKM2D_SXZ][1 * NX + 2] = NAN; /* ix 2, iz 1 */
    assert_int_equal(ekm2d_writer_append(w, 0.5, fx->sc.length / fx->sc.cells, fields, &err), EKM_ENUMERIC);
    assert_non_null(strstr(err.message, "field sxz is not finite"));
    assert_non_null(strstr(err.message, "ix 2, iz 1"));
    assert_non_null(strstr(err.message, "t = 0.5 s"));
    assert_null(strchr(err.message, '\n'));
    ekm2d_writer_abort(w);
    assert_int_equal(files_named(fx->dir, "nan2d"), 0);
}

static void test_abort(void **state)
{
    fixture *fx = *state;
    char path[700];
    snprintf(path, sizeof path, "%s/abort2d.h5", fx->dir);
    ekm_error err = {0};
    ekm2d_writer *w = NULL;
    assert_int_equal(ekm2d_writer_open(&w, path, &fx->sc, 1, NT, &err), EKM_OK);
    const double *fields[EKM2D_NFIELDS];
    fill_frame(fx, 0, fields);
    assert_int_equal(ekm2d_writer_append(w, 0.0, fx->sc.length / fx->sc.cells, fields, &err), EKM_OK);
    ekm2d_writer_abort(w);
    ekm2d_writer_abort(NULL); /* harmless */
    assert_int_equal(files_named(fx->dir, "abort2d"), 0);
}

/* More frames than announced is the caller's bug; a run too large for
 * memory is refused when opened. */
static void test_limits(void **state)
{
    fixture *fx = *state;
    char path[700];
    snprintf(path, sizeof path, "%s/limit2d.h5", fx->dir);
    ekm_error err = {0};
    ekm2d_writer *w = NULL;
    assert_int_equal(ekm2d_writer_open(&w, path, &fx->sc, 1, 1, &err), EKM_OK);
    const double *fields[EKM2D_NFIELDS];
    fill_frame(fx, 0, fields);
    assert_int_equal(ekm2d_writer_append(w, 0.0, fx->sc.length / fx->sc.cells, fields, &err), EKM_OK);
    assert_int_equal(ekm2d_writer_append(w, 0.5, fx->sc.length / fx->sc.cells, fields, &err), EKM_EINTERNAL);
    ekm2d_writer_abort(w);
    assert_int_equal(ekm2d_writer_open(&w, path, &fx->sc, 1, (size_t)1e9, &err), EKM_EINPUT);
    assert_null(w);
    assert_non_null(strstr(err.message, "[run] output_dt"));
    assert_int_equal(files_named(fx->dir, "limit2d"), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layout),
        cmocka_unit_test(test_not_finite),
        cmocka_unit_test(test_abort),
        cmocka_unit_test(test_limits),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
