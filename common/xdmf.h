/* xdmf.h: the XDMF sidecar of a profile time series (ekm run, ekmcompare cg),
 * so that ParaView opens it with any of its three XDMF readers (the legacy
 * XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT) with every field.
 *
 * The profile is a column of n cells along ParaView's Z axis (the slab
 * normal z), cell j spanning [lo + j dz, lo + (j+1) dz], one cell wide in X
 * and Y (width dz); every field is cell-centred (Center="Cell"): a cell's
 * value is its finite-volume (or bin) value, so Plot Over Line along Z
 * returns, at every sample, the value of the cell that holds it.  Frame i
 * (time t[i]) may have its own lo and dz (a moving wall).
 *
 * The fields are [nt][n] datasets of the HDF5 file; the Xdmf3 readers of
 * ParaView cannot read a HyperSlab (nor Function) item, so each row is
 * also a virtual dataset "/xdmf/FIELD/I" of the HDF5 file (no copy:
 * ekm_xdmf_add_views, before the HDF5 file is finished), referenced as a
 * plain HDF item.  The HDF5 file is named by its base name (keep the two
 * files in one directory).  Every string written into the XML is escaped
 * (& < > " '); bytes that XML 1.0 cannot hold (control characters,
 * invalid UTF-8) become '?'.
 */
#ifndef EKM_XDMF_H
#define EKM_XDMF_H

#include <stddef.h>
#include <stdio.h>

#include "h5.h"
#include "status.h"

typedef struct {
    const char *name; /* dataset [nt][n] and attribute name */
    int is_int;       /* 1: int32, 0: float64 */
} ekm_xdmf_field;

typedef struct {
    const char *title;            /* the collection's name (the scenario's) */
    const char *h5_path;          /* the HDF5 file's target path */
    size_t n, nt;                 /* cells, frames */
    const double *t;              /* [nt] frame times [s] */
    const double *lo, *dz;        /* [nt] lower end, cell size of each frame [m] */
    const ekm_xdmf_field *fields; /* nfields of them */
    size_t nfields;
    /* A 2D grid (ekmcompare cg --axes x,z) when nx > 0: the fields are
     * [nt][n][nx] datasets (x fastest), n cells along ParaView's Z (lo, dz)
     * by nx along its X (x0, dx), one cell (of width dx) thick in Y.
     * nx == 0 (a zero-initialised series): the column of n cells above. */
    size_t nx;
    double x0, dx; /* lower end and cell size along X [m] (2D) */
} ekm_xdmf_series;

/* The sidecar's path for an output path (".h5" replaced by ".xdmf", else
 * ".xdmf" appended). */
void ekm_xdmf_path(const char *h5_path, char *out, size_t size);

/* EKM_EUSAGE unless the sidecar can name the HDF5 file h5_path: its base
 * name must be valid UTF-8 without control characters (bytes below 0x20,
 * 0x7F), which XML 1.0 cannot hold and ekm_xdmf_escape would replace by
 * '?', naming a file that does not exist.  opt is the option that gave the
 * path ("-o"), for the message. */
ekm_status ekm_xdmf_check_name(const char *h5_path, const char *opt, ekm_error *err);

/* The row views /xdmf/FIELD/I of every field and frame, in f. */
ekm_status ekm_xdmf_add_views(ekm_h5_file *f, const ekm_xdmf_series *s, ekm_error *err);

/* Write the XDMF document of s to fp (errors of fp are the caller's to
 * check, e.g. by ekm_atomic_finish). */
void ekm_xdmf_write(FILE *fp, const ekm_xdmf_series *s);

/* Write text to fp escaped for an XML attribute value or element text. */
void ekm_xdmf_escape(FILE *fp, const char *text);

/* Finish the HDF5 file h5 (ekm_h5_finish), then write the sidecar of s to
 * its temporary, then rename both into place: on any failure neither is
 * left (nor a temporary).  Frees h5. */
ekm_status ekm_xdmf_commit_with(ekm_h5_file *h5, const ekm_xdmf_series *s, ekm_error *err);

/* ekm_xdmf_commit_with for a grid that does not move: every frame's lower
 * end along Z is lo and its cell size dz [m] (s->lo and s->dz are not
 * read).  Frees h5. */
ekm_status ekm_xdmf_commit_fixed(ekm_h5_file *h5, const ekm_xdmf_series *s, double lo, double dz,
                                 ekm_error *err);

#endif
