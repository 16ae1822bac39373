/* score2d.c: `ekmcompare score2d` (score2d.h). */
#include "score2d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "ekm_version.h"
#include "h5.h"
#include "h5kind.h"
#include "json_out.h"
#include "score.h"

#define SCORE2D_JSON_FLAGS (JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(9))

static const char *const KNOWN[] = {"phi", "sxx", "szz", "sxz"};
enum { NKNOWN = 4, MAX_FIELDS = 4 };

cg_score2d_opts cg_score2d_opts_default(void)
{
    cg_score2d_opts o;
    memset(&o, 0, sizeof o);
    o.time = NAN;
    o.support = CG_SCORE_SUPPORT;
    return o;
}

/* One side on its grid: fields [nz][nx] (the requested ones, phi always). */
typedef struct {
    const char *path, *group; /* group NULL: an ekm run */
    char prefix[256];         /* a map's group without trailing '/' ("": the root) */
    size_t nx, nz;
    double *x, *z;
    double *phi, *mask; /* mask: a map's, or NULL */
    double *f[MAX_FIELDS], *se[MAX_FIELDS];
    double t; /* the ekm run's frame time [s]; NAN for a map */
} side2d;

static void side_free(side2d *s)
{
    free(s->x);
    free(s->z);
    free(s->phi);
    free(s->mask);
    for (int k = 0; k < MAX_FIELDS; k++) {
        free(s->f[k]);
        free(s->se[k]);
    }
}

static const char *units_of(const char *field)
{
    return strcmp(field, "phi") ? "Pa" : "1";
}

static ekm_status parse_fields(const char *list, char names[MAX_FIELDS][16], size_t *nf, ekm_error *err)
{
    const char *s = list ? list : "phi,sxx,szz,sxz";
    *nf = 0;
    while (*s) {
        const char *e = strchr(s, ',');
        const size_t len = e ? (size_t)(e - s) : strlen(s);
        int known = -1;
        for (int k = 0; k < NKNOWN; k++)
            if (strlen(KNOWN[k]) == len && !strncmp(s, KNOWN[k], len))
                known = k;
        if (known < 0)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "score2d: --fields: unknown field '%.*s' (expected phi, sxx, szz, sxz)",
                            (int)(len < 40 ? len : 40), s);
        for (size_t i = 0; i < *nf; i++)
            if (!strcmp(names[i], KNOWN[known]))
                return EKM_FAIL(err, EKM_EUSAGE, "score2d: --fields: '%s' given twice", KNOWN[known]);
        snprintf(names[(*nf)++], 16, "%s", KNOWN[known]);
        if (!e)
            break;
        s = e + 1;
    }
    if (*nf == 0)
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: --fields: expected at least one field");
    return EKM_OK;
}

/* An increasing axis of n >= 1 finite values. */
static ekm_status read_axis(ekm_h5_file *f, const char *name, double **x, size_t *n, ekm_error *err)
{
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    ekm_status rc = ekm_h5_read_double(f, name, &rank, dims, x, err);
    if (rc)
        return rc;
    if (rank != 1 || dims[0] < 1)
        return EKM_FAIL(err, EKM_EINPUT, "%s: %s: expected a 1D dataset of cell centres", ekm_h5_path(f),
                        name);
    *n = dims[0];
    for (size_t i = 0; i < *n; i++)
        if (!isfinite((*x)[i]) || (i > 0 && !((*x)[i] > (*x)[i - 1])))
            return EKM_FAIL(err, EKM_EINPUT, "%s: %s: expected finite, increasing cell centres",
                            ekm_h5_path(f), name);
    return EKM_OK;
}

static void join(char *buf, size_t size, const char *prefix, const char *name)
{
    if (prefix[0])
        snprintf(buf, size, "%s/%s", prefix, name);
    else
        snprintf(buf, size, "%s", name);
}

/* A map dataset [nz][nx] of the side's group. */
static ekm_status read_map_field(ekm_h5_file *f, const side2d *s, const char *name, double **out,
                                 ekm_error *err)
{
    char path[512];
    join(path, sizeof path, s->prefix, name);
    if (!ekm_h5_exists(f, path))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: expected a dataset %s (a pile map's group: x, z, phi, sxx, szz, sxz, "
                        "FIELD_se, mask)",
                        s->path, path);
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    ekm_status rc = ekm_h5_read_double(f, path, &rank, dims, out, err);
    if (!rc && !(rank == 2 && dims[0] == s->nz && dims[1] == s->nx))
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: %s: expected [%zu][%zu] values (z, x)", s->path, path, s->nz,
                      s->nx);
    return rc;
}

static ekm_status read_map(ekm_h5_file *f, side2d *s, char names[][16], size_t nf, ekm_error *err)
{
    char path[512];
    const size_t len = strlen(s->group);
    if (len >= sizeof s->prefix)
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: the group name %.40s... is too long", s->group);
    memcpy(s->prefix, s->group, len + 1);
    for (size_t n = len; n > 0 && s->prefix[n - 1] == '/'; n--)
        s->prefix[n - 1] = '\0';
    if (s->prefix[0] && !ekm_h5_exists(f, s->prefix))
        return EKM_FAIL(err, EKM_EINPUT, "%s: no group %s (a pile map's groups are /ENGINE/LAW/SOURCE)",
                        s->path, s->group);
    join(path, sizeof path, s->prefix, "x");
    ekm_status rc = read_axis(f, path, &s->x, &s->nx, err);
    if (!rc) {
        join(path, sizeof path, s->prefix, "z");
        rc = read_axis(f, path, &s->z, &s->nz, err);
    }
    if (!rc)
        rc = read_map_field(f, s, "phi", &s->phi, err);
    if (!rc) {
        join(path, sizeof path, s->prefix, "mask");
        if (ekm_h5_exists(f, path))
            rc = read_map_field(f, s, "mask", &s->mask, err);
    }
    for (size_t k = 0; k < nf && !rc; k++) {
        char se[32];
        snprintf(se, sizeof se, "%s_se", names[k]);
        rc = read_map_field(f, s, names[k], &s->f[k], err);
        if (!rc)
            rc = read_map_field(f, s, se, &s->se[k], err);
    }
    return rc;
}

/* Frame k of an ekm run's field [nt][nz][nx], times sign. */
static ekm_status read_run_field(ekm_h5_file *f, side2d *s, const char *name, size_t nt, size_t k,
                                 double sign, double **out, ekm_error *err)
{
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    double *all = NULL;
    ekm_status rc = ekm_h5_read_double(f, name, &rank, dims, &all, err);
    if (!rc && !(rank == 3 && dims[0] == nt && dims[1] == s->nz && dims[2] == s->nx))
        rc = EKM_FAIL(err, EKM_EINPUT,
                      "%s: %s: expected [%zu][%zu][%zu] values (t, z, x: a 2D run's output; a slab run's "
                      "output is scored by `ekmcompare score`)",
                      s->path, name, nt, s->nz, s->nx);
    if (!rc) {
        const size_t n = s->nz * s->nx;
        *out = malloc(n * sizeof **out);
        if (!*out)
            rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        else
            for (size_t i = 0; i < n; i++)
                (*out)[i] = sign * all[k * n + i];
    }
    free(all);
    return rc;
}

static ekm_status read_run(ekm_h5_file *f, side2d *s, double time, char names[][16], size_t nf,
                           ekm_error *err)
{
    ekm_status rc = cg_h5kind_check(f, "score2d", "--model", CG_H5KIND_EKM, err);
    double *t = NULL;
    size_t nt = 0;
    if (!rc)
        rc = read_axis(f, "x", &s->x, &s->nx, err);
    if (!rc)
        rc = read_axis(f, "z", &s->z, &s->nz, err);
    if (!rc)
        rc = read_axis(f, "t", &t, &nt, err);
    size_t k = nt ? nt - 1 : 0;
    if (!rc && isfinite(time)) {
        size_t best = 0;
        for (size_t i = 1; i < nt; i++)
            if (fabs(t[i] - time) < fabs(t[best] - time))
                best = i;
        if (!(fabs(t[best] - time) <= 1e-9 * fmax(1.0, fabs(time))))
            rc = EKM_FAIL(err, EKM_EINPUT,
                          "%s: no output at t = %g s (--time; the nearest is %.9g s, of %zu from %g to %g s)",
                          s->path, time, t[best], nt, t[0], t[nt - 1]);
        k = best;
    }
    if (!rc) {
        s->t = t[k];
        rc = read_run_field(f, s, "phi", nt, k, 1.0, &s->phi, err);
    }
    /* ekm's stresses are tension positive, the maps' compression positive */
    for (size_t i = 0; i < nf && !rc; i++)
        rc = read_run_field(f, s, names[i], nt, k, strcmp(names[i], "phi") ? -1.0 : 1.0, &s->f[i], err);
    free(t);
    return rc;
}

static ekm_status read_side(side2d *s, double time, char names[][16], size_t nf, ekm_error *err)
{
    ekm_h5_file *f = NULL;
    ekm_status rc = ekm_h5_open(&f, s->path, err);
    if (!rc)
        rc = s->group ? read_map(f, s, names, nf, err) : read_run(f, s, time, names, nf, err);
    ekm_h5_close(f);
    return rc;
}

/* The model's value of field f (its [nz][nx] array) at DEM centre (x, z):
 * bilinear between the model's centres; NAN outside them. */
static double model_at(const side2d *m, const double *f, double x, double z)
{
    size_t i, j;
    double ax, az;
    if (!cg_score_locate(m->x, m->nx, x, &i, &ax) || !cg_score_locate(m->z, m->nz, z, &j, &az))
        return NAN;
    const size_t j1 = j + 1 < m->nz ? j + 1 : j;
    return cg_score_interp(f + j * m->nx, f + j1 * m->nx, m->nx, i, ax, az);
}

static json_t *side_json(const side2d *s, int *bad)
{
    json_t *o = json_object();
    ekm_json_set(o, "path", json_string(s->path), bad);
    ekm_json_set(o, "group", s->group ? json_string(s->group) : json_null(), bad);
    ekm_json_set(o, "kind", json_string(s->group ? "pile map" : "ekm run"), bad);
    ekm_json_set(o, "t_s", ekm_json_number(s->t), bad);
    ekm_json_set(o, "cells", json_integer((json_int_t)(s->nx * s->nz)), bad);
    return o;
}

static ekm_status write_json(const cg_score2d_opts *o, const side2d *d, const side2d *m, double support_phi,
                             const cg_score2d_row *rows, size_t nrows, ekm_error *err)
{
    int bad = 0;
    json_t *root = json_object(), *res = json_object(), *opt = json_object();
    ekm_json_set(root, "tool", json_string("ekmcompare score2d"), &bad);
    ekm_json_set(root, "code_version", json_string(EKMBENCH_VERSION), &bad);
    ekm_json_set(root, "dem", side_json(d, &bad), &bad);
    ekm_json_set(root, "model", side_json(m, &bad), &bad);
    ekm_json_set(opt, "support", ekm_json_number(o->support), &bad);
    ekm_json_set(opt, "support_phi", ekm_json_number(support_phi), &bad);
    ekm_json_set(opt, "stress_sign", json_string("compression positive (an ekm run's stresses negated)"),
                 &bad);
    ekm_json_set(opt, "se", json_string(m->group ? "dem and model in quadrature" : "dem"), &bad);
    ekm_json_set(opt, "se_floor_rel_rms", ekm_json_number(CG_SCORE_SE_FLOOR), &bad);
    ekm_json_set(root, "options", opt, &bad);
    for (size_t r = 0; r < nrows; r++) {
        json_t *fr = json_object_get(res, rows[r].field);
        if (!fr) {
            fr = json_object();
            ekm_json_set(fr, "units", json_string(rows[r].units), &bad);
            ekm_json_set(res, rows[r].field, fr, &bad);
        }
        json_t *g = json_object();
        ekm_json_set(g, "points", json_integer((json_int_t)rows[r].m.points), &bad);
        ekm_json_set(g, "points_with_se", json_integer((json_int_t)rows[r].m.points_se), &bad);
        ekm_json_set(g, "rel_l2", ekm_json_number(rows[r].m.rel_l2), &bad);
        ekm_json_set(g, "noise_normalised", ekm_json_number(rows[r].m.noise), &bad);
        ekm_json_set(fr, rows[r].region, g, &bad);
    }
    ekm_json_set(root, "fields", res, &bad);
    ekm_status rc = bad ? EKM_FAIL(err, EKM_ENOMEM, "score2d: out of memory building the JSON")
                        : ekm_json_write(o->json, root, SCORE2D_JSON_FLAGS, err);
    json_decref(root);
    return rc;
}

static void write_table(FILE *fp, const side2d *d, const side2d *m, const cg_score2d_row *rows, size_t nrows)
{
    if (m->group)
        fprintf(fp, "score2d: %s %s against %s %s\n\n", m->path, m->group, d->path, d->group);
    else
        fprintf(fp, "score2d: %s at t = %g s against %s %s\n\n", m->path, m->t, d->path, d->group);
    fprintf(fp, "| field | region | points | rel. L2 | noise-normalised |\n|---|---|---:|---:|---:|\n");
    for (size_t r = 0; r < nrows; r++)
        fprintf(fp, "| %s [%s] | %s | %zu | %.4g | %.4g |\n", rows[r].field, rows[r].units, rows[r].region,
                rows[r].m.points, rows[r].m.rel_l2, rows[r].m.noise);
}

ekm_status cg_score2d(const cg_score2d_opts *o, cg_score2d_row *rows, size_t *nrows, ekm_error *err)
{
    char names[MAX_FIELDS][16];
    size_t nf = 0;
    *nrows = 0;
    if (!o->dem || !o->group || !o->model)
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: expected --dem MAPS.h5 --group GROUP --model FILE");
    if (!(o->support >= 0.0 && o->support < 1.0))
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: --support: expected a fraction in [0, 1), got %g",
                        o->support);
    if (o->model_group && isfinite(o->time))
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: --time applies to an ekm run, not to --model-group");
    ekm_status rc = parse_fields(o->fields, names, &nf, err);
    if (rc)
        return rc;
    if (o->json) {
        const char *inputs[2] = {o->dem, o->model};
        rc = ekm_atomic_refuse_input(o->json, inputs, 2, err);
        if (!rc)
            rc = ekm_atomic_check_target(o->json, err);
        if (rc)
            return rc;
    }
    side2d d = {.path = o->dem, .group = o->group, .t = NAN};
    side2d m = {.path = o->model, .group = o->model_group, .t = NAN};
    rc = read_side(&d, NAN, names, nf, err);
    if (!rc)
        rc = read_side(&m, o->time, names, nf, err);
    const size_t n = d.nx * d.nz;
    double *mv = NULL, *dv = NULL, *sv = NULL, *mphi = NULL;
    if (!rc) {
        mv = malloc(n * sizeof *mv);
        dv = malloc(n * sizeof *dv);
        sv = malloc(n * sizeof *sv);
        mphi = malloc(n * sizeof *mphi);
        if (!mv || !dv || !sv || !mphi)
            rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    double phi_max = 0.0;
    size_t common = 0;
    if (!rc) {
        for (size_t c = 0; c < n; c++) {
            if (isfinite(d.phi[c]))
                phi_max = fmax(phi_max, d.phi[c]);
            mphi[c] = model_at(&m, m.phi, d.x[c % d.nx], d.z[c / d.nx]);
        }
        for (size_t c = 0; c < n; c++)
            common += isfinite(mphi[c]) && d.phi[c] > o->support * phi_max && mphi[c] > o->support * phi_max;
        if (!(phi_max > 0.0) || common == 0)
            rc = EKM_FAIL(
                err, EKM_EINPUT,
                "score2d: %s and %s share no cell with material (phi above %g x the DEM's largest, %g; "
                "the grids: x %g..%g and %g..%g m, z %g..%g and %g..%g m)",
                o->dem, o->model, o->support, phi_max, d.x[0], d.x[d.nx - 1], m.x[0], m.x[m.nx - 1], d.z[0],
                d.z[d.nz - 1], m.z[0], m.z[m.nz - 1]);
    }
    const double thr = o->support * phi_max;
    cg_score2d_row out[CG_SCORE2D_MAX_ROWS];
    for (size_t k = 0; k < nf && !rc; k++)
        for (int region = 0; region < 2 && !rc; region++) {
            if (region == 1 && !d.mask)
                continue;
            size_t p = 0;
            for (size_t c = 0; c < n; c++) {
                if (!(d.phi[c] > thr && mphi[c] > thr) || (region == 1 && !(d.mask[c] > 0.5)))
                    continue;
                const double v = model_at(&m, m.f[k], d.x[c % d.nx], d.z[c / d.nx]);
                mv[p] = v;
                dv[p] = d.f[k][c];
                const double sm = m.group ? model_at(&m, m.se[k], d.x[c % d.nx], d.z[c / d.nx]) : 0.0;
                sv[p] = sqrt(d.se[k][c] * d.se[k][c] + sm * sm);
                p++;
            }
            cg_score2d_row row = {.units = units_of(names[k]), .region = region ? "interior" : "support"};
            snprintf(row.field, sizeof row.field, "%s", names[k]);
            row.m = cg_metric_compute(mv, dv, sv, p, CG_SCORE_SE_FLOOR);
            out[(*nrows)++] = row;
        }
    if (!rc && o->table)
        write_table(o->table, &d, &m, out, *nrows);
    if (!rc && o->json)
        rc = write_json(o, &d, &m, thr, out, *nrows, err);
    if (!rc && rows)
        memcpy(rows, out, *nrows * sizeof *out);
    if (rc)
        *nrows = 0;
    free(mv);
    free(dv);
    free(sv);
    free(mphi);
    side_free(&d);
    side_free(&m);
    return rc;
}
