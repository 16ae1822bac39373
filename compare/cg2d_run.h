/* cg2d_run.h: `ekmcompare cg --axes x,z`: dumps -> selected snapshots ->
 * particles (cg_input.h, with the second axis) -> 2D kernel sums (cg2d.h)
 * -> fields with standard errors -> HDF5 [nt][nz][nx] with its XDMF
 * sidecar (and CSV), written atomically.
 *
 * One run (the default): the inputs are the files of one run, in time
 * order, as in 1D; windows (--every, --window) and standard errors by
 * blocking over snapshots (stats.h), with at most CG2D_BLOCKS (cg2d.h) blocks
 * per window (the block store is CG2D_BLOCKS x 17 values per cell).
 *
 * Ensemble (--ensemble): every input is one independent run (another
 * seed); each run's selected snapshots are averaged (one window per run,
 * --steady applied per run), the ensemble's fields are derived from the
 * mean of the runs' averaged primaries (every run weighs the same), and
 * the standard error of every value is that of the mean of the R runs'
 * own fields, sd / sqrt(R) (independent: no blocking); NaN where fewer
 * than two runs have a finite value. The runs share one grid: their boxes
 * along x and z (or --range) must be the first run's.
 */
#ifndef CG_CG2D_RUN_H
#define CG_CG2D_RUN_H

#include "cg_opts.h"
#include "status.h"

ekm_status cg2d_run(const cg_run_opts *o, ekm_error *err);

#endif
