#include "h5out.h"

#include "closure.h"

#include "bc.h"
#include "ekm_version.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "atomic.h"
#include "fields.h"
#include "local_slab.h"
#include "h5.h"
#include "schema.h"
#include "xdmf.h"

enum { F_PHI, F_VX, F_VZ, F_T, F_P, F_SXZ, F_SZZ, F_REGIME, N_FIELDS };

/* Dataset names; their units come from the field schema (schema.h). */
static const char *const FIELD_NAMES[N_FIELDS] = {"phi", "vx", "vz", "T", "P", "sxz", "szz", "regime"};

struct ekm_h5_writer {
    char path[1024];
    const ekm_scenario *sc;
    ekm_h5_file *file;
    size_t nt, nz;
    double *buf[N_FIELDS - 1];
    int *regime;
    double *times; /* [nt] output times [s], for the XDMF sidecar */
    double *dz;    /* [nt] cell size [m] at each output (the gap / nz with a moving wall) */
    size_t times_cap;
};

static int parse_number(const char *v, double *out)
{
    char *end;
    double x = strtod(v, &end);
    if (end == v || *end != '\0' || !isfinite(x))
        return 0;
    *out = x;
    return 1;
}

ekm_status ekm_h5out_scenario_attrs(ekm_h5_file *file, const ekm_scenario *sc, ekm_error *err)
{
    ekm_status rc = EKM_OK;
    for (size_t i = 0; i < sc->n_entries && rc == EKM_OK; i++) {
        double x;
        if (parse_number(sc->entries[i].value, &x))
            rc = ekm_h5_attr_set_double(file, NULL, sc->entries[i].name, x, err);
        else
            rc = ekm_h5_attr_set_string(file, NULL, sc->entries[i].name, sc->entries[i].value, err);
    }
    char created[32];
    time_t now = time(NULL);
    strftime(created, sizeof created, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_double(file, NULL, "gravity_x", ekm_scenario_gravity_x(sc), err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_double(file, NULL, "gravity_z", ekm_scenario_gravity_z(sc), err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_string(file, NULL, "variant",
                                    sc->variant == EKM_VARIANT_THESIS ? "thesis" : "full", err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_string(file, NULL, "closure", sc->closure->name, err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_double(file, NULL, "has_temperature", sc->closure->has_temperature ? 1.0 : 0.0,
                                    err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_string(file, NULL, "code_version", EKMBENCH_VERSION, err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_string(file, NULL, "scenario_file", sc->source, err);
    if (rc == EKM_OK && sc->material_source[0])
        rc = ekm_h5_attr_set_string(file, NULL, "material_file", sc->material_source, err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_string(file, NULL, "scenario", sc->name, err);
    if (rc == EKM_OK)
        rc = ekm_h5_attr_set_string(file, NULL, "created", created, err);
    return rc;
}

static void free_writer(ekm_h5_writer *w)
{
    for (int f = 0; f < N_FIELDS - 1; f++)
        free(w->buf[f]);
    free(w->regime);
    free(w->times);
    free(w->dz);
    free(w);
}

void ekm_h5_writer_abort(ekm_h5_writer *w)
{
    if (!w)
        return;
    ekm_h5_abort(w->file);
    free_writer(w);
}

/* The extendible /t, /z (the cells' centres of every frame: a
 * pressure-held wall moves them) and fields, and the root attributes. */
static ekm_status write_layout(ekm_h5_writer *w, ekm_error *err)
{
    const size_t dz[1] = {w->nz};
    ekm_status st =
        ekm_h5_create_series(w->file, "t", EKM_H5_DOUBLE, 1, NULL, 64, ekm_field_units("t"), NULL, err);
    if (st == EKM_OK)
        st = ekm_h5_create_series(w->file, "z", EKM_H5_DOUBLE, 2, dz, 1, ekm_field_units("z"), NULL, err);
    for (int f = 0; f < N_FIELDS && st == EKM_OK; f++)
        st = ekm_h5_create_series(w->file, FIELD_NAMES[f], f == F_REGIME ? EKM_H5_INT : EKM_H5_DOUBLE, 2, dz,
                                  1, ekm_field_units(FIELD_NAMES[f]), NULL, err);
    if (st == EKM_OK && ekm_boundary_pressure_wall(&w->sc->top))
        st = ekm_h5_create_series(w->file, "gap", EKM_H5_DOUBLE, 1, NULL, 64, ekm_field_units("gap"), NULL,
                                  err);
    if (st == EKM_OK)
        st = ekm_h5out_scenario_attrs(w->file, w->sc, err);
    return st;
}

/* Bytes of HDF5 per frame and field beyond the data: the row's virtual
 * dataset for the XDMF sidecar (about 700 measured), rounded up. */
#define ROW_VIEW_BYTES 1024.0

/* EKM_EINPUT when the output of the whole run would not fit in
 * EKM_H5OUT_MAX_BYTES: the frames at every output_dt up to t_end, each
 * with every field's row and its view, and the row of /z. */
static ekm_status check_output_size(const ekm_scenario *sc, size_t nz, ekm_error *err)
{
    const double frames = floor(sc->t_end / sc->output_dt) + 2.0;
    const double bytes = frames * ((N_FIELDS + 1) * 8.0 * (double)nz + N_FIELDS * ROW_VIEW_BYTES);
    if (bytes <= EKM_H5OUT_MAX_BYTES)
        return EKM_OK;
    return EKM_FAIL(err, EKM_EINPUT,
                    "%s: [run] output_dt: the output would hold about %.3g GB (%.0f frames x %zu cells x %d "
                    "fields and /z), more than the %.3g GB an output may (it is built in memory): expected a "
                    "larger output_dt or fewer [domain] cells",
                    sc->source, bytes / 1e9, frames, nz, N_FIELDS, EKM_H5OUT_MAX_BYTES / 1e9);
}

ekm_status ekm_h5_writer_open(ekm_h5_writer **out, const char *path, const ekm_scenario *sc,
                              const ekm_state *s, ekm_error *err)
{
    *out = NULL;
    ekm_status size_ok = check_output_size(sc, (size_t)s->n, err);
    if (size_ok != EKM_OK)
        return size_ok;
    ekm_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s", path);
    if (strlen(path) >= sizeof w->path) {
        free_writer(w);
        return EKM_FAIL(err, EKM_EINPUT, "%s: output path too long", path);
    }
    snprintf(w->path, sizeof w->path, "%s", path);
    w->sc = sc;
    w->nz = (size_t)s->n;
    for (int f = 0; f < N_FIELDS - 1; f++)
        if (!(w->buf[f] = malloc(w->nz * sizeof(double)))) {
            free_writer(w);
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s", path);
        }
    if (!(w->regime = malloc(w->nz * sizeof(int)))) {
        free_writer(w);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s", path);
    }
    ekm_status st = ekm_h5_create(&w->file, path, err);
    if (st != EKM_OK) {
        free_writer(w);
        return st;
    }
    st = write_layout(w, err);
    if (st != EKM_OK) {
        ekm_h5_writer_abort(w);
        return st;
    }
    *out = w;
    return EKM_OK;
}

ekm_status ekm_h5_writer_append(ekm_h5_writer *w, const ekm_state *s, ekm_error *err)
{
    ekm_fields fl = {.vx = w->buf[F_VX],
                     .vz = w->buf[F_VZ],
                     .P = w->buf[F_P],
                     .sxz = w->buf[F_SXZ],
                     .szz = w->buf[F_SZZ],
                     .regime = w->regime};
    ekm_slab_fields(w->sc, s, s->t, &fl);
    memcpy(w->buf[F_PHI], s->phi, w->nz * sizeof(double));
    memcpy(w->buf[F_T], s->T, w->nz * sizeof(double));
    for (int f = 0; f < N_FIELDS - 1; f++)
        for (size_t j = 0; j < w->nz; j++)
            if (!isfinite(w->buf[f][j]) &&
                !(f == F_T && !w->sc->closure->has_temperature && isnan(w->buf[f][j])))
                return EKM_FAIL(err, EKM_ENUMERIC,
                                "t = %g s, cell %llu (z = %g m): field %s is not finite (%g); "
                                "nothing written",
                                s->t, (unsigned long long)j, s->z[j], FIELD_NAMES[f], w->buf[f][j]);
    if (w->nt == w->times_cap) {
        size_t cap = w->times_cap ? 2 * w->times_cap : 64;
        double *t = realloc(w->times, cap * sizeof *t);
        if (t)
            w->times = t;
        double *dz = t ? realloc(w->dz, cap * sizeof *dz) : NULL;
        if (!dz)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory writing %s", w->path);
        w->dz = dz;
        w->times_cap = cap;
    }
    w->times[w->nt] = s->t;
    w->dz[w->nt] = s->dz;
    ekm_status st = ekm_h5_append(w->file, "t", &s->t, err);
    if (st == EKM_OK)
        st = ekm_h5_append(w->file, "z", s->z, err);
    for (int f = 0; f < N_FIELDS && st == EKM_OK; f++)
        st = ekm_h5_append(w->file, FIELD_NAMES[f],
                           f == F_REGIME ? (const void *)w->regime : (const void *)w->buf[f], err);
    const double gap = s->n * s->dz; /* [m] */
    if (st == EKM_OK && ekm_boundary_pressure_wall(&w->sc->top))
        st = ekm_h5_append(w->file, "gap", &gap, err);
    if (st != EKM_OK)
        return st;
    w->nt++;
    return EKM_OK;
}

ekm_status ekm_h5_writer_set_attr(ekm_h5_writer *w, const char *name, double value, ekm_error *err)
{
    return ekm_h5_attr_set_double(w->file, NULL, name, value, err);
}

ekm_status ekm_h5_writer_set_attr_array(ekm_h5_writer *w, const char *name, const double *values, size_t n,
                                        ekm_error *err)
{
    return ekm_h5_attr_set_double_array(w->file, NULL, name, values, n, err);
}

/* The HDF5 file with its row views and the sidecar are completed on disk,
 * then renamed into place (common/xdmf.h): a failure leaves neither. */
ekm_status ekm_h5_writer_commit(ekm_h5_writer *w, ekm_error *err)
{
    ekm_xdmf_field fields[N_FIELDS];
    for (int f = 0; f < N_FIELDS; f++)
        fields[f] = (ekm_xdmf_field){.name = FIELD_NAMES[f], .is_int = f == F_REGIME};
    double *lo = calloc(w->nt ? w->nt : 1, sizeof *lo); /* the column starts at z = 0 */
    if (!lo) {
        ekm_h5_writer_abort(w);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory writing %s", w->path);
    }
    const ekm_xdmf_series series = {.title = w->sc->name,
                                    .h5_path = w->path,
                                    .n = w->nz,
                                    .nt = w->nt,
                                    .t = w->times,
                                    .lo = lo,
                                    .dz = w->dz,
                                    .fields = fields,
                                    .nfields = N_FIELDS};
    ekm_status rc = ekm_xdmf_commit_with(w->file, &series, err);
    w->file = NULL;
    free(lo);
    free_writer(w);
    return rc;
}
