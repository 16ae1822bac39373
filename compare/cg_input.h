/* cg_input.h: the snapshots of `ekmcompare cg`: dump files -> selected
 * snapshots -> particles (and, with pair dumps, their contacts).
 *
 * Snapshots are streamed file after file (memory is one snapshot); a step
 * already seen (restart overlap between files) is skipped and counted. The
 * time of a snapshot is ITEM: TIME when the dump has it, otherwise step x
 * dt (--dt), and must be after the previous snapshot's (cg_snapshot_time:
 * a time that goes back or repeats is the dump's error); --steps, --from
 * and --to select. Only the columns the options need are asked of the
 * reader; they are converted to the particle arrays
 * of cg.h: the coordinate along the axis (plain, unwrapped or scaled,
 * triclinic boxes, wrapped into a periodic box), velocities, mass and
 * volume (from radius/diameter and --rho-p when a column is missing),
 * per-atom stress x volume; atoms of types not kept (--types) stay in the
 * arrays (pair dumps find them) with zero mass, volume and stress.
 */
#ifndef CG_INPUT_H
#define CG_INPUT_H

#include <stddef.h>
#include <stdint.h>

#include "cg.h"
#include "cg_opts.h"
#include "contacts.h"
#include "dump.h"
#include "status.h"

/* Dump columns the reader is asked for. */
enum {
    CG_IN_POS = 0, /* 3 x flavour (plain, u, s, su) + dim: x y z xu ... */
    CG_IN_VX = 12,
    CG_IN_VY,
    CG_IN_VZ,
    CG_IN_MASS,
    CG_IN_RADIUS,
    CG_IN_DIAMETER,
    CG_IN_STRESS,
    CG_IN_ID = CG_IN_STRESS + 6,
    CG_IN_TYPE,
    CG_IN_NCOL
};

typedef struct {
    const cg_run_opts *o;
    const char *cols[CG_IN_NCOL]; /* the columns asked of the reader (compact) */
    size_t ncols;
    int col[CG_IN_NCOL]; /* CG_IN_* -> index in cols, or -1 if not asked */
    size_t ifile;        /* next file to open */
    cg_dump *d;
    cg_snapshot snap;
    int have_last;
    int64_t last_step; /* last accepted step (skip repeats) */
    size_t nread;      /* snapshots read */
    size_t nrepeat;    /* repeated steps skipped */
    size_t cap;        /* particle capacity */
    double *s, *v, *m, *vol, *rad, *S;
    cg_particles pt;
    double t;          /* time of the current snapshot [s] */
    double lo, hi;     /* box along the axis [m] */
    int periodic;      /* box periodic along the axis */
    double *s2;        /* 2D (o->axis2 >= 0): coordinate along axis2 [m] */
    double lo2, hi2;   /* box along axis2 [m] */
    int periodic2;     /* box periodic along axis2 */
    double length_avg; /* 2D: box length along the averaged axis [m] */
    double dsum;       /* sum of diameters so far [m] */
    double dcount;     /* particles in dsum */
    cg_contacts pairs; /* contacts from the pair dumps */
    int skip_pairs;    /* 1: do not read the pair dumps (steady pass) */
    /* the times read so far (strictly increasing, cg_snapshot_time) */
    cg_time_order order;
} cg_input;

/* Start reading the inputs of o (nothing is opened yet). */
void cg_input_init(cg_input *src, const cg_run_opts *o);

/* Next selected snapshot, converted (src->pt, src->t); EKM_EOF after the
 * last file. */
ekm_status cg_input_next(cg_input *src, ekm_error *err);

/* Close the files and free the buffers (src itself is the caller's). */
void cg_input_close(cg_input *src);

#endif
