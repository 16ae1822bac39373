/* cg_output.h: the outputs of `ekmcompare cg`: the profiles of every
 * window with their standard errors and the run's description, as HDF5
 * (datasets with `units`, root attributes: docs/compare.md) or CSV (one
 * row per window and bin), each written under a temporary name and
 * renamed when complete.  Beside the HDF5 file, OUT.xdmf (common/xdmf.h)
 * opens every field and its standard error in ParaView, the bins as cells
 * along ParaView's Z axis, like ekm's output.
 */
#ifndef CG_OUTPUT_H
#define CG_OUTPUT_H

#include <stddef.h>

#include "cg.h"
#include "cg_opts.h"
#include "status.h"
#include "kernel.h"
#include "window.h"

/* What the run did, for the root attributes. */
typedef struct {
    char inputs[4096];              /* dump files, one a line */
    char pairs[4096];               /* pair dumps, one a line */
    char window[256];               /* the selection and windows, in words */
    char stress[256];               /* the stress definition, in words */
    double width, d, area, t_start; /* kernel width [m], mean diameter [m],
                                       lateral area [m^2], steady start [s] */
    size_t nread, nused, nout;      /* snapshots read, used; particle-snapshots
                                       outside the grid */
    int steady;                     /* 1: t_start is the --steady start */
    const char *wall;               /* the boundary treatment, in words */
} cg_run_info;

/* The guard of every cg output, 1D and 2D: a value written is a finite
 * number, or NaN where its field is not defined: the velocities and T of an
 * empty bin or cell (rho = 0), mu where P <= 0, I where P <= 0, with no
 * density or beside an empty bin, and a standard error from fewer than two
 * blocks (or runs) with a value. Anything else (inf anywhere, NaN where the
 * bin holds particles) comes from dump values whose products overflow
 * double precision (a mass of 1e295 kg at 2e8 m/s: m v^2 = inf) and the
 * output is refused before it is opened.
 * cg_output_value_ok: is v finite, or NaN with nan_ok?
 * cg_output_refuse: the error (EKM_ENUMERIC) naming the inputs, the field
 * (name and suffix, "T" "_se"), the bin or cell (where) and the window's
 * mid-time t. */
int cg_output_value_ok(double v, int nan_ok);
ekm_status cg_output_refuse(const cg_run_opts *o, const char *field, const char *suffix, const char *where,
                            double t, double v, ekm_error *err);

/* Field units from the field schema (common/schema.h). Both refuse
 * values the guard above does not allow (EKM_ENUMERIC), writing nothing. */
ekm_status cg_output_h5(const cg_run_opts *o, const cg_grid *g, const cg_window_results *r,
                        const cg_kernel *k, const cg_run_info *info, ekm_error *err);
ekm_status cg_output_csv(const cg_run_opts *o, const cg_grid *g, const cg_window_results *r, ekm_error *err);

#endif
