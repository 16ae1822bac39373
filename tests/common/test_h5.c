/* common/h5: every attribute and dataset kind written and read back
 * exactly, with units/description; the on-disk layout the readers of
 * today's files depend on (fixed-length NUL-terminated strings, int32,
 * chunked unlimited series); atomic creation; one-line errors naming the
 * file and the dataset or attribute. */
#include <hdf5.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "h5.h"
#include "testutil.h"

static char dir[1024];

static int setup(void **state)
{
    (void)state;
    return tu_fresh_dir("h5", dir, sizeof dir);
}

static void write_example(const char *path)
{
    ekm_error err = {0};
    ekm_h5_file *f;
    assert_int_equal(ekm_h5_create(&f, path, &err), EKM_OK);
    assert_int_equal(tu_count_temporaries(dir), 1);
    assert_false(tu_exists(path));
    const double z[3] = {0.5, 1.5, 2.5};
    const size_t d1[1] = {3}, d2[2] = {2, 3}, d3[3] = {2, 2, 2};
    const double m2[6] = {1, 2, 3, 4, 5, 6.25};
    double m3[8];
    for (int i = 0; i < 8; i++)
        m3[i] = 0.1 * i;
    const int k1[3] = {-1, 0, 7}, k2[6] = {1, 2, 3, 4, 5, 6};
    assert_int_equal(ekm_h5_write_double(f, "z", 1, d1, z, "m", "cell centres", &err), EKM_OK);
    assert_int_equal(ekm_h5_write_double(f, "m2", 2, d2, m2, "Pa", NULL, &err), EKM_OK);
    assert_int_equal(ekm_h5_write_double(f, "m3", 3, d3, m3, NULL, NULL, &err), EKM_OK);
    assert_int_equal(ekm_h5_write_int(f, "k1", 1, d1, k1, "1", "ints", &err), EKM_OK);
    assert_int_equal(ekm_h5_write_int(f, "k2", 2, d2, k2, "1", NULL, &err), EKM_OK);
    const size_t empty[1] = {0};
    assert_int_equal(ekm_h5_write_double(f, "empty", 1, empty, NULL, "s", NULL, &err), EKM_OK);
    /* series: t[nt] in chunks of 64, phi[nt][3], regime[nt][3] int */
    const size_t row[1] = {3};
    assert_int_equal(ekm_h5_create_series(f, "t", EKM_H5_DOUBLE, 1, NULL, 64, "s", NULL, &err), EKM_OK);
    assert_int_equal(ekm_h5_create_series(f, "phi", EKM_H5_DOUBLE, 2, row, 1, "1", "solid fraction", &err),
                     EKM_OK);
    assert_int_equal(ekm_h5_create_series(f, "regime", EKM_H5_INT, 2, row, 1, "1", NULL, &err), EKM_OK);
    for (int i = 0; i < 4; i++) {
        const double t = 0.25 * i, phi[3] = {0.1 * 1 * i, 0.1 * 2 * i, 0.1 * 3 * i};
        const int reg[3] = {i, i + 1, i + 2};
        assert_int_equal(ekm_h5_append(f, "t", &t, &err), EKM_OK);
        assert_int_equal(ekm_h5_append(f, "phi", phi, &err), EKM_OK);
        assert_int_equal(ekm_h5_append(f, "regime", reg, &err), EKM_OK);
    }
    /* attributes on the root and on a dataset */
    const double dv[3] = {1.5, -2.0, 1e-300};
    const int iv[2] = {4, -5};
    assert_int_equal(ekm_h5_attr_set_string(f, NULL, "scenario", "chute", &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_string(f, "/", "empty_string", "", &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double(f, NULL, "material.eps0", 0.1 + 0.2, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_int(f, NULL, "cells", 200, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double_array(f, NULL, "dv", dv, 3, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_int_array(f, "z", "iv", iv, 2, &err), EKM_OK);
    assert_int_equal(ekm_h5_attr_set_double(f, "phi", "scale", 2.5, &err), EKM_OK);
    assert_int_equal(ekm_h5_commit(f, &err), EKM_OK);
    assert_int_equal(tu_count_temporaries(dir), 0);
}

static void test_round_trip(void **state)
{
    (void)state;
    char path[1100];
    snprintf(path, sizeof path, "%s/round.h5", dir);
    write_example(path);
    ekm_error err = {0};
    ekm_h5_file *f;
    assert_int_equal(ekm_h5_open(&f, path, &err), EKM_OK);
    assert_string_equal(ekm_h5_path(f), path);
    int rank;
    size_t dims[3];
    double *d;
    int *k;
    assert_int_equal(ekm_h5_read_double(f, "z", &rank, dims, &d, &err), EKM_OK);
    assert_int_equal(rank, 1);
    assert_int_equal(dims[0], 3);
    assert_true(d[0] == 0.5 && d[1] == 1.5 && d[2] == 2.5);
    free(d);
    assert_int_equal(ekm_h5_read_double(f, "m2", &rank, dims, &d, &err), EKM_OK);
    assert_int_equal(rank, 2);
    assert_true(dims[0] == 2 && dims[1] == 3 && d[5] == 6.25 && d[3] == 4);
    free(d);
    assert_int_equal(ekm_h5_read_double(f, "m3", &rank, dims, &d, &err), EKM_OK);
    assert_int_equal(rank, 3);
    assert_true(dims[0] == 2 && dims[1] == 2 && dims[2] == 2);
    for (int i = 0; i < 8; i++)
        assert_true(d[i] == 0.1 * i);
    free(d);
    assert_int_equal(ekm_h5_read_int(f, "k1", &rank, dims, &k, &err), EKM_OK);
    assert_true(rank == 1 && dims[0] == 3 && k[0] == -1 && k[1] == 0 && k[2] == 7);
    free(k);
    assert_int_equal(ekm_h5_read_int(f, "k2", &rank, dims, &k, &err), EKM_OK);
    assert_true(rank == 2 && dims[0] == 2 && dims[1] == 3 && k[5] == 6);
    free(k);
    assert_int_equal(ekm_h5_read_double(f, "empty", &rank, dims, &d, &err), EKM_OK);
    assert_true(rank == 1 && dims[0] == 0 && d != NULL);
    free(d);
    assert_int_equal(ekm_h5_read_double(f, "t", &rank, dims, &d, &err), EKM_OK);
    assert_true(rank == 1 && dims[0] == 4 && d[3] == 0.75);
    free(d);
    assert_int_equal(ekm_h5_read_double(f, "phi", &rank, dims, &d, &err), EKM_OK);
    assert_true(rank == 2 && dims[0] == 4 && dims[1] == 3);
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 3; j++)
            assert_true(d[3 * i + j] == 0.1 * (j + 1) * i);
    free(d);
    assert_int_equal(ekm_h5_read_int(f, "regime", &rank, dims, &k, &err), EKM_OK);
    assert_true(rank == 2 && dims[0] == 4 && k[3 * 3 + 2] == 5);
    free(k);
    /* units and descriptions */
    char buf[128];
    const char *with_units[][2] = {{"z", "m"},     {"m2", "Pa"}, {"k1", "1"},  {"k2", "1"},
                                   {"empty", "s"}, {"t", "s"},   {"phi", "1"}, {"regime", "1"}};
    for (size_t i = 0; i < sizeof with_units / sizeof with_units[0]; i++) {
        assert_int_equal(ekm_h5_attr_get_string(f, with_units[i][0], "units", buf, sizeof buf, &err), EKM_OK);
        assert_string_equal(buf, with_units[i][1]);
    }
    assert_false(ekm_h5_attr_exists(f, "m3", "units"));
    assert_int_equal(ekm_h5_attr_get_string(f, "z", "description", buf, sizeof buf, &err), EKM_OK);
    assert_string_equal(buf, "cell centres");
    assert_int_equal(ekm_h5_attr_get_string(f, "phi", "description", buf, sizeof buf, &err), EKM_OK);
    assert_string_equal(buf, "solid fraction");
    assert_false(ekm_h5_attr_exists(f, "m2", "description"));
    /* attributes */
    assert_int_equal(ekm_h5_attr_get_string(f, NULL, "scenario", buf, sizeof buf, &err), EKM_OK);
    assert_string_equal(buf, "chute");
    assert_int_equal(ekm_h5_attr_get_string(f, NULL, "empty_string", buf, sizeof buf, &err), EKM_OK);
    assert_string_equal(buf, "");
    double x;
    assert_int_equal(ekm_h5_attr_get_double(f, NULL, "material.eps0", &x, &err), EKM_OK);
    assert_true(x == 0.1 + 0.2);
    assert_int_equal(ekm_h5_attr_get_string(f, NULL, "material.eps0", buf, sizeof buf, &err), EKM_OK);
    assert_string_equal(buf, "0.30000000000000004");
    int n;
    assert_int_equal(ekm_h5_attr_get_int(f, NULL, "cells", &n, &err), EKM_OK);
    assert_int_equal(n, 200);
    assert_int_equal(ekm_h5_attr_get_double(f, NULL, "cells", &x, &err), EKM_OK);
    assert_true(x == 200.0);
    double dv[4];
    size_t nv;
    assert_int_equal(ekm_h5_attr_get_double_array(f, NULL, "dv", dv, 4, &nv, &err), EKM_OK);
    assert_true(nv == 3 && dv[0] == 1.5 && dv[1] == -2.0 && dv[2] == 1e-300);
    assert_int_equal(ekm_h5_attr_get_double_array(f, NULL, "dv", dv, 2, &nv, &err), EKM_EINPUT);
    assert_int_equal(ekm_h5_attr_get_double_array(f, "z", "iv", dv, 4, &nv, &err), EKM_OK);
    assert_true(nv == 2 && dv[0] == 4 && dv[1] == -5);
    assert_int_equal(ekm_h5_attr_get_double(f, "phi", "scale", &x, &err), EKM_OK);
    assert_true(x == 2.5);
    /* kind mismatches are refused with the attribute named */
    assert_int_equal(ekm_h5_attr_get_int(f, NULL, "material.eps0", &n, &err), EKM_EINPUT);
    assert_int_equal(ekm_h5_attr_get_double(f, NULL, "scenario", &x, &err), EKM_EINPUT);
    char expected[2048];
    snprintf(expected, sizeof expected, "%s: attribute scenario: expected a number", path);
    assert_string_equal(err.message, expected);
    /* too small a buffer */
    assert_int_equal(ekm_h5_attr_get_string(f, NULL, "scenario", buf, 3, &err), EKM_EINPUT);
    assert_true(ekm_h5_exists(f, "phi"));
    assert_false(ekm_h5_exists(f, "nope"));
    ekm_h5_close(f);
}

/* The layout today's readers (tests, figures, h5py) rely on. */
static void test_layout(void **state)
{
    (void)state;
    char path[1100];
    snprintf(path, sizeof path, "%s/layout.h5", dir);
    write_example(path);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    /* a fixed-length, NUL-terminated string of strlen + 1 bytes */
    hid_t a = H5Aopen(file, "scenario", H5P_DEFAULT), type = H5Aget_type(a), space = H5Aget_space(a);
    assert_int_equal(H5Tget_class(type), H5T_STRING);
    assert_false(H5Tis_variable_str(type));
    assert_int_equal(H5Tget_size(type), strlen("chute") + 1);
    assert_int_equal(H5Tget_strpad(type), H5T_STR_NULLTERM);
    assert_int_equal(H5Sget_simple_extent_type(space), H5S_SCALAR);
    H5Sclose(space);
    H5Tclose(type);
    H5Aclose(a);
    /* a scalar float64 */
    a = H5Aopen(file, "material.eps0", H5P_DEFAULT);
    type = H5Aget_type(a);
    assert_true(H5Tequal(type, H5T_IEEE_F64LE) > 0);
    H5Tclose(type);
    H5Aclose(a);
    /* int32 series, chunk 1 x nz, unlimited first dimension */
    hid_t d = H5Dopen2(file, "regime", H5P_DEFAULT);
    type = H5Dget_type(d);
    assert_true(H5Tequal(type, H5T_STD_I32LE) > 0);
    H5Tclose(type);
    space = H5Dget_space(d);
    hsize_t dims[2], maxdims[2], chunk[2];
    H5Sget_simple_extent_dims(space, dims, maxdims);
    assert_true(dims[0] == 4 && dims[1] == 3 && maxdims[0] == H5S_UNLIMITED && maxdims[1] == 3);
    hid_t plist = H5Dget_create_plist(d);
    assert_int_equal(H5Pget_layout(plist), H5D_CHUNKED);
    assert_int_equal(H5Pget_chunk(plist, 2, chunk), 2);
    assert_true(chunk[0] == 1 && chunk[1] == 3);
    H5Pclose(plist);
    H5Sclose(space);
    H5Dclose(d);
    d = H5Dopen2(file, "t", H5P_DEFAULT);
    plist = H5Dget_create_plist(d);
    assert_int_equal(H5Pget_chunk(plist, 1, chunk), 1);
    assert_true(chunk[0] == 64);
    H5Pclose(plist);
    H5Dclose(d);
    /* fixed datasets are contiguous */
    d = H5Dopen2(file, "z", H5P_DEFAULT);
    plist = H5Dget_create_plist(d);
    assert_int_equal(H5Pget_layout(plist), H5D_CONTIGUOUS);
    H5Pclose(plist);
    H5Dclose(d);
    H5Fclose(file);
}

static void test_abort_and_create_errors(void **state)
{
    (void)state;
    char path[1100];
    snprintf(path, sizeof path, "%s/aborted.h5", dir);
    ekm_error err = {0};
    ekm_h5_file *f;
    assert_int_equal(ekm_h5_create(&f, path, &err), EKM_OK);
    const size_t d1[1] = {1};
    const double v = 1;
    assert_int_equal(ekm_h5_write_double(f, "v", 1, d1, &v, "1", NULL, &err), EKM_OK);
    /* a second dataset of the same name: refused, named */
    assert_int_equal(ekm_h5_write_double(f, "v", 1, d1, &v, "1", NULL, &err), EKM_EIO);
    char expected[2048];
    snprintf(expected, sizeof expected, "%s: cannot write the dataset v", path);
    assert_string_equal(err.message, expected);
    /* an attribute on a dataset that does not exist */
    assert_int_equal(ekm_h5_attr_set_double(f, "nope", "a", 1.0, &err), EKM_EIO);
    snprintf(expected, sizeof expected, "%s: dataset nope: cannot write the attribute a", path);
    assert_string_equal(err.message, expected);
    ekm_h5_abort(f);
    assert_false(tu_exists(path));
    assert_int_equal(tu_count_temporaries(dir), 0);
    ekm_h5_abort(NULL);
    ekm_h5_close(NULL);
    /* a directory that does not exist */
    snprintf(path, sizeof path, "%s/no/such/dir.h5", dir);
    assert_int_equal(ekm_h5_create(&f, path, &err), EKM_EIO);
    assert_null(f);
    snprintf(expected, sizeof expected, "%s: cannot create the output file: No such file or directory", path);
    assert_string_equal(err.message, expected);
}

static void test_read_errors(void **state)
{
    (void)state;
    char path[1100], text[1100], expected[2048];
    snprintf(path, sizeof path, "%s/read.h5", dir);
    write_example(path);
    ekm_error err = {0};
    ekm_h5_file *f;
    assert_int_equal(ekm_h5_open(&f, path, &err), EKM_OK);
    int rank;
    size_t dims[3];
    double *d = (double *)&rank;
    assert_int_equal(ekm_h5_read_double(f, "sxz", &rank, dims, &d, &err), EKM_EINPUT);
    assert_null(d);
    snprintf(expected, sizeof expected, "%s: expected a dataset sxz", path);
    assert_string_equal(err.message, expected);
    assert_null(strchr(err.message, '\n'));
    char buf[64];
    assert_int_equal(ekm_h5_attr_get_string(f, NULL, "created", buf, sizeof buf, &err), EKM_EINPUT);
    snprintf(expected, sizeof expected, "%s: expected an attribute created", path);
    assert_string_equal(err.message, expected);
    assert_int_equal(ekm_h5_attr_get_string(f, "phi", "nope", buf, sizeof buf, &err), EKM_EINPUT);
    snprintf(expected, sizeof expected, "%s: dataset phi: expected an attribute nope", path);
    assert_string_equal(err.message, expected);
    assert_int_equal(ekm_h5_attr_get_string(f, "sxz", "units", buf, sizeof buf, &err), EKM_EINPUT);
    snprintf(expected, sizeof expected, "%s: expected a dataset sxz", path);
    assert_string_equal(err.message, expected);
    ekm_h5_close(f);
    /* not an HDF5 file */
    snprintf(text, sizeof text, "%s/not.h5", dir);
    assert_int_equal(tu_write_file(text, "phi,vx\n1,2\n"), 0);
    assert_int_equal(ekm_h5_open(&f, text, &err), EKM_EINPUT);
    assert_null(f);
    snprintf(expected, sizeof expected, "%s: expected an HDF5 file", text);
    assert_string_equal(err.message, expected);
    /* no such file */
    snprintf(text, sizeof text, "%s/missing.h5", dir);
    assert_int_equal(ekm_h5_open(&f, text, &err), EKM_EIO);
    snprintf(expected, sizeof expected, "%s: cannot open: no such readable file", text);
    assert_string_equal(err.message, expected);
    /* a directory: an i/o error, not "expected an HDF5 file" */
    assert_int_equal(ekm_h5_open(&f, dir, &err), EKM_EIO);
    assert_null(f);
    snprintf(expected, sizeof expected, "%s: cannot open: not a regular file", dir);
    assert_string_equal(err.message, expected);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_layout),
        cmocka_unit_test(test_abort_and_create_errors),
        cmocka_unit_test(test_read_errors),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
