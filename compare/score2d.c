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

static const char *const KNOWN[] = {"phi", "P", "sxx", "szz", "sxz"};
enum { NKNOWN = 5, MAX_FIELDS = 5 };

cg_score2d_opts cg_score2d_opts_default(void)
{
    cg_score2d_opts o;
    memset(&o, 0, sizeof o);
    o.time = NAN;
    o.support = CG_SCORE_SUPPORT;
    return o;
}

typedef enum { SIDE_MAP, SIDE_RUN, SIDE_CG } side_kind;

/* One side on its grid: the frame's fields [nz][nx], compression positive. */
typedef struct {
    side_kind kind;
    const char *path, *group; /* group: a map's, as given */
    char prefix[256];         /* a map's group without trailing '/' ("": the root) */
    ekm_h5_file *f;
    size_t nx, nz, nt, frame; /* nt, frame: a run's or cg output's series */
    double *x, *z;
    double *phi, *mask; /* mask: a map's, or NULL */
    double *v[MAX_FIELDS], *se[MAX_FIELDS];
    double t; /* the frame's time [s]; NAN for a map */
} side2d;

static void side_free(side2d *s)
{
    ekm_h5_close(s->f);
    free(s->x);
    free(s->z);
    free(s->phi);
    free(s->mask);
    for (int k = 0; k < MAX_FIELDS; k++) {
        free(s->v[k]);
        free(s->se[k]);
    }
}

static const char *units_of(const char *field)
{
    return strcmp(field, "phi") ? "Pa" : "1";
}

/* The factor that makes a side's field compression positive: the maps are,
 * ekm's and cg's stress components are negative in compression (P is
 * positive in both). */
static double sign_of(const side2d *s, const char *field)
{
    return s->kind != SIDE_MAP && field[0] == 's' ? -1.0 : 1.0;
}

static const char *kind_name(const side2d *s)
{
    return s->kind == SIDE_MAP ? "pile map" : s->kind == SIDE_RUN ? "ekm run" : "ekmcompare cg 2D";
}

static void join(char *buf, size_t size, const side2d *s, const char *name)
{
    if (s->kind == SIDE_MAP && s->prefix[0])
        snprintf(buf, size, "%s/%s", s->prefix, name);
    else
        snprintf(buf, size, "%s", name);
}

static int has(const side2d *s, const char *name)
{
    char path[512];
    join(path, sizeof path, s, name);
    return ekm_h5_exists(s->f, path);
}

static ekm_status parse_fields(const char *list, char names[MAX_FIELDS][16], size_t *nf, ekm_error *err)
{
    const char *p = list;
    *nf = 0;
    while (*p) {
        const char *e = strchr(p, ',');
        const size_t len = e ? (size_t)(e - p) : strlen(p);
        int known = -1;
        for (int k = 0; k < NKNOWN; k++)
            if (strlen(KNOWN[k]) == len && !strncmp(p, KNOWN[k], len))
                known = k;
        if (known < 0)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "score2d: --fields: unknown field '%.*s' (expected phi, P, sxx, szz, sxz)",
                            (int)(len < 40 ? len : 40), p);
        for (size_t i = 0; i < *nf; i++)
            if (!strcmp(names[i], KNOWN[known]))
                return EKM_FAIL(err, EKM_EUSAGE, "score2d: --fields: '%s' given twice", KNOWN[known]);
        snprintf(names[(*nf)++], 16, "%s", KNOWN[known]);
        if (!e)
            break;
        p = e + 1;
    }
    if (*nf == 0)
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: --fields: expected at least one field");
    return EKM_OK;
}

/* An increasing axis of n >= 1 finite values. */
static ekm_status read_axis(const side2d *s, const char *name, double **x, size_t *n, ekm_error *err)
{
    char path[512];
    join(path, sizeof path, s, name);
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    ekm_status rc = ekm_h5_read_double(s->f, path, &rank, dims, x, err);
    if (rc)
        return rc;
    if (rank != 1 || dims[0] < 1)
        return EKM_FAIL(err, EKM_EINPUT, "%s: %s: expected a 1D dataset of cell centres", s->path, path);
    *n = dims[0];
    for (size_t i = 0; i < *n; i++)
        if (!isfinite((*x)[i]) || (i > 0 && !((*x)[i] > (*x)[i - 1])))
            return EKM_FAIL(err, EKM_EINPUT, "%s: %s: expected finite, increasing values", s->path, path);
    return EKM_OK;
}

/* Field NAME of the side's frame into *out [nz][nx], times sign: a map's
 * [nz][nx] dataset, a series' row `frame` of [nt][nz][nx]. */
static ekm_status read_frame(side2d *s, const char *name, double sign, double **out, ekm_error *err)
{
    char path[512];
    join(path, sizeof path, s, name);
    if (!ekm_h5_exists(s->f, path))
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s (%s)", s->path, path,
                        s->kind == SIDE_MAP ? "a pile map's group: x, z, phi, sxx, szz, sxz, FIELD_se, mask"
                                            : "the fields of a 2D grid [nt][nz][nx]");
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    double *all = NULL;
    ekm_status rc = ekm_h5_read_double(s->f, path, &rank, dims, &all, err);
    const int series = s->kind != SIDE_MAP;
    if (!rc && series && !(rank == 3 && dims[0] == s->nt && dims[1] == s->nz && dims[2] == s->nx))
        rc = EKM_FAIL(err, EKM_EINPUT,
                      "%s: %s: expected [%zu][%zu][%zu] values (t, z, x: a 2D grid's; a slab's profiles are "
                      "scored by `ekmcompare score`)",
                      s->path, path, s->nt, s->nz, s->nx);
    if (!rc && !series && !(rank == 2 && dims[0] == s->nz && dims[1] == s->nx))
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: %s: expected [%zu][%zu] values (z, x)", s->path, path, s->nz,
                      s->nx);
    if (!rc) {
        const size_t n = s->nz * s->nx, off = series ? s->frame * n : 0;
        *out = malloc(n * sizeof **out);
        if (!*out)
            rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        else
            for (size_t i = 0; i < n; i++)
                (*out)[i] = sign * all[off + i];
    }
    free(all);
    return rc;
}

/* Open a side, check its kind, read its grid and pick its frame. */
static ekm_status open_side(side2d *s, const char *option, double time, ekm_error *err)
{
    ekm_status rc = ekm_h5_open(&s->f, s->path, err);
    if (rc)
        return rc;
    if (s->group) {
        const size_t len = strlen(s->group);
        if (len >= sizeof s->prefix)
            return EKM_FAIL(err, EKM_EUSAGE, "score2d: the group name %.40s... is too long", s->group);
        memcpy(s->prefix, s->group, len + 1);
        for (size_t n = len; n > 0 && s->prefix[n - 1] == '/'; n--)
            s->prefix[n - 1] = '\0';
        if (s->prefix[0] && !ekm_h5_exists(s->f, s->prefix))
            return EKM_FAIL(err, EKM_EINPUT, "%s: no group %s (a pile map's groups are /ENGINE/LAW/SOURCE)",
                            s->path, s->group);
    } else {
        /* the DEM: a cg output; the model: an ekm run or a cg output
         * (engine against engine) */
        const unsigned allowed = s->kind == SIDE_CG ? CG_H5KIND_CG : CG_H5KIND_EKM | CG_H5KIND_CG;
        rc = cg_h5kind_check(s->f, "score2d", option, allowed, err);
        if (rc)
            return rc;
        if (s->kind == SIDE_RUN && cg_h5kind_of(s->f) == CG_H5KIND_CG)
            s->kind = SIDE_CG;
    }
    rc = read_axis(s, "x", &s->x, &s->nx, err);
    if (!rc)
        rc = read_axis(s, "z", &s->z, &s->nz, err);
    if (rc || s->kind == SIDE_MAP)
        return rc;
    double *t = NULL;
    rc = read_axis(s, "t", &t, &s->nt, err);
    if (!rc) {
        s->frame = s->nt - 1;
        if (isfinite(time)) {
            size_t best = 0;
            for (size_t i = 1; i < s->nt; i++)
                if (fabs(t[i] - time) < fabs(t[best] - time))
                    best = i;
            if (!(fabs(t[best] - time) <= 1e-9 * fmax(1.0, fabs(time))))
                rc = EKM_FAIL(
                    err, EKM_EINPUT,
                    "%s: no output at t = %g s (--time; the nearest is %.9g s, of %zu from %g to %g s)",
                    s->path, time, t[best], s->nt, t[0], t[s->nt - 1]);
            s->frame = best;
        }
        s->t = t[s->frame];
    }
    free(t);
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
    ekm_json_set(o, "kind", json_string(kind_name(s)), bad);
    ekm_json_set(o, "t_s", ekm_json_number(s->t), bad);
    ekm_json_set(o, "cells", json_integer((json_int_t)(s->nx * s->nz)), bad);
    return o;
}

static json_t *metric_json(const cg_metric *m, int *bad)
{
    json_t *g = json_object();
    ekm_json_set(g, "points", json_integer((json_int_t)m->points), bad);
    ekm_json_set(g, "points_with_se", json_integer((json_int_t)m->points_se), bad);
    ekm_json_set(g, "rel_l2", ekm_json_number(m->rel_l2), bad);
    ekm_json_set(g, "noise_normalised", ekm_json_number(m->noise), bad);
    return g;
}

/* SCORE.json: per field the support region's metric at the field's top
 * level (score.h's layout, which the campaign's table reads) and the
 * interior's under "interior". */
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
    ekm_json_set(opt, "stress_sign", json_string("compression positive (ekm's and cg's stresses negated)"),
                 &bad);
    ekm_json_set(opt, "se",
                 json_string(o->no_noise           ? "none (--noise none: noise-normalised errors null)"
                             : m->kind == SIDE_RUN ? "dem"
                                                   : "dem and model in quadrature"),
                 &bad);
    ekm_json_set(opt, "se_floor_rel_rms", ekm_json_number(CG_SCORE_SE_FLOOR), &bad);
    ekm_json_set(root, "options", opt, &bad);
    for (size_t r = 0; r < nrows; r++) {
        json_t *fr = json_object_get(res, rows[r].field);
        if (!fr) {
            fr = metric_json(&rows[r].m, &bad);
            ekm_json_set(fr, "units", json_string(rows[r].units), &bad);
            ekm_json_set(fr, "points_left_out", json_integer((json_int_t)rows[r].left_out), &bad);
            ekm_json_set(fr, "se",
                         json_string(o->no_noise           ? "none"
                                     : m->kind == SIDE_RUN ? "dem"
                                                           : "both, in quadrature"),
                         &bad);
            ekm_json_set(res, rows[r].field, fr, &bad);
        } else
            ekm_json_set(fr, rows[r].region, metric_json(&rows[r].m, &bad), &bad);
    }
    ekm_json_set(root, "fields", res, &bad);
    ekm_json_set(root, "free_surface", json_null(), &bad);
    ekm_json_set(root, "model_run", json_null(), &bad);
    if (o->dem_sha256) {
        json_t *in = json_object();
        ekm_json_set(in, "dem", json_pack("{s:s, s:s}", "path", o->dem, "sha256", o->dem_sha256), &bad);
        ekm_json_set(in, "ekm", json_pack("{s:s, s:s}", "path", o->model, "sha256", o->ekm_sha256), &bad);
        ekm_json_set(root, "inputs", in, &bad);
    }
    ekm_status rc = bad ? EKM_FAIL(err, EKM_ENOMEM, "score2d: out of memory building the JSON")
                        : ekm_json_write(o->json, root, SCORE2D_JSON_FLAGS, err);
    json_decref(root);
    return rc;
}

static void write_table(FILE *fp, const side2d *d, const side2d *m, const cg_score2d_row *rows, size_t nrows)
{
    if (m->kind == SIDE_MAP)
        fprintf(fp, "score2d: %s %s", m->path, m->group);
    else
        fprintf(fp, "score2d: %s at t = %g s", m->path, m->t);
    if (d->kind == SIDE_MAP)
        fprintf(fp, " against %s %s\n\n", d->path, d->group);
    else
        fprintf(fp, " against %s at t = %g s\n\n", d->path, d->t);
    fprintf(fp, "| field | region | points | left out | rel. L2 | noise-normalised |\n"
                "|---|---|---:|---:|---:|---:|\n");
    for (size_t r = 0; r < nrows; r++) {
        fprintf(fp, "| %s [%s] | %s | %zu | %zu | %.4g | ", rows[r].field, rows[r].units, rows[r].region,
                rows[r].m.points, rows[r].left_out, rows[r].m.rel_l2);
        if (isfinite(rows[r].m.noise))
            fprintf(fp, "%.4g |\n", rows[r].m.noise);
        else
            fprintf(fp, "- |\n");
    }
}

static ekm_status check_opts(const cg_score2d_opts *o, ekm_error *err)
{
    if (!o->dem || !o->model)
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: expected --dem FILE [--group G] --model FILE");
    if (!(o->support >= 0.0 && o->support < 1.0))
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: --support: expected a fraction in [0, 1), got %g",
                        o->support);
    if (o->model_group && isfinite(o->time))
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: --time applies to an ekm run, not to --model-group");
    if (!o->dem_sha256 != !o->ekm_sha256)
        return EKM_FAIL(err, EKM_EUSAGE, "score2d: --dem-sha256 and --ekm-sha256 go together");
    if ((o->dem_sha256 && !cg_score_is_sha256(o->dem_sha256)) ||
        (o->ekm_sha256 && !cg_score_is_sha256(o->ekm_sha256)))
        return EKM_FAIL(err, EKM_EUSAGE,
                        "score2d: --dem-sha256, --ekm-sha256: expected 64 lowercase hex digits");
    if (o->json) {
        const char *inputs[2] = {o->dem, o->model};
        ekm_status rc = ekm_atomic_refuse_input(o->json, inputs, 2, err);
        if (!rc)
            rc = ekm_atomic_check_target(o->json, err);
        return rc;
    }
    return EKM_OK;
}

/* The fields to score: --fields, or those of phi,P,sxx,szz,sxz both sides
 * have (and their SEs, where a side carries them). */
static ekm_status choose_fields(const cg_score2d_opts *o, const side2d *d, const side2d *m,
                                char names[MAX_FIELDS][16], size_t *nf, ekm_error *err)
{
    if (o->fields)
        return parse_fields(o->fields, names, nf, err);
    *nf = 0;
    for (int k = 0; k < NKNOWN; k++)
        if (has(d, KNOWN[k]) && has(m, KNOWN[k]))
            snprintf(names[(*nf)++], 16, "%s", KNOWN[k]);
    if (*nf == 0)
        return EKM_FAIL(err, EKM_EINPUT, "score2d: %s and %s have no field in common (phi, P, sxx, szz, sxz)",
                        o->dem, o->model);
    return EKM_OK;
}

static ekm_status read_fields(side2d *s, char names[][16], size_t nf, int with_se, ekm_error *err)
{
    ekm_status rc = read_frame(s, "phi", 1.0, &s->phi, err);
    if (!rc && s->kind == SIDE_MAP && has(s, "mask"))
        rc = read_frame(s, "mask", 1.0, &s->mask, err);
    for (size_t k = 0; k < nf && !rc; k++) {
        const double sign = sign_of(s, names[k]);
        rc = read_frame(s, names[k], sign, &s->v[k], err);
        if (!rc && with_se) {
            char se[32];
            snprintf(se, sizeof se, "%s_se", names[k]);
            rc = read_frame(s, se, 1.0, &s->se[k], err);
        }
    }
    return rc;
}

ekm_status cg_score2d(const cg_score2d_opts *o, cg_score2d_row *rows, size_t *nrows, ekm_error *err)
{
    char names[MAX_FIELDS][16];
    size_t nf = 0;
    *nrows = 0;
    ekm_status rc = check_opts(o, err);
    if (rc)
        return rc;
    side2d d = {.kind = o->group ? SIDE_MAP : SIDE_CG, .path = o->dem, .group = o->group, .t = NAN};
    side2d m = {
        .kind = o->model_group ? SIDE_MAP : SIDE_RUN, .path = o->model, .group = o->model_group, .t = NAN};
    rc = open_side(&d, "--dem", NAN, err);
    if (!rc)
        rc = open_side(&m, "--model", o->time, err);
    if (!rc)
        rc = choose_fields(o, &d, &m, names, &nf, err);
    if (!rc)
        rc = read_fields(&d, names, nf, 1, err);
    if (!rc)
        rc = read_fields(&m, names, nf, m.kind != SIDE_RUN, err);
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
            size_t p = 0, left_out = 0;
            for (size_t c = 0; c < n; c++) {
                if (!(d.phi[c] > thr) || (region == 1 && !(d.mask[c] > 0.5)))
                    continue;
                if (!(mphi[c] > thr)) {
                    left_out++;
                    continue;
                }
                const double x = d.x[c % d.nx], z = d.z[c / d.nx];
                mv[p] = model_at(&m, m.v[k], x, z);
                dv[p] = d.v[k][c];
                const double sm = m.se[k] ? model_at(&m, m.se[k], x, z) : 0.0;
                sv[p] = sqrt(d.se[k][c] * d.se[k][c] + sm * sm);
                p++;
            }
            cg_score2d_row row = {.units = units_of(names[k]), .region = region ? "interior" : "support"};
            snprintf(row.field, sizeof row.field, "%s", names[k]);
            row.m = cg_metric_compute(mv, dv, sv, p, CG_SCORE_SE_FLOOR);
            if (o->no_noise) { /* --noise none: no SE is a noise estimate */
                row.m.noise = NAN;
                row.m.points_se = 0;
            }
            row.left_out = left_out;
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
