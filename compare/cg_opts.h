/* cg_opts.h: the options of one `ekmcompare cg` run (1D profile or 2D
 * grid: cg_run.h, cg2d_run.h), their defaults, and the check that its
 * outputs replace none of its inputs.
 */
#ifndef CG_OPTS_H
#define CG_OPTS_H

#include <stdint.h>
#include <stdio.h>

#include "cg.h"
#include "cg_keys.h"
#include "cg_select.h"
#include "status.h"

#define CG_MAXTYPES EKM_CG_TYPES_MAX /* most atom types --types may list */

typedef struct {
    const char *const *inputs; /* dump files, in time order */
    size_t ninputs;
    const char *out;           /* HDF5 output path, or NULL */
    const char *csv;           /* CSV output path, or NULL */
    int axis;                  /* profile axis: 0 x, 1 y, 2 z */
    int axis2;                 /* 2D grid (--axes x,z, cg2d.h): the second axis (0 x, with
                                  axis 2 z); -1: a 1D profile (the default) */
    const char *kernel;        /* "gauss", "lucy" or "bins" */
    double width;              /* kernel std. deviation [m]; 0: mean diameter */
    size_t bins;               /* number of bins; 0: from dz */
    double dz;                 /* bin width [m]; 0: width/2 */
    int have_range;            /* 1: grid over [range_lo, range_hi] */
    double range_lo, range_hi; /* [m] */
    double rho_p;              /* material density [kg/m^3]; 0: not given */
    cg_select select;          /* --dt, --from, --to, --steps (cg_select.h) */
    int steady;                /* 1: find the steady start (MSER-5) */
    size_t every;              /* > 0: one profile per `every` snapshots */
    double window;             /* > 0: one profile per window [s] */
    cg_tmode tmode;            /* temperature definition */
    int exact;                 /* 1: kernel per particle, no sub-grid (cg.h) */
    size_t nstress;            /* 0 or 6 per-atom stress columns */
    const char *stress[6];     /* names: xx yy zz xy xz yz (stress x volume) */
    const char *const *pairs;  /* pair dumps (dump local), in time order */
    size_t npairs;
    size_t npaircols;        /* 9: x1 y1 z1 x2 y2 z2 fx fy fz; 5: id1 id2 fx fy fz */
    const char *paircols[9]; /* their column names (force on 1 by 2) */
    size_t ntypes;           /* > 0: only atoms of these types count */
    int types[CG_MAXTYPES];  /* atom types kept (dump column `type`) */
    size_t expect_snapshots; /* > 0: the dumps must hold exactly this many
                                complete snapshots (--expect-snapshots): fewer,
                                more, or one cut short is an error */
    FILE *log;               /* notes and warnings, or NULL */
    size_t bins_x;           /* 2D: cells along x (--bins NX,NZ; o->bins along z); 0: from dz */
    int ensemble;            /* 2D: 1: every input is an independent run (--ensemble) */
} cg_run_opts;

/* Storage for the names an option's value gives (cg_run_opts points into it). */
typedef struct {
    char stress[6][EKM_CG_NAME_MAX];
    char paircols[9][EKM_CG_NAME_MAX];
} cg_opts_names;

/* Set the option v (parsed by ekm_cg_keys_parse, scenario/cg_keys.h) in
 * o; names holds the names it gives. --pairs (a list) is the caller's. */
void cg_opts_apply(cg_run_opts *o, cg_opts_names *names, const ekm_cg_value *v);

/* The defaults: axis z, the Gaussian kernel of the mean diameter, ... */
cg_run_opts cg_opts_default(void);

/* Every output of o must be writable, and none may replace an input
 * (dumps, pair dumps), the HDF5 output's XDMF sidecar or (the CSV) the
 * HDF5 output. */
ekm_status cg_opts_refuse_inputs(const cg_run_opts *o, ekm_error *err);

#endif
