/* checkpoint2d.c: the restart file of a 2D run (checkpoint2d.h). */
#include "checkpoint2d.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "h5.h"
#include "ekm_version.h"

#define CHECKPOINT_FORMAT "ekm2d checkpoint 1"
/* The longest scenario_keys attribute [bytes] (HDF5 keeps attributes
 * under 64 kB in the object header). */
#define KEYS_MAX 60000

/* The scenario's keys but run.t_end, "section.key = value" a line, into a
 * malloc'ed string (NULL: out of memory or too long). */
static char *scenario_keys(const ekm_scenario *sc)
{
    char *s = malloc(KEYS_MAX);
    if (!s)
        return NULL;
    size_t n = 0;
    s[0] = '\0';
    for (size_t i = 0; i < sc->n_entries; i++) {
        if (strcmp(sc->entries[i].name, "run.t_end") == 0)
            continue;
        const int w = snprintf(s + n, KEYS_MAX - n, "%s = %s\n", sc->entries[i].name, sc->entries[i].value);
        if (w < 0 || (size_t)w >= KEYS_MAX - n) {
            free(s);
            return NULL;
        }
        n += (size_t)w;
    }
    return s;
}

/* EKM_EINPUT naming the first key of the checkpoint's list `have` that sc
 * does not hold with the same value, or the first of sc's it lacks. */
static ekm_status keys_differ(const char *path, const char *have, const char *want, ekm_error *err)
{
    const char *a = have, *b = want;
    while (*a && *b) {
        const char *ea = strchr(a, '\n'), *eb = strchr(b, '\n');
        const size_t la = ea ? (size_t)(ea - a) : strlen(a), lb = eb ? (size_t)(eb - b) : strlen(b);
        if (la != lb || memcmp(a, b, la) != 0)
            return EKM_FAIL(
                err, EKM_EINPUT,
                "%s: a checkpoint of another scenario: it has '%.*s' where this run has '%.*s' (every "
                "key but run.t_end must be the same; remove the checkpoint to start anew)",
                path, (int)la, a, (int)lb, b);
        a += la + (ea != NULL);
        b += lb + (eb != NULL);
    }
    const char *extra = *a ? a : b;
    const size_t l = strcspn(extra, "\n");
    return EKM_FAIL(
        err, EKM_EINPUT,
        "%s: a checkpoint of another scenario: '%.*s' is only in %s (every key but run.t_end must "
        "be the same; remove the checkpoint to start anew)",
        path, (int)l, extra, *a ? "the checkpoint" : "this run");
}

void ekm2d_checkpoint_free(ekm2d_checkpoint *c)
{
    if (!c)
        return;
    ekm2d_restart_free(&c->state);
    free(c->frame_t);
    free(c->frame_dz);
    free(c->frames);
    c->frame_t = c->frame_dz = c->frames = NULL;
    c->n_frames = 0;
}

/* The scalars, as root attributes (the counts as doubles: exact below 2^53). */
typedef struct {
    const char *name;
    double *value;
    int count; /* 1: a count (a whole number >= 0) */
} scalar_ref;

enum { N_SCALARS = 14 };

static void scalars(ekm2d_checkpoint *c, double counts[6], scalar_ref out[N_SCALARS])
{
    ekm2d_restart *r = &c->state;
    const scalar_ref list[N_SCALARS] = {
        {"t", &r->t, 0},
        {"dz", &r->dz, 0},
        {"dt_prev", &r->dt_prev, 0},
        {"dt_solid", &r->dt_solid, 0},
        {"dt_change", &r->dt_change, 0},
        {"mass_in", &r->mass_in, 0},
        {"solid_lag_max", &r->solid_lag_max, 0},
        {"wall_time_s", &c->wall_s, 0},
        {"steps", &counts[0], 1},
        {"rejected", &counts[1], 1},
        {"newton_total", &counts[2], 1},
        {"to_solid", &counts[3], 1},
        {"to_flow", &counts[4], 1},
        {"solid_floor_steps", &counts[5], 1},
    };
    memcpy(out, list, sizeof list);
}

ekm_status ekm2d_checkpoint_write(const char *path, const ekm_scenario *sc, const ekm2d_checkpoint *c,
                                  ekm_error *err)
{
    char *keys = scenario_keys(sc);
    if (!keys)
        return EKM_FAIL(err, EKM_EINPUT, "%s: the scenario's keys do not fit in a checkpoint (%d bytes)",
                        path, KEYS_MAX);
    ekm2d_checkpoint w = *c; /* the scalars are read through pointers */
    const ekm2d_restart *r = &c->state;
    double counts[6] = {(double)r->steps,    (double)r->rejected, (double)r->newton_total,
                        (double)r->to_solid, (double)r->to_flow,  (double)r->solid_floor_steps};
    scalar_ref list[N_SCALARS];
    scalars(&w, counts, list);
    ekm_h5_file *f = NULL;
    ekm_status st = ekm_h5_create(&f, path, err);
    if (st == EKM_OK)
        st = ekm_h5_attr_set_string(f, NULL, "format", CHECKPOINT_FORMAT, err);
    if (st == EKM_OK)
        st = ekm_h5_attr_set_string(f, NULL, "code_version", EKMBENCH_VERSION, err);
    if (st == EKM_OK)
        st = ekm_h5_attr_set_string(f, NULL, "scenario_keys", keys, err);
    for (size_t i = 0; i < N_SCALARS && st == EKM_OK; i++)
        st = ekm_h5_attr_set_double(f, NULL, list[i].name, *list[i].value, err);
    const size_t ncell = (size_t)r->nx * (size_t)r->nz;
    const size_t d_state[3] = {(size_t)r->nz + 1, (size_t)r->nx + 1, (size_t)r->dof + 1};
    const size_t d_t[1] = {c->n_frames};
    const size_t d_frames[3] = {c->n_frames, EKM2D_NFIELDS, ncell};
    if (st == EKM_OK)
        st = ekm_h5_write_double(f, "state", 3, d_state, r->values, NULL,
                                 "the stepper's state per element (continuum/twod/step2d.h)", err);
    if (st == EKM_OK)
        st = ekm_h5_write_double(f, "frame_t", 1, d_t, c->frame_t, "s", NULL, err);
    if (st == EKM_OK)
        st = ekm_h5_write_double(f, "frame_dz", 1, d_t, c->frame_dz, "m", NULL, err);
    if (st == EKM_OK)
        st = ekm_h5_write_double(f, "frames", 3, d_frames, c->frames, NULL,
                                 "the output frames so far, out2d.h's fields in SI", err);
    free(keys);
    if (st == EKM_OK)
        return ekm_h5_commit(f, err);
    ekm_h5_abort(f);
    return st;
}

/* Every value of data[n] finite: else EKM_EINPUT naming the dataset. */
static ekm_status all_finite(const char *path, const char *name, const double *data, size_t n, ekm_error *err)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(data[k]))
            return EKM_FAIL(err, EKM_EINPUT, "%s: /%s holds a value that is not finite (entry %zu)", path,
                            name, k);
    return EKM_OK;
}

static ekm_status read_all(ekm_h5_file *f, const char *path, const ekm_scenario *sc, ekm2d_checkpoint *c,
                           char *keys, ekm_error *err)
{
    char format[64];
    ekm_status st = ekm_h5_attr_get_string(f, NULL, "format", format, sizeof format, err);
    if (st == EKM_OK && strcmp(format, CHECKPOINT_FORMAT) != 0)
        st = EKM_FAIL(err, EKM_EINPUT, "%s: format '%s', expected '%s'", path, format, CHECKPOINT_FORMAT);
    if (st == EKM_OK)
        st = ekm_h5_attr_get_string(f, NULL, "code_version", c->code_version, sizeof c->code_version, err);
    if (st == EKM_OK)
        st = ekm_h5_attr_get_string(f, NULL, "scenario_keys", keys, KEYS_MAX, err);
    char *want = st == EKM_OK ? scenario_keys(sc) : NULL;
    if (st == EKM_OK && !want)
        st = EKM_FAIL(err, EKM_EINPUT, "%s: the scenario's keys do not fit in a checkpoint (%d bytes)", path,
                      KEYS_MAX);
    if (st == EKM_OK && strcmp(keys, want) != 0)
        st = keys_differ(path, keys, want, err);
    free(want);
    double counts[6] = {0};
    scalar_ref list[N_SCALARS];
    scalars(c, counts, list);
    for (size_t i = 0; i < N_SCALARS && st == EKM_OK; i++) {
        st = ekm_h5_attr_get_double(f, NULL, list[i].name, list[i].value, err);
        /* dt_solid is INFINITY when no solid cell limits the step */
        if (st == EKM_OK && !isfinite(*list[i].value) && strcmp(list[i].name, "dt_solid") != 0)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute %s is not finite", path, list[i].name);
        if (st == EKM_OK && list[i].count &&
            (*list[i].value < 0.0 || *list[i].value != floor(*list[i].value)))
            st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute %s = %g, expected a count", path, list[i].name,
                          *list[i].value);
    }
    ekm2d_restart *r = &c->state;
    r->steps = (long)counts[0];
    r->rejected = (long)counts[1];
    r->newton_total = (long)counts[2];
    r->to_solid = (long)counts[3];
    r->to_flow = (long)counts[4];
    r->solid_floor_steps = (long)counts[5];
    if (st == EKM_OK && !(r->t >= 0.0 && r->t <= sc->t_end * (1.0 + 1e-12)))
        st = EKM_FAIL(err, EKM_EINPUT,
                      "%s: the checkpoint is at t = %.9g s, beyond this run's [run] t_end = %g s (expected a "
                      "t_end at or after it)",
                      path, r->t, sc->t_end);
    if (st == EKM_OK && !(r->dz > 0.0))
        st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute dz = %g, expected > 0 m", path, r->dz);
    int rank = 0;
    size_t dims[EKM_H5_MAX_RANK];
    if (st == EKM_OK)
        st = ekm_h5_read_double(f, "state", &rank, dims, &r->values, err);
    if (st == EKM_OK &&
        (rank != 3 || dims[0] != (size_t)sc->cells + 1 || dims[1] != (size_t)sc->cells_x + 1 || dims[2] < 2))
        st = EKM_FAIL(err, EKM_EINPUT, "%s: /state is not of this run's %d x %d cells", path, sc->cells_x,
                      sc->cells);
    if (st == EKM_OK) {
        r->nx = sc->cells_x;
        r->nz = sc->cells;
        r->dof = (int)dims[2] - 1;
        st = all_finite(path, "state", r->values, dims[0] * dims[1] * dims[2], err);
    }
    const size_t ncell = (size_t)sc->cells * (size_t)sc->cells_x;
    size_t d_t[EKM_H5_MAX_RANK], d_dz[EKM_H5_MAX_RANK];
    int rank_t = 0, rank_dz = 0;
    if (st == EKM_OK)
        st = ekm_h5_read_double(f, "frame_t", &rank_t, d_t, &c->frame_t, err);
    if (st == EKM_OK)
        st = ekm_h5_read_double(f, "frame_dz", &rank_dz, d_dz, &c->frame_dz, err);
    if (st == EKM_OK)
        st = ekm_h5_read_double(f, "frames", &rank, dims, &c->frames, err);
    if (st == EKM_OK && (rank_t != 1 || rank_dz != 1 || rank != 3 || d_dz[0] != d_t[0] || dims[0] != d_t[0] ||
                         dims[1] != EKM2D_NFIELDS || dims[2] != ncell || d_t[0] == 0))
        st = EKM_FAIL(
            err, EKM_EINPUT,
            "%s: /frame_t, /frame_dz and /frames do not hold the same frames of %d fields on %zu cells", path,
            EKM2D_NFIELDS, ncell);
    if (st == EKM_OK) {
        c->n_frames = d_t[0];
        st = all_finite(path, "frames", c->frames, c->n_frames * EKM2D_NFIELDS * ncell, err);
    }
    for (size_t k = 0; k < c->n_frames && st == EKM_OK; k++)
        if (!(c->frame_dz[k] > 0.0) || !(c->frame_t[k] <= r->t) ||
            (k > 0 && !(c->frame_t[k] > c->frame_t[k - 1])))
            st = EKM_FAIL(
                err, EKM_EINPUT,
                "%s: frame %zu at t = %g s (dz %g m): expected increasing times up to the checkpoint's "
                "%g s and dz > 0",
                path, k, c->frame_t[k], c->frame_dz[k], r->t);
    return st;
}

ekm_status ekm2d_checkpoint_read(const char *path, const ekm_scenario *sc, ekm2d_checkpoint *c,
                                 ekm_error *err)
{
    memset(c, 0, sizeof *c);
    char *keys = malloc(KEYS_MAX);
    if (!keys)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (checkpoint %s)", path);
    ekm_h5_file *f = NULL;
    ekm_status st = ekm_h5_open(&f, path, err);
    if (st == EKM_OK)
        st = read_all(f, path, sc, c, keys, err);
    ekm_h5_close(f);
    free(keys);
    if (st != EKM_OK)
        ekm2d_checkpoint_free(c);
    return st;
}
