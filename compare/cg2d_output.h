/* cg2d_output.h: the outputs of `ekmcompare cg --axes x,z`: every window's
 * fields [nt][nz][nx] with their standard errors and the run's description
 * as HDF5 (datasets with `units` from the field schema, root attributes:
 * docs/compare.md) with its XDMF sidecar (common/xdmf.h, a 2D grid), or
 * CSV (one row per window and cell), each written under a temporary name
 * and renamed when complete. */
#ifndef CG_CG2D_OUTPUT_H
#define CG_CG2D_OUTPUT_H

#include <stddef.h>

#include "cg2d.h"
#include "cg_opts.h"
#include "status.h"

/* The fields of the closed windows (or of the ensemble: one). */
typedef struct {
    size_t ncell;
    size_t nt, cap;
    double *t;               /* window mid-times [s] */
    double *nsnap;           /* snapshots per window */
    double *f[CG2D_NFIELD];  /* nt x ncell */
    double *se[CG2D_NFIELD]; /* nt x ncell */
} cg2d_results;

/* What the outputs show. */
typedef struct {
    const cg_run_opts *o;
    const cg2d_grid *g;
    const cg2d_results *r;
    const char *kernel;               /* kernel name */
    const char *inputs;               /* dump files, one a line */
    const char *window;               /* the selection and windows, in words */
    double width;                     /* kernel width [m] */
    double d;                         /* mean particle diameter [m] */
    double length_y;                  /* box length along the averaged axis [m] */
    size_t nread, nused, nout, nruns; /* snapshots read, used; particle-snapshots
                                         outside the grid; runs (ensemble) */
} cg2d_output;

ekm_status cg2d_output_h5(const cg2d_output *out, ekm_error *err);
ekm_status cg2d_output_csv(const cg2d_output *out, ekm_error *err);

#endif
