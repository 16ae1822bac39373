/* A pressure-held top wall moves the cells (issue 32: "an output must never
 * mean two things"): `ekm run` and `ekm steady` write /z as the cell centres
 * of every frame, [nt][nz], so the shear rate a reader fits to the last
 * frame's /vx against that frame's /z is the wall's velocity over that
 * frame's gap (plane Couette flow: a linear profile).  Before, `ekm run`
 * wrote the initial grid as /z: the fit gave 10.00 1/s (0.42 m/s over the
 * initial 42 mm) while the wall's 0.42 m/s over the final 38.44 mm is
 * 10.93 1/s, what `ekm steady`, whose /z was at the final gap, gave.  The
 * XDMF sidecar puts each frame's cells at that frame's /z. */
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

#include "h5.h"

/* The shear cell of the issue (its steady state: stop = steady at about
 * 31 s of 100, half a second of computing). */
#define SETS "--set material.eta0=5.1e-4 --set material.eps0=170 --set material.T0=2.2"

static char out_dir[512];

static int setup(void **state)
{
    (void)state;
    snprintf(out_dir, sizeof out_dir, "%s/moving_grid_test", EKM_BINARY_DIR);
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "rm -rf '%s' && mkdir -p '%s' && '%s' run '%s/scenarios/shear_cell.ini' -o '%s/run.h5' " SETS
             " --quiet && '%s' steady '%s/scenarios/shear_cell.ini' -o '%s/steady.h5' " SETS " --quiet",
             out_dir, out_dir, EKM_BINARY, EKM_SOURCE_DIR, out_dir, EKM_BINARY, EKM_SOURCE_DIR, out_dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Dataset `name` of f as doubles, of the given rank; its dims in dims. */
static double *read_all(ekm_h5_file *f, const char *name, int want_rank, size_t dims[EKM_H5_MAX_RANK])
{
    int rank;
    double *data = NULL;
    ekm_error err;
    if (ekm_h5_read_double(f, name, &rank, dims, &data, &err) != EKM_OK)
        fail_msg("%s", err.message);
    assert_int_equal(rank, want_rank);
    return data;
}

/* Least-squares slope of v against z over the interior cells 1 .. n-2. */
static double interior_slope(const double *z, const double *v, size_t n)
{
    double zbar = 0.0, vbar = 0.0;
    for (size_t j = 1; j + 1 < n; j++) {
        zbar += z[j];
        vbar += v[j];
    }
    zbar /= (double)(n - 2);
    vbar /= (double)(n - 2);
    double szz = 0.0, szv = 0.0;
    for (size_t j = 1; j + 1 < n; j++) {
        szz += (z[j] - zbar) * (z[j] - zbar);
        szv += (z[j] - zbar) * (v[j] - vbar);
    }
    return szv / szz;
}

typedef struct {
    size_t nt, nz;
    double *t, *z, *gap, *vx; /* [nt], [nt][nz], [nt], [nt][nz] */
    double wall;              /* top.velocity [m/s] */
} output;

static void output_read(output *o, const char *name)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s", out_dir, name);
    ekm_h5_file *f = NULL;
    ekm_error err;
    if (ekm_h5_open(&f, path, &err) != EKM_OK)
        fail_msg("%s", err.message);
    size_t dims[EKM_H5_MAX_RANK];
    o->t = read_all(f, "t", 1, dims);
    o->nt = dims[0];
    o->gap = read_all(f, "gap", 1, dims);
    assert_int_equal(dims[0], o->nt);
    o->z = read_all(f, "z", 2, dims);
    assert_int_equal(dims[0], o->nt);
    o->nz = dims[1];
    o->vx = read_all(f, "vx", 2, dims);
    assert_true(dims[0] == o->nt && dims[1] == o->nz);
    char units[16];
    assert_int_equal(ekm_h5_attr_get_string(f, "z", "units", units, sizeof units, &err), EKM_OK);
    assert_string_equal(units, "m");
    assert_int_equal(ekm_h5_attr_get_double(f, NULL, "top.velocity", &o->wall, &err), EKM_OK);
    ekm_h5_close(f);
    /* every row: the centres of the frame's nz cells over its gap */
    for (size_t i = 0; i < o->nt; i++)
        for (size_t j = 0; j < o->nz; j++)
            assert_true(fabs(o->z[i * o->nz + j] - ((double)j + 0.5) * o->gap[i] / (double)o->nz) <=
                        1e-12 * o->gap[i]);
}

static void output_free(output *o)
{
    free(o->t);
    free(o->z);
    free(o->gap);
    free(o->vx);
}

/* The shear rate of the last frame: fitted to /vx against /z of that
 * frame, and the wall's velocity over that frame's /gap. */
static double last_rate(const output *o, double *wall_rate)
{
    const size_t last = o->nt - 1;
    *wall_rate = o->wall / o->gap[last];
    return interior_slope(o->z + last * o->nz, o->vx + last * o->nz, o->nz);
}

static void test_run_shear_rate(void **state)
{
    (void)state;
    output o;
    output_read(&o, "run.h5");
    assert_true(o.nt > 2 && o.nz == 42);
    double wall_rate;
    const double rate = last_rate(&o, &wall_rate);
    /* against the first frame's grid (the old /z): 0.42 / 0.042 */
    const double rate_first = interior_slope(o.z, o.vx + (o.nt - 1) * o.nz, o.nz);
    printf("ekm run: gap %.6g -> %.6g m at t = %g s; last frame: shear rate from /z and /vx %.10g 1/s, "
           "wall / gap %.10g 1/s (relative difference %.2e); on the first frame's /z %.10g 1/s\n",
           o.gap[0], o.gap[o.nt - 1], o.t[o.nt - 1], rate, wall_rate, rate / wall_rate - 1.0, rate_first);
    assert_true(fabs(o.gap[o.nt - 1] - o.gap[0]) > 0.05 * o.gap[0]); /* the wall moved */
    assert_true(fabs(rate / wall_rate - 1.0) <= 1e-6);
    assert_true(fabs(rate_first / wall_rate - 1.0) > 0.05);
    output_free(&o);
}

static void test_steady_shear_rate(void **state)
{
    (void)state;
    output o, r;
    output_read(&o, "steady.h5");
    output_read(&r, "run.h5");
    assert_true(o.nt == 1 && o.nz == 42); /* one frame: /z [1][nz] */
    double wall_rate;
    const double rate = last_rate(&o, &wall_rate);
    printf("ekm steady: gap %.10g m; shear rate from /z and /vx %.10g 1/s, wall / gap %.10g 1/s "
           "(relative difference %.2e)\n",
           o.gap[0], rate, wall_rate, rate / wall_rate - 1.0);
    assert_true(fabs(rate / wall_rate - 1.0) <= 1e-6);
    /* the same state as the run's last frame, on the same cells */
    assert_true(fabs(o.gap[0] / r.gap[r.nt - 1] - 1.0) <= 1e-6);
    for (size_t j = 0; j < o.nz; j++)
        assert_true(fabs(o.z[j] - r.z[(r.nt - 1) * r.nz + j]) <= 1e-6 * o.gap[0]);
    output_free(&o);
    output_free(&r);
}

/* Up to n numbers of the text of an XML node into v; how many. */
static int node_numbers(xmlNodePtr node, double *v, int n)
{
    xmlChar *text = xmlNodeGetContent(node);
    const char *p = (const char *)text;
    int got = 0;
    for (char *end; got < n; got++, p = end) {
        v[got] = strtod(p, &end);
        if (end == p)
            break;
    }
    xmlFree(text);
    return got;
}

/* The sidecar: frame i (Time t[i]) is a column whose cell j is centred at
 * /z[i][j], origin + (j + 1/2) dz of its ORIGIN_DXDYDZ geometry along Z
 * (the first number: 3DCoRectMesh orders Z Y X). */
static void test_sidecar_geometry(void **state)
{
    (void)state;
    output o;
    output_read(&o, "run.h5");
    char path[700];
    snprintf(path, sizeof path, "%s/run.xdmf", out_dir);
    xmlDocPtr doc = xmlReadFile(path, NULL, XML_PARSE_NONET);
    assert_non_null(doc);
    xmlNodePtr domain = xmlDocGetRootElement(doc)->children;
    while (domain && domain->type != XML_ELEMENT_NODE)
        domain = domain->next;
    assert_non_null(domain);
    xmlNodePtr coll = domain->children;
    while (coll && coll->type != XML_ELEMENT_NODE)
        coll = coll->next;
    assert_non_null(coll);
    size_t frame = 0;
    for (xmlNodePtr g = coll->children; g; g = g->next) {
        if (g->type != XML_ELEMENT_NODE || xmlStrcmp(g->name, BAD_CAST "Grid"))
            continue;
        assert_true(frame < o.nt);
        double t = NAN, origin[3] = {NAN, NAN, NAN}, spacing[3] = {NAN, NAN, NAN};
        for (xmlNodePtr c = g->children; c; c = c->next) {
            if (c->type != XML_ELEMENT_NODE)
                continue;
            if (!xmlStrcmp(c->name, BAD_CAST "Time")) {
                xmlChar *v = xmlGetProp(c, BAD_CAST "Value");
                t = strtod((const char *)v, NULL);
                xmlFree(v);
            } else if (!xmlStrcmp(c->name, BAD_CAST "Geometry")) {
                int item = 0;
                for (xmlNodePtr d = c->children; d; d = d->next)
                    if (d->type == XML_ELEMENT_NODE)
                        assert_int_equal(node_numbers(d, item++ ? spacing : origin, 3), 3);
                assert_int_equal(item, 2);
            }
        }
        assert_true(t == o.t[frame]);
        for (size_t j = 0; j < o.nz; j++)
            assert_true(fabs(origin[0] + ((double)j + 0.5) * spacing[0] - o.z[frame * o.nz + j]) <=
                        1e-12 * o.gap[frame]);
        frame++;
    }
    assert_int_equal(frame, o.nt);
    xmlFreeDoc(doc);
    xmlCleanupParser();
    output_free(&o);
}

int main(void)
{
    ekm_h5_quiet();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_shear_rate),
        cmocka_unit_test(test_steady_shear_rate),
        cmocka_unit_test(test_sidecar_geometry),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
