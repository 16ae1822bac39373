/* score.c: the EKM against coarse-grained DEM (see score.h). */
#include "score.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "h5.h"
#include "h5kind.h"
#include "metric.h"
#include "scalars.h"
#include "schema.h"
#include "utf8.h"

#define MAXF 16
static const char *const default_fields[] = {"phi", "vx", "vz", "T", "P", "sxz", "szz"};

cg_score_opts cg_score_opts_default(void)
{
    cg_score_opts o;
    memset(&o, 0, sizeof o);
    o.support = CG_SCORE_SUPPORT;
    return o;
}

int cg_score_locate(const double *x, size_t n, double v, size_t *i, double *a)
{
    if (n == 0 || !(v >= x[0] - 1e-12 * fabs(x[0])) || !(v <= x[n - 1] + 1e-12 * fabs(x[n - 1])))
        return 0;
    if (n == 1) {
        *i = 0;
        *a = 0.0;
        return 1;
    }
    size_t lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (x[mid] <= v)
            lo = mid;
        else
            hi = mid;
    }
    *i = lo;
    double dx = x[lo + 1] - x[lo];
    *a = dx > 0 ? (v - x[lo]) / dx : 0.0;
    if (*a < 0)
        *a = 0;
    if (*a > 1)
        *a = 1;
    return 1;
}

double cg_score_interp(const double *r0, const double *r1, size_t nze, size_t zi, double az, double at)
{
    size_t z1 = zi + 1 < nze ? zi + 1 : zi;
    double e0 = r0[zi] + az * (r0[z1] - r0[zi]);
    double e1 = r1[zi] + az * (r1[z1] - r1[zi]);
    return e0 + at * (e1 - e0);
}

void cg_score_centres(const double *zm, int per_frame, size_t n, const double *gap, size_t i0, size_t i1,
                      double at, double *z)
{
    if (per_frame) {
        const double *r0 = zm + i0 * n, *r1 = zm + i1 * n;
        for (size_t k = 0; k < n; k++)
            z[k] = r0[k] + at * (r1[k] - r0[k]);
        return;
    }
    const double stretch = gap ? (gap[i0] + at * (gap[i1] - gap[i0])) / gap[0] : 1.0;
    for (size_t k = 0; k < n; k++)
        z[k] = zm[k] * stretch;
}

/* 1 when v printed to 9 significant digits reads back as v */
static int reads_back_9(double v)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%.9g", v);
    return strtod(buf, NULL) == v;
}

static int increasing(const double *x, size_t n)
{
    for (size_t i = 1; i < n; i++)
        if (!(x[i] > x[i - 1]))
            return 0;
    return 1;
}

static ekm_status parse_scalars(const char *list, int *kinds, size_t *nk, ekm_error *err);

/* a value in grain diameters (NaN without a diameter) */
static double in_d(double v, double d)
{
    return (isfinite(d) && d > 0) ? v / d : NAN;
}

/* SCORE.json (score_json.h), with the scalars asked for, sets expanded */
static ekm_status write_json(const cg_score_opts *o, const cg_score_field *res, size_t nres, const char *mode,
                             const cg_score_summary *sm, ekm_error *err)
{
    int kinds[CG_SCALAR_COUNT * 4];
    size_t nk = 0;
    ekm_status rc = parse_scalars(o->scalars, kinds, &nk, err);
    return rc ? rc : cg_score_json_write(o, res, nres, mode, kinds, nk, sm, err);
}

/* A dataset of 1 ([n], *nt = 0) or 2 ([nt][n]) dimensions as doubles. */
static ekm_status read_array(ekm_h5_file *f, const char *name, double **data, size_t *nt, size_t *n,
                             ekm_error *err)
{
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    ekm_status rc = ekm_h5_read_double(f, name, &rank, dims, data, err);
    if (rc)
        return rc;
    if (rank > 2) {
        free(*data);
        *data = NULL;
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected 1 or 2 dimensions", ekm_h5_path(f), name);
    }
    *nt = rank == 2 ? dims[0] : 0;
    *n = rank == 2 ? dims[1] : dims[0];
    return EKM_OK;
}

typedef struct {
    double *zd, *td, *ze, *te; /* DEM and EKM coordinates and times */
    size_t nzd, ntd, nze, nte;
    int ze_frames; /* 1: ze is [nte][nze], each frame's centres; 0: [nze] (cg_score_centres) */
} axes;

static ekm_status read_axes(ekm_h5_file *dem, ekm_h5_file *ekm, const cg_score_opts *o, axes *ax,
                            ekm_error *err)
{
    char axis[8] = "z";
    size_t nt;
    ekm_status rc = EKM_OK;
    if (ekm_h5_attr_exists(dem, NULL, "axis")) {
        if ((rc = ekm_h5_attr_get_string(dem, NULL, "axis", axis, sizeof axis, err)))
            return rc;
    } else {
        if (!ekm_h5_exists(dem, "z") && ekm_h5_exists(dem, "x"))
            strcpy(axis, "x");
        else if (!ekm_h5_exists(dem, "z") && ekm_h5_exists(dem, "y"))
            strcpy(axis, "y");
    }
    rc = read_array(dem, axis, &ax->zd, &nt, &ax->nzd, err);
    if (!rc && nt)
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected 1 dimension", o->dem, axis);
    if (!rc)
        rc = read_array(dem, "t", &ax->td, &nt, &ax->ntd, err);
    if (!rc && nt)
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset t: expected 1 dimension", o->dem);
    size_t nzt = 0;
    if (!rc)
        rc = read_array(ekm, "z", &ax->ze, &nzt, &ax->nze, err);
    if (!rc)
        rc = read_array(ekm, "t", &ax->te, &nt, &ax->nte, err);
    if (!rc && nt)
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset t: expected 1 dimension", o->ekm);
    /* /z: a row per frame [nt][nz] (an ekm output), or one row [nz] for
     * every frame (a cg output; an ekm output from before) */
    if (!rc && nzt && nzt != ax->nte)
        rc = EKM_FAIL(
            err, EKM_EINPUT,
            "%s: dataset z: expected one row of %zu cell centres per output time (%zu), got %zu rows", o->ekm,
            ax->nze, ax->nte, nzt);
    if (rc)
        return rc;
    ax->ze_frames = nzt > 0;
    if (ax->nze == 0 || ax->nte == 0)
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected non-empty /z and /t", o->ekm);
    if (ax->nzd == 0 || ax->ntd == 0)
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected non-empty /%s and /t", o->dem, axis);
    for (size_t i = 0; i < (ax->ze_frames ? ax->nte : 1); i++)
        if (!increasing(ax->ze + i * ax->nze, ax->nze))
            return EKM_FAIL(err, EKM_EINPUT, "%s: dataset z: expected increasing values (row %zu)", o->ekm,
                            i);
    if (!increasing(ax->te, ax->nte))
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset t: expected increasing values", o->ekm);
    for (size_t i = 0; i < ax->nzd; i++)
        ax->zd[i] += o->shift;
    return EKM_OK;
}

/* The fields the scalars and the support use, of one side ([nt][n] each,
 * NULL when absent). */
enum { S_PHI, S_VX, S_SXZ, S_SZZ, S_P, S_T, S_RHO, S_N };
static const char *const side_names[S_N] = {"phi", "vx", "sxz", "szz", "P", "T", "rho"};

typedef struct {
    double *f[S_N], *se[S_N];
    double *gap;  /* [nt] wall-to-wall gap of a pressure-held wall [m], NULL: none */
    double rho_p; /* [kg/m^3] the file's material.rho_p, NaN: none */
} side;

static void side_free(side *s)
{
    for (int i = 0; i < S_N; i++) {
        free(s->f[i]);
        free(s->se[i]);
    }
    free(s->gap);
}

/* A root attribute of the first of the two files that has it (NaN if
 * neither). */
static ekm_status attr_either(ekm_h5_file *a, ekm_h5_file *b, const char *name, double *v, ekm_error *err)
{
    *v = NAN;
    ekm_h5_file *f = ekm_h5_attr_exists(a, NULL, name) ? a : ekm_h5_attr_exists(b, NULL, name) ? b : NULL;
    return f ? ekm_h5_attr_get_double(f, NULL, name, v, err) : EKM_OK;
}

/* Whether the model file is an EKM run made to stop when steady and, if so,
 * whether it got there (its root attributes, docs/output-format.md): a run
 * that ended at t_end without reaching it is a transient, which the table
 * marks instead of scoring it as a steady state. */
static ekm_status model_run(ekm_h5_file *f, cg_score_summary *sm, ekm_error *err)
{
    sm->run_until_steady = 0;
    sm->run_steady = -1;
    sm->run_steady_time = sm->run_steady_drift = sm->run_steady_acceleration = NAN;
    if (!ekm_h5_attr_exists(f, NULL, "run.stop"))
        return EKM_OK;
    char stop[32];
    ekm_status rc = ekm_h5_attr_get_string(f, NULL, "run.stop", stop, sizeof stop, err);
    if (rc || strcmp(stop, "steady") != 0)
        return rc;
    double steady = NAN;
    rc = ekm_h5_attr_get_double(f, NULL, "steady", &steady, err);
    if (!rc && steady != 0.0 && steady != 1.0)
        rc = EKM_FAIL(err, EKM_EINPUT,
                      "%s: root attribute steady: expected 0 or 1 (run.stop = steady), got %g",
                      ekm_h5_path(f), steady);
    if (!rc && ekm_h5_attr_exists(f, NULL, "steady_time"))
        rc = ekm_h5_attr_get_double(f, NULL, "steady_time", &sm->run_steady_time, err);
    if (!rc && ekm_h5_attr_exists(f, NULL, "steady_drift"))
        rc = ekm_h5_attr_get_double(f, NULL, "steady_drift", &sm->run_steady_drift, err);
    if (!rc && ekm_h5_attr_exists(f, NULL, "steady_acceleration"))
        rc = ekm_h5_attr_get_double(f, NULL, "steady_acceleration", &sm->run_steady_acceleration, err);
    if (!rc) {
        sm->run_until_steady = 1;
        sm->run_steady = steady == 1.0;
    }
    return rc;
}

/* a dataset that must have shape [nt][n] */
static ekm_status read_shaped(ekm_h5_file *f, const char *name, size_t nt, size_t n, double **data,
                              ekm_error *err)
{
    size_t nt1, n1;
    ekm_status rc = read_array(f, name, data, &nt1, &n1, err);
    if (!rc && (nt1 != nt || n1 != n)) {
        free(*data);
        *data = NULL;
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", ekm_h5_path(f), name, nt,
                      n);
    }
    return rc;
}

/* a dataset of shape [nt][n] if present (else *data = NULL) */
static ekm_status read_optional(ekm_h5_file *f, const char *name, size_t nt, size_t n, double **data,
                                ekm_error *err)
{
    *data = NULL;
    if (!ekm_h5_exists(f, name))
        return EKM_OK;
    return read_shaped(f, name, nt, n, data, err);
}

static ekm_status side_read(ekm_h5_file *f, size_t nt, size_t n, side *s, ekm_error *err)
{
    ekm_status rc = EKM_OK;
    char sename[48];
    for (int i = 0; i < S_N && !rc; i++) {
        snprintf(sename, sizeof sename, "%s_se", side_names[i]);
        rc = read_optional(f, side_names[i], nt, n, &s->f[i], err);
        if (!rc)
            rc = read_optional(f, sename, nt, n, &s->se[i], err);
    }
    /* an EKM run with a pressure-held wall: its gap of every frame (the
     * grid of an output with one /z row for all frames, cg_score_centres) */
    if (!rc && ekm_h5_exists(f, "gap")) {
        size_t nt1, n1;
        rc = read_array(f, "gap", &s->gap, &nt1, &n1, err);
        int positive = !rc && nt1 == 0 && n1 == nt;
        for (size_t i = 0; positive && i < nt; i++)
            positive = s->gap[i] > 0 && isfinite(s->gap[i]);
        if (!rc && !positive)
            rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset gap: expected [%zu] positive values", ekm_h5_path(f),
                          nt);
    }
    s->rho_p = NAN;
    if (!rc && ekm_h5_attr_exists(f, NULL, "material.rho_p"))
        rc = ekm_h5_attr_get_double(f, NULL, "material.rho_p", &s->rho_p, err);
    return rc;
}

/* row i0 + at (row i1 - row i0) of every field of s into buf[2 S_N + 1][n]
 * (the last row: the grid at that time, cg_score_centres of z, per_frame),
 * and the profile p pointing at it; g_normal and top_velocity are the
 * scenario's */
static void side_row(const side *s, const double *z, int per_frame, size_t n, size_t i0, size_t i1, double at,
                     double *buf, double g_normal, double top_velocity, cg_scalar_profile *p)
{
    const double *rows[2 * S_N];
    for (int i = 0; i < S_N; i++) {
        rows[i] = s->f[i];
        rows[S_N + i] = s->se[i];
    }
    for (int i = 0; i < 2 * S_N; i++) {
        double *out = buf + (size_t)i * n;
        if (!rows[i])
            continue;
        const double *r0 = rows[i] + i0 * n, *r1 = rows[i] + i1 * n;
        for (size_t k = 0; k < n; k++)
            out[k] = r0[k] + at * (r1[k] - r0[k]);
    }
#define ROW(i) (rows[i] ? buf + (size_t)(i)*n : NULL)
    p->n = n;
    double *zs = buf + (size_t)(2 * S_N) * n;
    cg_score_centres(z, per_frame, n, s->gap, i0, i1, at, zs);
    p->z = zs;
    p->phi = ROW(S_PHI);
    p->vx = ROW(S_VX);
    p->sxz = ROW(S_SXZ);
    p->szz = ROW(S_SZZ);
    p->P = ROW(S_P);
    p->T = ROW(S_T);
    p->phi_se = ROW(S_N + S_PHI);
    p->vx_se = ROW(S_N + S_VX);
    p->sxz_se = ROW(S_N + S_SXZ);
    p->szz_se = ROW(S_N + S_SZZ);
    p->P_se = ROW(S_N + S_P);
    p->T_se = ROW(S_N + S_T);
    p->rho = ROW(S_RHO);
    p->rho_se = ROW(S_N + S_RHO);
    p->rho_p = s->rho_p;
    p->g_normal = g_normal;
    p->top_velocity = top_velocity;
#undef ROW
}

/* the scalar list (names and set names) as kinds, in order, each once */
static ekm_status parse_scalars(const char *list, int *kinds, size_t *nk, ekm_error *err)
{
    *nk = 0;
    if (!list || !*list)
        return EKM_OK;
    const char *p = list;
    while (*p) {
        const char *q = strchr(p, ',');
        size_t len = q ? (size_t)(q - p) : strlen(p);
        char name[48];
        if (len == 0 || len >= sizeof name)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "--scalars: expected a comma-separated list of scalar or set names, got '%s'",
                            list);
        memcpy(name, p, len);
        name[len] = '\0';
        const char *set = cg_scalar_set(name);
        if (set) {
            size_t nset;
            ekm_status rc = parse_scalars(set, kinds + *nk, &nset, err);
            if (rc)
                return rc;
            *nk += nset;
        } else {
            int k = cg_scalar_lookup(name);
            if (k < 0)
                return EKM_FAIL(err, EKM_EUSAGE,
                                "--scalars: unknown scalar '%s' (expected a set: chute, shear_cell, "
                                "filling, simple_shear, or a scalar name of docs/compare.md)",
                                name);
            kinds[(*nk)++] = k;
        }
        p += len + (q ? 1 : 0);
        if (*nk > CG_SCALAR_COUNT * 4)
            return EKM_FAIL(err, EKM_EUSAGE, "--scalars: list too long: '%s'", list);
    }
    /* each kind once, first occurrence kept */
    size_t m = 0;
    for (size_t i = 0; i < *nk; i++) {
        size_t j = 0;
        while (j < m && kinds[j] != kinds[i])
            j++;
        if (j == m)
            kinds[m++] = kinds[i];
    }
    *nk = m;
    return EKM_OK;
}

/* the free surface and the scalars (the sides' rows at the DEM times) */
static ekm_status summarise(const cg_score_opts *o, const axes *ax, const side *sd, const side *se_,
                            const size_t *ti, const double *ta, const int *tin, double g_normal,
                            double top_velocity, cg_score_summary *sm, ekm_error *err)
{
    int kinds[CG_SCALAR_COUNT * 4];
    size_t nk;
    ekm_status rc = parse_scalars(o->scalars, kinds, &nk, err);
    if (rc)
        return rc;
    size_t jl = ax->ntd;
    for (size_t j = 0; j < ax->ntd; j++)
        if (tin[j])
            jl = j;
    sm->t = NAN;
    sm->dem_height = sm->model_height = NAN;
    sm->nscalars = 0;
    if (jl == ax->ntd)
        return EKM_OK;
    double *bd = malloc((2 * S_N + 1) * ax->nzd * sizeof *bd),
           *be = malloc((2 * S_N + 1) * ax->nze * sizeof *be);
    if (!bd || !be) {
        free(bd);
        free(be);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    sm->t = ax->td[jl];
    for (size_t j = 0; j < ax->ntd && !rc; j++) {
        if (!tin[j])
            continue;
        cg_scalar_profile pd, pe;
        size_t i1 = ti[j] + 1 < ax->nte ? ti[j] + 1 : ti[j];
        side_row(sd, ax->zd, 0, ax->nzd, j, j, 0.0, bd, g_normal, top_velocity, &pd);
        side_row(se_, ax->ze, ax->ze_frames, ax->nze, ti[j], i1, ta[j], be, g_normal, top_velocity, &pe);
        if (j == jl) {
            sm->dem_height = cg_scalar_compute(CG_SCALAR_LAYER_HEIGHT, &pd).value;
            sm->model_height = cg_scalar_compute(CG_SCALAR_LAYER_HEIGHT, &pe).value;
        }
        for (size_t i = 0; i < nk; i++) {
            cg_scalar_kind k = (cg_scalar_kind)kinds[i];
            int per_time = cg_scalar_per_time(k);
            if (!per_time && j != jl)
                continue;
            if (sm->nscalars == CG_SCORE_MAX_SCALARS) {
                rc = EKM_FAIL(err, EKM_EINPUT, "%s: more than %d scalars (a time series with too many times)",
                              o->dem, CG_SCORE_MAX_SCALARS);
                break;
            }
            cg_score_scalar *c = &sm->scalar[sm->nscalars++];
            if (per_time)
                snprintf(c->name, sizeof c->name, "%s@%.6gs", cg_scalar_name(k), ax->td[j]);
            else
                snprintf(c->name, sizeof c->name, "%s", cg_scalar_name(k));
            c->units = cg_scalar_units(k);
            c->t = ax->td[j];
            cg_scalar_value vd = cg_scalar_compute(k, &pd), ve = cg_scalar_compute(k, &pe);
            c->dem = vd.value;
            c->dem_se = vd.se;
            c->model = ve.value;
            c->model_se = ve.se;
        }
    }
    free(bd);
    free(be);
    return rc;
}

/* A --fields name must be a field of the schema (common/schema.h). */
static ekm_status check_field_name(const char *name, ekm_error *err)
{
    if (ekm_field_lookup(name))
        return EKM_OK;
    char known[512] = "";
    size_t used = 0;
    for (size_t i = 0; i < ekm_field_count() && used < sizeof known; i++) {
        const char *n = ekm_field_at(i)->name;
        const size_t len = strlen(n);
        if (len > 3 && !strcmp(n + len - 3, "_se"))
            continue; /* standard errors come with their field */
        used += (size_t)snprintf(known + used, sizeof known - used, "%s%s", used ? " " : "", n);
    }
    return EKM_FAIL(err, EKM_EINPUT, "--fields: unknown field '%s' (the fields are: %s)", name, known);
}

/* Dataset name of file f must carry the schema's units attribute. */
static ekm_status check_units(ekm_h5_file *f, const char *path, const char *name, ekm_error *err)
{
    const char *want = ekm_field_units(name);
    if (!want)
        return EKM_OK;
    char got[64];
    ekm_status rc = ekm_h5_attr_get_string(f, name, "units", got, sizeof got, err);
    if (rc)
        return rc;
    if (strcmp(got, want))
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: units '%s', expected '%s' (the field schema)", path,
                        name, got, want);
    return EKM_OK;
}

/* A field's numbers must exist: no point in common (the files, or --shift,
 * put the DEM grid or times outside the model's) is a bad input (exit 2);
 * an undefined number over the points compared (the DEM field zero at
 * every point, no standard error above the floor) a failed computation
 * (exit 4). Never a NaN (null) in the JSON. */
static ekm_status check_result(const cg_score_opts *o, const axes *ax, const char *name, const cg_metric *m,
                               size_t left_out, ekm_error *err)
{
    /* the model's cell centres over all its frames (each row increasing) */
    double ze_lo = ax->ze[0], ze_hi = ax->ze[ax->nze - 1];
    for (size_t i = 1; ax->ze_frames && i < ax->nte; i++) {
        ze_lo = fmin(ze_lo, ax->ze[i * ax->nze]);
        ze_hi = fmax(ze_hi, ax->ze[i * ax->nze + ax->nze - 1]);
    }
    if (m->points == 0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "score: --dem %s --ekm %s: field %s: no point in common (DEM coordinate %.6g..%.6g m "
                        "with --shift %.6g m and times %.6g..%.6g s; model cell centres %.6g..%.6g m and "
                        "times %.6g..%.6g s; %zu points off the common support)",
                        o->dem, o->ekm, name, ax->zd[0], ax->zd[ax->nzd - 1], o->shift, ax->td[0],
                        ax->td[ax->ntd - 1], ze_lo, ze_hi, ax->te[0], ax->te[ax->nte - 1], left_out);
    if (!isfinite(m->rel_l2))
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "score: --dem %s: field %s: rel_l2 undefined: the DEM field is zero at all %zu "
                        "points compared",
                        o->dem, name, m->points);
    if (!isfinite(m->noise))
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "score: --dem %s: field %s: noise_normalised undefined: none of the %zu points "
                        "compared has a standard error above %g x the field's RMS (%s_se; a window of "
                        "fewer than two snapshots?)",
                        o->dem, name, m->points, CG_SCORE_SE_FLOOR, name);
    return EKM_OK;
}

/* --fields: the names of a comma-separated list into names[] (each a known field). */
static ekm_status parse_field_list(const char *list, char names[][32], size_t *nf, ekm_error *err)
{
    for (const char *p = list; *p;) {
        const char *q = strchr(p, ',');
        size_t len = q ? (size_t)(q - p) : strlen(p);
        if (len == 0 || len >= 32 || *nf == MAXF)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "--fields: expected a comma-separated list of field names, got '%s'", list);
        memcpy(names[*nf], p, len);
        names[*nf][len] = '\0';
        ekm_status st = check_field_name(names[(*nf)++], err);
        if (st)
            return st;
        p += len + (q ? 1 : 0);
    }
    return EKM_OK;
}

/* The JSON must not replace an input; each file the kind its option
 * names: --dem a cg output, --ekm an ekm run or a second engine's cg
 * output (engine against engine). */
static ekm_status open_inputs(const cg_score_opts *o, ekm_h5_file **dem, ekm_h5_file **ekm, ekm_error *err)
{
    const char *inputs[2] = {o->dem, o->ekm};
    ekm_status rc = o->json ? ekm_atomic_refuse_input(o->json, inputs, 2, err) : EKM_OK;
    if (!rc)
        rc = ekm_h5_open(dem, o->dem, err);
    if (!rc)
        rc = ekm_h5_open(ekm, o->ekm, err);
    if (!rc)
        rc = cg_h5kind_check(*dem, "score", "--dem", CG_H5KIND_CG, err);
    if (!rc)
        rc = cg_h5kind_check(*ekm, "score", "--ekm", CG_H5KIND_EKM | CG_H5KIND_CG, err);
    return rc;
}

/* Where each DEM time falls among the EKM's output times: index ti,
 * fraction ta, inside or not (tin). */
typedef struct {
    size_t *ti;
    double *ta;
    int *tin;
    int last; /* 1: every DEM time takes the EKM's last output */
} time_map;

static void time_map_free(time_map *tm)
{
    free(tm->ti);
    free(tm->ta);
    free(tm->tin);
}

/* --ekm-time last, or no DEM time inside the EKM's: the EKM's last output
 * for every DEM time (a note says so in the second case). */
static ekm_status map_times(const cg_score_opts *o, const axes *ax, time_map *tm, ekm_error *err)
{
    tm->last = o->ekm_last;
    tm->ti = malloc(ax->ntd * sizeof *tm->ti);
    tm->ta = malloc(ax->ntd * sizeof *tm->ta);
    tm->tin = malloc(ax->ntd * sizeof *tm->tin);
    if (!tm->ti || !tm->ta || !tm->tin)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    size_t nin = 0;
    for (size_t j = 0; j < ax->ntd; j++) {
        tm->tin[j] = cg_score_locate(ax->te, ax->nte, ax->td[j], &tm->ti[j], &tm->ta[j]);
        nin += (size_t)tm->tin[j];
    }
    if (!tm->last && nin == 0) {
        tm->last = 1;
        if (o->log)
            fprintf(o->log,
                    "note: no DEM time (%.6g..%.6g s) inside the EKM output times (%.6g..%.6g s): "
                    "comparing with the EKM's last output (t = %.6g s)\n",
                    ax->td[0], ax->td[ax->ntd - 1], ax->te[0], ax->te[ax->nte - 1], ax->te[ax->nte - 1]);
    }
    if (tm->last)
        for (size_t j = 0; j < ax->ntd; j++) {
            tm->tin[j] = 1;
            tm->ti[j] = ax->nte - 1;
            tm->ta[j] = 0.0;
        }
    return EKM_OK;
}

/* The common support's threshold: o->support x the DEM's largest phi (0:
 * none). */
static ekm_status support_threshold(const cg_score_opts *o, const axes *ax, const side *sdem,
                                    const side *smod, double *support_phi, ekm_error *err)
{
    *support_phi = 0.0;
    if (!(o->support > 0))
        return EKM_OK;
    if (!sdem->f[S_PHI] || !smod->f[S_PHI])
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: expected a dataset phi for the common support (--support 0 scores without it)",
                        sdem->f[S_PHI] ? o->ekm : o->dem);
    double m = NAN;
    for (size_t q = 0; q < ax->ntd * ax->nzd; q++)
        if (isfinite(sdem->f[S_PHI][q]) && !(sdem->f[S_PHI][q] <= m))
            m = sdem->f[S_PHI][q];
    if (!isfinite(m) || !(m > 0))
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset phi: expected a positive value", o->dem);
    *support_phi = o->support * m;
    return EKM_OK;
}

/* One field's score: the points both cover (in DEM order: time, then
 * coordinate), the model interpolated onto them, against the DEM value and
 * its standard error (a second engine's own standard error added in
 * quadrature), into *r. */
static ekm_status score_field(const cg_score_opts *o, const axes *ax, ekm_h5_file *dem, ekm_h5_file *ekm,
                              const side *sdem, const side *smod, const time_map *tm, double support_phi,
                              const char *name, cg_score_field *r, ekm_error *err)
{
    double *fd = NULL, *sd = NULL, *fe = NULL, *fse = NULL;
    char sename[48];
    snprintf(sename, sizeof sename, "%s_se", name);
    ekm_status rc = EKM_OK;
    /* T of a model without a granular temperature (an ekm output of a
     * closure with has_temperature = 0: mu_i): not a number to compare */
    double has_T = 1.0;
    if (!strcmp(name, "T") && ekm_h5_attr_exists(ekm, NULL, "has_temperature") &&
        (rc = ekm_h5_attr_get_double(ekm, NULL, "has_temperature", &has_T, err)) != EKM_OK)
        return rc;
    if (has_T == 0.0) {
        *r = (cg_score_field){.rel_l2 = NAN, .noise = NAN, .na = "no temperature"};
        snprintf(r->name, sizeof r->name, "%s", name);
        return EKM_OK;
    }
    if (!ekm_h5_exists(dem, name))
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", o->dem, name);
    else if (!ekm_h5_exists(ekm, name))
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", o->ekm, name);
    if (!rc)
        rc = check_units(dem, o->dem, name, err);
    if (!rc)
        rc = check_units(ekm, o->ekm, name, err);
    if (!rc)
        rc = read_shaped(dem, name, ax->ntd, ax->nzd, &fd, err);
    if (!rc)
        rc = read_optional(dem, sename, ax->ntd, ax->nzd, &sd, err);
    if (!rc)
        rc = read_shaped(ekm, name, ax->nte, ax->nze, &fe, err);
    if (!rc)
        rc = read_optional(ekm, sename, ax->nte, ax->nze, &fse, err);
    double *pm = NULL, *pdem = NULL, *ps = NULL, *zc = NULL;
    const size_t ncand = ax->ntd * ax->nzd;
    if (!rc && (!(pm = malloc(ncand * sizeof *pm)) || !(pdem = malloc(ncand * sizeof *pdem)) ||
                !(ps = malloc(ncand * sizeof *ps)) || !(zc = malloc(ax->nze * sizeof *zc))))
        rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    if (!rc) {
        size_t np = 0, left_out = 0;
        for (size_t j = 0; j < ax->ntd; j++) {
            if (!tm->tin[j])
                continue;
            size_t i0 = tm->ti[j], i1 = i0 + 1 < ax->nte ? i0 + 1 : i0;
            double at = tm->ta[j];
            /* the EKM's cell centres at this DEM time */
            cg_score_centres(ax->ze, ax->ze_frames, ax->nze, smod->gap, i0, i1, at, zc);
            for (size_t k = 0; k < ax->nzd; k++) {
                size_t zi;
                double az;
                if (!cg_score_locate(zc, ax->nze, ax->zd[k], &zi, &az)) {
                    /* outside the model's cell centres: left out when the
                     * DEM has material there (e.g. above a pressure-held
                     * EKM gap shorter than the DEM's) */
                    if (support_phi > 0 && sdem->f[S_PHI][j * ax->nzd + k] > support_phi)
                        left_out++;
                    continue;
                }
                if (support_phi > 0) {
                    /* common support: material on both sides */
                    double mphi = cg_score_interp(smod->f[S_PHI] + i0 * ax->nze,
                                                  smod->f[S_PHI] + i1 * ax->nze, ax->nze, zi, az, at);
                    double dphi = sdem->f[S_PHI][j * ax->nzd + k];
                    if (!(mphi > support_phi && dphi > support_phi)) {
                        left_out++;
                        continue;
                    }
                }
                double e = cg_score_interp(fe + i0 * ax->nze, fe + i1 * ax->nze, ax->nze, zi, az, at),
                       d = fd[j * ax->nzd + k];
                double s = sd ? sd[j * ax->nzd + k] : NAN;
                if (fse) {
                    double s2 = cg_score_interp(fse + i0 * ax->nze, fse + i1 * ax->nze, ax->nze, zi, az, at);
                    s = sqrt(s * s + s2 * s2);
                }
                pm[np] = e;
                pdem[np] = d;
                ps[np] = s;
                np++;
            }
        }
        cg_metric m = cg_metric_compute(pm, pdem, ps, np, CG_SCORE_SE_FLOOR);
        rc = check_result(o, ax, name, &m, left_out, err);
        snprintf(r->name, sizeof r->name, "%s", name);
        r->points = m.points;
        r->points_se = m.points_se;
        r->points_left_out = left_out;
        r->rel_l2 = m.rel_l2;
        r->noise = m.noise;
        r->se_both = fse != NULL;
        r->na = NULL;
    }
    free(fd);
    free(sd);
    free(fe);
    free(fse);
    free(pm);
    free(pdem);
    free(ps);
    free(zc);
    return rc;
}

/* The markdown table of the fields and the scalars. */
static void write_table(FILE *fp, const cg_score_field *res, size_t nres, const cg_score_summary *sm)
{
    fprintf(fp, "| field | points | left out | rel. L2 error | noise-normalised error "
                "|\n|---|---:|---:|---:|---:|\n");
    for (size_t i = 0; i < nres; i++)
        if (res[i].na)
            fprintf(fp, "| %s | n/a (%s) | | | |\n", res[i].name, res[i].na);
        else
            fprintf(fp, "| %s | %zu | %zu | %.4g | %.4g |\n", res[i].name, res[i].points,
                    res[i].points_left_out, res[i].rel_l2, res[i].noise);
    fprintf(fp, "\nlayer height: DEM %.4g m, model %.4g m, offset %.4g m = %.3g d\n", sm->dem_height,
            sm->model_height, sm->model_height - sm->dem_height,
            in_d(sm->model_height - sm->dem_height, sm->mean_diameter));
    if (sm->nscalars) {
        fprintf(fp, "\n| scalar | units | DEM | SE | model | rel. error | error / SE "
                    "|\n|---|---|---:|---:|---:|---:|---:|\n");
        for (size_t i = 0; i < sm->nscalars; i++) {
            const cg_score_scalar *c = &sm->scalar[i];
            fprintf(fp, "| %s | %s | %.4g | %.2g | %.4g | %.3g | %.3g |\n", c->name, c->units, c->dem,
                    c->dem_se, c->model, (c->model - c->dem) / fabs(c->dem), (c->model - c->dem) / c->dem_se);
        }
    }
}

/* What SCORE.json records must be recordable: both checksums or neither,
 * each as sha256sum prints it; the options to 9 digits (score_json.c);
 * UTF-8 input paths. */
static ekm_status check_record(const cg_score_opts *o, ekm_error *err)
{
    if (!o->dem_sha256 != !o->ekm_sha256)
        return EKM_FAIL(err, EKM_EUSAGE, "score: expected both --dem-sha256 and --ekm-sha256, or neither");
    if (o->dem_sha256 && !o->json)
        return EKM_FAIL(err, EKM_EUSAGE,
                        "score: --dem-sha256 and --ekm-sha256 are recorded in the JSON: expected -o");
    const struct {
        const char *option, *value;
    } sums[] = {{"--dem-sha256", o->dem_sha256}, {"--ekm-sha256", o->ekm_sha256}};
    for (size_t i = 0; i < 2; i++)
        if (sums[i].value && !cg_score_is_sha256(sums[i].value))
            return EKM_FAIL(err, EKM_EUSAGE, "%s: expected 64 lower-case hexadecimal digits, got '%s'",
                            sums[i].option, sums[i].value);
    if (!o->json)
        return EKM_OK;
    const struct {
        const char *option;
        double value;
    } nums[] = {{"--shift", o->shift}, {"--support", o->support}};
    for (size_t i = 0; i < 2; i++)
        if (!reads_back_9(nums[i].value))
            return EKM_FAIL(err, EKM_EUSAGE, "%s: expected at most 9 significant digits, got %.17g",
                            nums[i].option, nums[i].value);
    if (!ekm_utf8_valid(o->dem) || !ekm_utf8_valid(o->ekm))
        return EKM_FAIL(err, EKM_EUSAGE, "score: -o %s: the input paths must be UTF-8 to be recorded in JSON",
                        o->json);
    return EKM_OK;
}

ekm_status cg_score(const cg_score_opts *o, cg_score_field *res, size_t *nres, ekm_error *err)
{
    cg_score_field loc[MAXF];
    cg_score_summary sm_loc;
    cg_score_summary *sm = o->summary ? o->summary : &sm_loc;
    memset(sm, 0, sizeof *sm);
    sm->mean_diameter = NAN;
    if (!res)
        res = loc;
    *nres = 0;
    if (!o->dem || !o->ekm)
        return EKM_FAIL(err, EKM_EUSAGE, "score: expected --dem CG.h5 and --ekm RUN.h5");
    if (!(o->support >= 0 && o->support < 1))
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--support: expected a fraction of the DEM's largest phi in [0, 1), got %g",
                        o->support);
    ekm_status rc_rec = check_record(o, err);
    if (rc_rec)
        return rc_rec;
    char names[MAXF][32];
    size_t nf = 0;
    if (o->fields) {
        ekm_status st = parse_field_list(o->fields, names, &nf, err);
        if (st)
            return st;
    }
    ekm_h5_file *dem = NULL, *ekm = NULL;
    ekm_status rc = open_inputs(o, &dem, &ekm, err);
    axes ax;
    memset(&ax, 0, sizeof ax);
    if (!rc)
        rc = read_axes(dem, ekm, o, &ax, err);
    if (!rc && !o->fields)
        for (size_t i = 0; i < sizeof default_fields / sizeof *default_fields; i++)
            if (ekm_h5_exists(dem, default_fields[i]) && ekm_h5_exists(ekm, default_fields[i]))
                strcpy(names[nf++], default_fields[i]);
    if (!rc && nf == 0)
        rc = EKM_FAIL(err, EKM_EINPUT, "%s, %s: no field in common", o->dem, o->ekm);
    time_map tm = {0};
    if (!rc)
        rc = map_times(o, &ax, &tm, err);
    /* the sides' phi (common support, free surface) and the scalars' fields */
    side sdem, smod;
    memset(&sdem, 0, sizeof sdem);
    memset(&smod, 0, sizeof smod);
    if (!rc)
        rc = side_read(dem, ax.ntd, ax.nzd, &sdem, err);
    if (!rc)
        rc = side_read(ekm, ax.nte, ax.nze, &smod, err);
    double support_phi = 0.0;
    if (!rc)
        rc = support_threshold(o, &ax, &sdem, &smod, &support_phi, err);
    sm->support_phi = support_phi;
    if (!rc) {
        const char *which = ekm_h5_attr_exists(dem, NULL, "mean_diameter")   ? o->dem
                            : ekm_h5_attr_exists(ekm, NULL, "mean_diameter") ? o->ekm
                                                                             : NULL;
        if (which)
            rc = ekm_h5_attr_get_double(which == o->dem ? dem : ekm, NULL, "mean_diameter",
                                        &sm->mean_diameter, err);
    }
    /* the scenario's gravity (its z component) and top-wall velocity: the
     * EKM file carries them ([gravity], [top] velocity), a CG file not */
    double g_normal = NAN, top_velocity = NAN;
    if (!rc)
        rc = model_run(ekm, sm, err);
    if (!rc)
        rc = attr_either(dem, ekm, "gravity_z", &g_normal, err);
    if (!rc)
        rc = attr_either(dem, ekm, "top.velocity", &top_velocity, err);
    if (!rc && sdem.f[S_PHI] && smod.f[S_PHI])
        rc = summarise(o, &ax, &sdem, &smod, tm.ti, tm.ta, tm.tin, g_normal, top_velocity, sm, err);
    else if (!rc && o->scalars && *o->scalars)
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset phi for --scalars",
                      sdem.f[S_PHI] ? o->ekm : o->dem);
    for (size_t f = 0; f < nf && !rc; f++) {
        res[*nres].name[0] = '\0'; /* set when the field was scored (also when check_result refuses it) */
        rc = score_field(o, &ax, dem, ekm, &sdem, &smod, &tm, support_phi, names[f], &res[*nres], err);
        if (res[*nres].name[0])
            (*nres)++;
    }
    if (!rc && o->table)
        write_table(o->table, res, *nres, sm);
    if (!rc && o->json)
        rc = write_json(o, res, *nres, tm.last ? "ekm last output" : "interpolated", sm, err);
    side_free(&sdem);
    side_free(&smod);
    time_map_free(&tm);
    free(ax.zd);
    free(ax.td);
    free(ax.ze);
    free(ax.te);
    ekm_h5_close(dem);
    ekm_h5_close(ekm);
    return rc;
}
