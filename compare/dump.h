/* dump.h: streaming reader for LAMMPS/LIGGGHTS `dump custom` files.
 *
 * Formats: text (`dump custom`, LIGGGHTS or LAMMPS, any column order, extra
 * columns ignored, trailing blanks allowed), the same gzip-compressed (zlib,
 * detected from the content, not the name), and LAMMPS binary dumps with
 * column names (magic string, format revision >= 2, as written by LAMMPS
 * since 2020; older binary files carry no column names and are refused).
 *
 * The caller names the columns it wants at open time; every snapshot then
 * delivers those columns (or marks them absent) for all atoms in a buffer
 * reused from one snapshot to the next, so memory does not grow with the
 * number of snapshots.
 *
 * Local dumps (`dump local`, e.g. compute pair/gran/local or pair/local:
 * ITEM: NUMBER OF ENTRIES, ITEM: ENTRIES) are read the same way, one entry
 * per "atom".
 *
 * Boxes: orthogonal and triclinic (`ITEM: BOX BOUNDS xy xz yz ...`); the
 * bounding box the engines write is converted back to the box (lo, hi)
 * and the tilt factors.
 *
 * Errors name the input and its line ("run.dump:120: ..."; binary files name
 * the byte offset, "run.bin:@4096: ..."). A snapshot cut short by the end of
 * the file (a killed run) is not an error: cg_dump_next returns EKM_EOF and
 * sets `truncated` and `warning`. A text dump's last line without its
 * newline is cut short, even when what is left of it parses (0.0123 cut to
 * 0.01): the engines end every line with one.
 */
#ifndef CG_DUMP_H
#define CG_DUMP_H

#include <stddef.h>
#include <stdint.h>

#include "status.h"

#define CG_DUMP_MAXCOL 64 /* most columns one may select */

typedef struct {
    int64_t step;                /* time step number */
    int has_time;                /* 1 if the dump carried ITEM: TIME */
    double time;                 /* simulation time from ITEM: TIME [s] */
    int64_t natoms;              /* atoms in this snapshot */
    int triclinic;               /* 1 if the box has tilt factors */
    double lo[3], hi[3];         /* box corners (not the bounding box) [m] */
    double tilt[3];              /* xy, xz, yz tilt factors [m] */
    int periodic[3];             /* 1 if x, y, z is periodic ('p' flags) */
    size_t nsel;                 /* number of selected columns */
    int present[CG_DUMP_MAXCOL]; /* 1 if selected column j exists */
    double *data;                /* natoms x nsel values, row-major; the values of
                                    absent columns are unspecified */
    size_t cap;                  /* allocated rows of data */
    char where[600];             /* "file:line" of this snapshot's ITEM: ATOMS */
    char time_where[620];        /* "file:line" of its time: the value of ITEM: TIME,
                                    without one of ITEM: TIMESTEP (binary:
                                    "file:@offset" of the header) */
    char box_where[3][620];      /* "file:line" of its box bounds along x, y, z
                                    (binary: "file:@offset" of the header) */
} cg_snapshot;

/* What a selected column's values must be, besides finite numbers (every
 * selected value is): checked per atom by the reader, so that a value that
 * makes no sense is reported at its file, line and column
 * ("a.dump:12:87: radius: expected a positive finite number, got -0.001",
 * "a.dump:10:3: type: expected an integer, got 1.5"). */
typedef enum {
    CG_DUMP_ANY = 0,  /* any finite number */
    CG_DUMP_POSITIVE, /* > 0 (mass) */
    CG_DUMP_RADIUS,   /* > 0, and the particle (2 x value) no larger than the
                         box's longest edge */
    CG_DUMP_DIAMETER, /* > 0, and no larger than the box's longest edge */
    CG_DUMP_INTEGER,  /* an integer of magnitude at most 2^53, exact in a
                         double (type, id: the engines write them as
                         integers; 1.5 is no atom type) */
    CG_DUMP_VELOCITY, /* |value| < CG_DUMP_LIGHT_SPEED: a velocity component
                         in SI units (the decks' `units si`); one of at
                         least the speed of light is no grain's (1e300 made
                         m v^2, T and P inf), and below it m v^2 stays far
                         from overflowing */
} cg_dump_check;

#define CG_DUMP_LIGHT_SPEED 299792458.0 /* speed of light [m/s] */

typedef struct cg_dump cg_dump;

/* Open a dump (text, gzip or binary) and select columns by name. */
ekm_status cg_dump_open(cg_dump **d, const char *path, const char *const *cols, size_t ncols, ekm_error *err);

/* Check the values of selected column j (0 <= j < ncols of cg_dump_open)
 * with c from the next snapshot on. */
void cg_dump_expect(cg_dump *d, size_t j, cg_dump_check c);

/* Read the next snapshot into s (its buffers are reused and grown). At a
 * clean end of data s is left as it was; after an error or a truncated
 * snapshot its contents are undefined.
 * Returns EKM_OK, EKM_EOF at the end (check cg_dump_truncated), or an error. */
ekm_status cg_dump_next(cg_dump *d, cg_snapshot *s, ekm_error *err);

/* After EKM_EOF: non-zero if the last snapshot was incomplete and skipped;
 * the warning text ("file:line: truncated snapshot ... skipped"). */
int cg_dump_truncated(const cg_dump *d);
const char *cg_dump_warning(const cg_dump *d);
/* The same without what was done ("file:line: truncated snapshot (...)"),
 * for an error when a cut-off dump is not acceptable. */
const char *cg_dump_truncation(const cg_dump *d);

/* The times of a series of snapshots (cg_snapshot_time). */
typedef struct {
    int have; /* 1 after the first snapshot */
    double t; /* time of the last one [s] */
} cg_time_order;

/* The time of snapshot s [s]: ITEM: TIME when the dump has it, else
 * step x dt (dt > 0; otherwise an error, EKM_EUSAGE, asking for --dt).
 * Times increase strictly from one snapshot to the next, over all the files
 * of a run (a snapshot whose step was already read, a restart overlap, is
 * the caller's to skip first): a time not after the previous one in *ord is
 * an error, EKM_EINPUT, at s->time_where, naming both times. *ord is
 * updated on success. */
ekm_status cg_snapshot_time(const cg_snapshot *s, double dt, cg_time_order *ord, double *t, ekm_error *err);

/* Close the dump; cg_dump_close(NULL) is harmless. */
void cg_dump_close(cg_dump *d);

/* Release a snapshot's buffers (the struct itself belongs to the caller). */
void cg_snapshot_free(cg_snapshot *s);

/* Parse a decimal floating-point token at *p (fast path for up to 15
 * significant digits, within 1 ulp; strtod otherwise). On success *p
 * points past it.
 * Returns 0, 1 if malformed, 2 if NaN or inf. Exposed for tests. */
int cg_parse_double(const char **p, double *out);

#endif
