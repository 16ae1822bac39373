/* The ekm program's output: `ekm run scenarios/chute.ini` writes an HDF5
 * file with the documented layout and attributes, and an XDMF sidecar whose
 * every HDF reference resolves to a dataset of the stated shape. */
#include <hdf5.h>
#include <libxml/parser.h>
#include <libxml/tree.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

static char out_dir[512];

static int setup(void **state)
{
    (void)state;
    snprintf(out_dir, sizeof out_dir, "%s/output_test", EKM_BINARY_DIR);
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "rm -rf '%s' && mkdir -p '%s' && '%s' run '%s/scenarios/chute.ini' -o '%s/chute.h5' "
             "--set run.t_end=0.2 --set run.output_dt=0.05 --quiet",
             out_dir, out_dir, EKM_BINARY, EKM_SOURCE_DIR, out_dir);
    return system(cmd) == 0 ? 0 : -1;
}

static void read_dims(hid_t file, const char *name, int *rank, hsize_t dims[2])
{
    hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
    assert_true(d >= 0);
    hid_t s = H5Dget_space(d);
    *rank = H5Sget_simple_extent_ndims(s);
    H5Sget_simple_extent_dims(s, dims, NULL);
    H5Sclose(s);
    H5Dclose(d);
}

static double read_double_attr(hid_t file, const char *name)
{
    double v = NAN;
    hid_t a = H5Aopen(file, name, H5P_DEFAULT);
    assert_true(a >= 0);
    assert_true(H5Aread(a, H5T_NATIVE_DOUBLE, &v) >= 0);
    H5Aclose(a);
    return v;
}

static void read_string_attr(hid_t obj, const char *name, char *buf, size_t size)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(a >= 0);
    hid_t t = H5Aget_type(a);
    assert_true(H5Tget_class(t) == H5T_STRING);
    size_t n = H5Tget_size(t);
    assert_true(n < size);
    assert_true(H5Aread(a, t, buf) >= 0);
    buf[n] = '\0';
    H5Tclose(t);
    H5Aclose(a);
}

static void test_hdf5_layout(void **state)
{
    (void)state;
    char path[600];
    snprintf(path, sizeof path, "%s/chute.h5", out_dir);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    int rank;
    hsize_t zd[2], td[2], fd[2];
    read_dims(f, "z", &rank, zd); /* the cell centres of every frame */
    assert_int_equal(rank, 2);
    assert_int_equal(zd[1], 60);
    read_dims(f, "t", &rank, td);
    assert_int_equal(rank, 1);
    assert_int_equal(td[0], 5); /* t = 0, 0.05, ..., 0.2 */
    assert_int_equal(zd[0], td[0]);
    const char *fields[] = {"phi", "vx", "vz", "T", "P", "sxz", "szz", "regime"};
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        read_dims(f, fields[i], &rank, fd);
        assert_int_equal(rank, 2);
        assert_int_equal(fd[0], td[0]);
        assert_int_equal(fd[1], zd[1]);
        hid_t d = H5Dopen2(f, fields[i], H5P_DEFAULT);
        char units[128];
        read_string_attr(d, "units", units, sizeof units);
        assert_true(strlen(units) > 0);
        H5Dclose(d);
    }
    assert_true(fabs(read_double_attr(f, "material.eps0") - 212.2) < 1e-12);
    assert_true(fabs(read_double_attr(f, "gravity.angle") - 24) < 1e-12);
    assert_true(fabs(read_double_attr(f, "gravity_x") - 9.81 * sin(24 * 3.14159265358979323846 / 180)) <
                1e-12);
    assert_true(fabs(read_double_attr(f, "gravity_z") + 9.81 * cos(24 * 3.14159265358979323846 / 180)) <
                1e-12);
    assert_true(fabs(read_double_attr(f, "run.t_end") - 0.2) < 1e-15); /* the --set value */
    /* run statistics (stats.*): counts consistent, the mass balance closes */
    const double steps = read_double_attr(f, "stats.steps");
    assert_true(steps > 0 && steps == floor(steps));
    assert_true(read_double_attr(f, "stats.cell_updates") == 60.0 * steps);
    assert_true(read_double_attr(f, "stats.wall_time_s") > 0.0);
    assert_true(read_double_attr(f, "stats.rejected_steps") >= 0.0);
    const double m0 = read_double_attr(f, "stats.mass_initial"), m1 = read_double_attr(f, "stats.mass_final");
    assert_true(m0 > 0.0 && fabs(m1 - m0 - read_double_attr(f, "stats.mass_in")) < 1e-12 * m0);
    char buf[256];
    read_string_attr(f, "variant", buf, sizeof buf);
    assert_string_equal(buf, "full");
    read_string_attr(f, "top.type", buf, sizeof buf);
    assert_string_equal(buf, "free");
    read_string_attr(f, "code_version", buf, sizeof buf);
    assert_true(strlen(buf) > 0);
    /* the layer flows down the slope: vx > 0 at the end in the layer */
    double phi[5][60], vx[5][60];
    hid_t d = H5Dopen2(f, "phi", H5P_DEFAULT);
    assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, phi) >= 0);
    H5Dclose(d);
    d = H5Dopen2(f, "vx", H5P_DEFAULT);
    assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, vx) >= 0);
    H5Dclose(d);
    assert_true(phi[4][10] > 0.5 && vx[4][20] > 0.0);
    H5Fclose(f);
}

/* The values of dataset `view` (a row view /xdmf/FIELD/I) equal row I of
 * /FIELD, read as doubles. */
static void check_view(hid_t file, const char *view)
{
    char field[64];
    unsigned row;
    assert_int_equal(sscanf(view, "/xdmf/%63[^/]/%u", field, &row), 2);
    int rank;
    hsize_t vd[2], fd[2];
    read_dims(file, view, &rank, vd);
    assert_int_equal(rank, 1);
    read_dims(file, field, &rank, fd);
    assert_int_equal(rank, 2);
    assert_true(row < fd[0] && vd[0] == fd[1]);
    double *all = malloc(fd[0] * fd[1] * sizeof *all), *got = malloc(vd[0] * sizeof *got);
    assert_non_null(all);
    assert_non_null(got);
    hid_t d = H5Dopen2(file, field, H5P_DEFAULT);
    assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, all) >= 0);
    H5Dclose(d);
    d = H5Dopen2(file, view, H5P_DEFAULT);
    assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, got) >= 0);
    H5Dclose(d);
    assert_memory_equal(got, all + row * fd[1], vd[0] * sizeof *got);
    free(all);
    free(got);
}

/* Every DataItem with Format="HDF" names FILE:/DATASET; the file must be the
 * sidecar's HDF5 file and the dataset must exist with the stated dims: the
 * row view of its field and frame, equal to that row.  The mesh is the
 * column of cells along Z (3DCoRectMesh "nz+1 2 2"), fields cell-centred. */
static void test_xdmf_resolves(void **state)
{
    (void)state;
    char xdmf[600], h5[600];
    snprintf(xdmf, sizeof xdmf, "%s/chute.xdmf", out_dir);
    snprintf(h5, sizeof h5, "%s/chute.h5", out_dir);
    xmlDocPtr doc = xmlReadFile(xdmf, NULL, XML_PARSE_NONET);
    assert_non_null(doc);
    hid_t f = H5Fopen(h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    int n_refs = 0, n_grids = 0;
    xmlNodePtr stack[64];
    int top = 0;
    stack[top++] = xmlDocGetRootElement(doc);
    while (top > 0) {
        xmlNodePtr node = stack[--top];
        for (xmlNodePtr c = node->children; c; c = c->next)
            if (c->type == XML_ELEMENT_NODE && top < 63)
                stack[top++] = c;
        if (xmlStrcmp(node->name, BAD_CAST "Time") == 0)
            n_grids++;
        if (xmlStrcmp(node->name, BAD_CAST "Topology") == 0) {
            xmlChar *type = xmlGetProp(node, BAD_CAST "TopologyType"),
                    *dims = xmlGetProp(node, BAD_CAST "Dimensions");
            assert_string_equal((const char *)type, "3DCoRectMesh");
            assert_string_equal((const char *)dims, "61 2 2"); /* chute: 60 cells */
            xmlFree(type);
            xmlFree(dims);
        }
        if (xmlStrcmp(node->name, BAD_CAST "Attribute") == 0) {
            xmlChar *center = xmlGetProp(node, BAD_CAST "Center");
            assert_string_equal((const char *)center, "Cell");
            xmlFree(center);
        }
        if (xmlStrcmp(node->name, BAD_CAST "DataItem") != 0)
            continue;
        xmlChar *format = xmlGetProp(node, BAD_CAST "Format");
        if (format && xmlStrcmp(format, BAD_CAST "HDF") == 0) {
            xmlChar *text = xmlNodeGetContent(node);
            xmlChar *dims_attr = xmlGetProp(node, BAD_CAST "Dimensions");
            const char *colon = strchr((const char *)text, ':');
            assert_non_null(colon);
            assert_int_equal((int)(colon - (const char *)text), (int)strlen("chute.h5"));
            assert_memory_equal(text, "chute.h5", strlen("chute.h5"));
            const char *dset = colon + 1;
            assert_true(H5Lexists(f, dset, H5P_DEFAULT) > 0);
            int rank;
            hsize_t dims[2];
            read_dims(f, dset, &rank, dims);
            char want[64];
            if (rank == 2)
                snprintf(want, sizeof want, "%llu %llu", (unsigned long long)dims[0],
                         (unsigned long long)dims[1]);
            else
                snprintf(want, sizeof want, "%llu", (unsigned long long)dims[0]);
            assert_string_equal((const char *)dims_attr, want);
            check_view(f, dset);
            n_refs++;
            xmlFree(text);
            xmlFree(dims_attr);
        }
        xmlFree(format);
    }
    H5Fclose(f);
    xmlFreeDoc(doc);
    xmlCleanupParser();
    assert_int_equal(n_grids, 5);
    assert_int_equal(n_refs, 5 * 8);
}

/* The solid regime's failure is in the output: `ekm run tilting_layer.ini`
 * writes the first failure (hypo.fail_time, fail_angle, fail_fY) as root
 * attributes, and the regime field shows the layer solid (3) until just
 * before the failure and flowing (1 or 2) at the base at the end. */
static void test_failure_reported(void **state)
{
    (void)state;
    char cmd[2048], path[1024];
    snprintf(path, sizeof path, "%s/tilting_layer.h5", out_dir);
    snprintf(cmd, sizeof cmd,
             "'%s' run '%s/scenarios/tilting_layer.ini' -o '%s' --set run.output_dt=8 --quiet", EKM_BINARY,
             EKM_SOURCE_DIR, path);
    assert_int_equal(system(cmd), 0);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    const double t_fail = read_double_attr(f, "hypo.fail_time"),
                 angle = read_double_attr(f, "hypo.fail_angle");
    const double fY = read_double_attr(f, "hypo.fail_fY");
    printf(
        "tilting_layer output: hypo.fail_time %.4f s, fail_angle %.4f deg, fail_fY %.2e, hypo.to_flow %.0f\n",
        t_fail, angle, fY, read_double_attr(f, "hypo.to_flow"));
    /* the scenario: tilting from 18 deg at t = 0.5 s, t_end 630 s (24.295 deg), 40 cells */
    assert_true(t_fail > 0.5 && t_fail < 630.0);
    assert_true(angle > 18.0 && angle < 24.295);
    assert_true(fabs(fY) < 1e-3);
    assert_true(read_double_attr(f, "hypo.to_flow") >= 1.0);
    int rank;
    hsize_t dims[2];
    read_dims(f, "regime", &rank, dims);
    assert_int_equal(rank, 2);
    assert_true(dims[0] == 80 && dims[1] == 40); /* t = 0, 8, ..., 624, 630 s */
    int(*regime)[40] = malloc(sizeof(int[80][40]));
    assert_non_null(regime);
    hid_t d = H5Dopen2(f, "regime", H5P_DEFAULT);
    assert_true(H5Dread(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, regime) >= 0);
    H5Dclose(d);
    for (int j = 0; j < 40; j++) {
        assert_int_equal(regime[0][j], 3);
        assert_int_equal(regime[78][j], 3); /* t = 624 s: still solid */
    }
    assert_true(regime[79][0] == 1 ||
                regime[79][0] == 2); /* the base flows (dense, or dilated below phi_co) */
    free(regime);
    H5Fclose(f);
}

int main(void)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hdf5_layout),
        cmocka_unit_test(test_xdmf_resolves),
        cmocka_unit_test(test_failure_reported),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
