/* out2d.c: the output file of a 2D run, HDF5 + XDMF sidecar (out2d.h;
 * layout in docs/output-format.md, "2D runs").  The 1D writer's twin
 * (h5out.c): the same root attributes (ekm_h5out_scenario_attrs), the
 * same in-memory file (common/h5.h) and the same atomic commit with the
 * sidecar, here of the 2D grid (common/xdmf.h with nx > 0). */
#include "out2d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bc.h"
#include "h5.h"
#include "h5out.h"
#include "schema.h"
#include "xdmf.h"

/* Dataset names in ekm2d_field order; their units come from the field
 * schema (schema.h). */
static const char *const FIELD_NAMES[EKM2D_NFIELDS] = {"phi", "vx",  "vz",  "T",     "P",
                                                       "sxx", "szz", "sxz", "regime"};

/* Bytes of HDF5 per frame and field beyond the data: the frame's virtual
 * dataset for the XDMF sidecar (h5out.c measured about 700), rounded up. */
#define FRAME_VIEW_BYTES 1024.0

struct ekm2d_writer {
    char path[EKM_ATOMIC_PATH_MAX];
    const ekm_scenario *sc;
    ekm_h5_file *file;
    size_t nx, nz;     /* cells along x and z */
    double dx, dz;     /* cell sizes [m] */
    size_t nt, max_nt; /* frames written, at most */
    double *times;     /* [max_nt] output times [s], for the XDMF sidecar */
    double *dz_frame;  /* [max_nt] each frame's cell size along z [m] (a moving top wall) */
    double *lo;        /* [max_nt] each frame's lower end along z: 0 [m] */
    int *regime;       /* [nz * nx] the frame's regime as int32 */
};

static void free_writer(ekm2d_writer *w)
{
    free(w->times);
    free(w->dz_frame);
    free(w->lo);
    free(w->regime);
    free(w);
}

void ekm2d_writer_abort(ekm2d_writer *w)
{
    if (!w)
        return;
    ekm_h5_abort(w->file);
    free_writer(w);
}

/* EKM_EINPUT when max_frames frames of every field (and their views)
 * would not fit in EKM_H5OUT_MAX_BYTES. */
static ekm_status check_output_size(const ekm_scenario *sc, size_t cells, size_t max_frames, ekm_error *err)
{
    const double bytes = (double)max_frames * EKM2D_NFIELDS * (8.0 * (double)cells + FRAME_VIEW_BYTES);
    if (bytes <= EKM_H5OUT_MAX_BYTES)
        return EKM_OK;
    return EKM_FAIL(err, EKM_EINPUT,
                    "%s: [run] output_dt: the output would hold about %.3g GB (%zu frames x %zu cells x %d "
                    "fields), more than the %.3g GB an output may (it is built in memory): expected a larger "
                    "output_dt or fewer [domain] cells",
                    sc->source, bytes / 1e9, max_frames, cells, EKM2D_NFIELDS, EKM_H5OUT_MAX_BYTES / 1e9);
}

/* A fixed dataset of cell centres (i + 1/2) h, i < n, with its units. */
static ekm_status write_centres(ekm_h5_file *f, const char *name, size_t n, double h, ekm_error *err)
{
    double *c = malloc((n ? n : 1) * sizeof *c);
    if (!c)
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory writing /%s", ekm_h5_path(f), name);
    for (size_t i = 0; i < n; i++)
        c[i] = ((double)i + 0.5) * h;
    const ekm_status st = ekm_h5_write_double(f, name, 1, &n, c, ekm_field_units(name), NULL, err);
    free(c);
    return st;
}

/* /x, /z, the extendible /t and fields, and the root attributes. */
static ekm_status write_layout(ekm2d_writer *w, int ranks, ekm_error *err)
{
    for (int k = 0; k < EKM2D_NFIELDS; k++)
        if (!ekm_field_units(FIELD_NAMES[k]))
            return EKM_FAIL(err, EKM_EINTERNAL, "%s: no units for %s in the field schema", w->path,
                            FIELD_NAMES[k]);
    const size_t frame_dims[2] = {w->nz, w->nx};
    ekm_status st = write_centres(w->file, "x", w->nx, w->dx, err);
    if (st == EKM_OK)
        st = write_centres(w->file, "z", w->nz, w->dz, err);
    if (st == EKM_OK)
        st = ekm_h5_create_series(w->file, "t", EKM_H5_DOUBLE, 1, NULL, 64, ekm_field_units("t"), NULL, err);
    if (st == EKM_OK && ekm_boundary_pressure_wall(&w->sc->top))
        st = ekm_h5_create_series(w->file, "gap", EKM_H5_DOUBLE, 1, NULL, 64, ekm_field_units("gap"), NULL,
                                  err);
    for (int k = 0; k < EKM2D_NFIELDS && st == EKM_OK; k++)
        st = ekm_h5_create_series(w->file, FIELD_NAMES[k], k == EKM2D_REGIME ? EKM_H5_INT : EKM_H5_DOUBLE, 3,
                                  frame_dims, 1, ekm_field_units(FIELD_NAMES[k]), NULL, err);
    if (st == EKM_OK)
        st = ekm_h5out_scenario_attrs(w->file, w->sc, err);
    if (st == EKM_OK)
        st = ekm_h5_attr_set_int(w->file, NULL, "ranks", ranks, err);
    return st;
}

ekm_status ekm2d_writer_open(ekm2d_writer **out, const char *path, const ekm_scenario *sc, int ranks,
                             size_t max_frames, ekm_error *err)
{
    *out = NULL;
    if (sc->cells_x < 1 || sc->cells < 1 || !(sc->width > 0.0) || !(sc->length > 0.0))
        return EKM_FAIL(err, EKM_EINTERNAL,
                        "%s: a 2D output needs cells_x, cells >= 1 and width, length > 0 (got %d x %d cells, "
                        "%g x %g m)",
                        path, sc->cells_x, sc->cells, sc->width, sc->length);
    const size_t nx = (size_t)sc->cells_x, nz = (size_t)sc->cells;
    ekm_status st = check_output_size(sc, nx * nz, max_frames, err);
    if (st != EKM_OK)
        return st;
    ekm2d_writer *w = calloc(1, sizeof *w);
    if (!w)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s", path);
    if (strlen(path) >= sizeof w->path) {
        free_writer(w);
        return EKM_FAIL(err, EKM_EINPUT, "%s: output path too long", path);
    }
    strcpy(w->path, path);
    w->sc = sc;
    w->nx = nx;
    w->nz = nz;
    w->dx = sc->width / (double)nx;
    w->dz = sc->length / (double)nz;
    w->max_nt = max_frames;
    w->times = malloc((max_frames ? max_frames : 1) * sizeof *w->times);
    w->dz_frame = malloc((max_frames ? max_frames : 1) * sizeof *w->dz_frame);
    w->lo = calloc(max_frames ? max_frames : 1, sizeof *w->lo);
    w->regime = malloc(nx * nz * sizeof *w->regime);
    if (!w->times || !w->dz_frame || !w->lo || !w->regime) {
        free_writer(w);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s (%zu x %zu cells, %zu frames)", path, nx,
                        nz, max_frames);
    }
    st = ekm_h5_create(&w->file, path, err);
    if (st != EKM_OK) {
        free_writer(w);
        return st;
    }
    st = write_layout(w, ranks, err);
    if (st != EKM_OK) {
        ekm2d_writer_abort(w);
        return st;
    }
    *out = w;
    return EKM_OK;
}

/* EKM_ENUMERIC naming the first value of the frame that is not finite. */
static ekm_status check_finite(const ekm2d_writer *w, double t, const double *const fields[EKM2D_NFIELDS],
                               ekm_error *err)
{
    const size_t n = w->nx * w->nz;
    for (int k = 0; k < EKM2D_NFIELDS; k++)
        for (size_t c = 0; c < n; c++)
            if (!isfinite(fields[k][c])) {
                const size_t ix = c % w->nx, iz = c / w->nx;
                return EKM_FAIL(err, EKM_ENUMERIC,
                                "%s: t = %g s, cell (ix %zu, iz %zu) (x = %g m, z = %g m): field %s is not "
                                "finite (%g); nothing written",
                                w->path, t, ix, iz, ((double)ix + 0.5) * w->dx, ((double)iz + 0.5) * w->dz,
                                FIELD_NAMES[k], fields[k][c]);
            }
    return EKM_OK;
}

ekm_status ekm2d_writer_append(ekm2d_writer *w, double t, double dz,
                               const double *const fields[EKM2D_NFIELDS], ekm_error *err)
{
    if (w->nt == w->max_nt)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: frame %zu at t = %g s: more frames than the %zu announced",
                        w->path, w->nt + 1, t, w->max_nt);
    if (!isfinite(t))
        return EKM_FAIL(err, EKM_ENUMERIC, "%s: frame %zu: the time is not finite (%g); nothing written",
                        w->path, w->nt, t);
    if (!(dz > 0.0) || !isfinite(dz))
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "%s: frame %zu at t = %g s: the cell size dz = %g m is not a positive finite number; "
                        "nothing written",
                        w->path, w->nt, t, dz);
    ekm_status st = check_finite(w, t, fields, err);
    if (st != EKM_OK)
        return st;
    const size_t n = w->nx * w->nz;
    for (size_t c = 0; c < n; c++)
        w->regime[c] = (int)lround(fields[EKM2D_REGIME][c]);
    st = ekm_h5_append(w->file, "t", &t, err);
    const double gap = dz * (double)w->nz; /* [m] */
    if (st == EKM_OK && ekm_boundary_pressure_wall(&w->sc->top))
        st = ekm_h5_append(w->file, "gap", &gap, err);
    for (int k = 0; k < EKM2D_NFIELDS && st == EKM_OK; k++)
        st = ekm_h5_append(w->file, FIELD_NAMES[k],
                           k == EKM2D_REGIME ? (const void *)w->regime : (const void *)fields[k], err);
    if (st != EKM_OK)
        return st;
    w->times[w->nt] = t;
    w->dz_frame[w->nt++] = dz;
    return EKM_OK;
}

ekm_status ekm2d_writer_set_attr(ekm2d_writer *w, const char *name, double value, ekm_error *err)
{
    return ekm_h5_attr_set_double(w->file, NULL, name, value, err);
}

/* The frames' views and the sidecar of the 2D grid (x from 0 along
 * ParaView's X, z from 0 along its Z, each frame with its dz), then both
 * renamed into place. */
ekm_status ekm2d_writer_commit(ekm2d_writer *w, ekm_error *err)
{
    ekm_xdmf_field fields[EKM2D_NFIELDS];
    for (int k = 0; k < EKM2D_NFIELDS; k++)
        fields[k] = (ekm_xdmf_field){.name = FIELD_NAMES[k], .is_int = k == EKM2D_REGIME};
    const ekm_xdmf_series series = {.title = w->sc->name,
                                    .h5_path = w->path,
                                    .n = w->nz,
                                    .nt = w->nt,
                                    .t = w->times,
                                    .fields = fields,
                                    .lo = w->lo,
                                    .dz = w->dz_frame,
                                    .nfields = EKM2D_NFIELDS,
                                    .nx = w->nx,
                                    .x0 = 0.0,
                                    .dx = w->dx};
    const ekm_status st = ekm_xdmf_commit_with(w->file, &series, err);
    w->file = NULL;
    free_writer(w);
    return st;
}
