/* steadiness.h: the one definition of "steady" in ekmbench.
 *
 * Two questions, two tools:
 *
 * 1. Is a run steady? The drift criterion decides (the DEM runner asks it
 *    of a finished run's monitor series, `ekmcompare steady`): with n
 *    samples v_0..v_{n-1} and q = floor(n/4), a is the mean of the quarter
 *    before the last, v_{n-2q} .. v_{n-q-1}, b the mean of the last
 *    quarter, v_{n-q} .. v_{n-1} (each summed in index order, then divided
 *    by q), and
 *        drift = |b - a| / (0.5 (|a| + |b|))      (0 when |a| + |b| = 0),
 *    rounded to 4 significant digits (printf %.4g); the run is steady when
 *    that rounded drift <= tol. Fewer than 8 samples: no verdict (null).
 *    This is, operation for operation, the awk that scripts/dem/run.sh
 *    used before (same numbers on the same file).
 *
 * 2. Where does the averaging window of a (steady) run start? MSER-5
 *    (White 1997) picks it: batch means y_j of 5 samples, and the start d
 *    minimising sum_{j>=d} (y_j - mean_d)^2 / (nb - d)^2 over d <= nb/2;
 *    `ekmcompare cg --steady` applies it to the kinetic energy per unit
 *    mass and, on a non-periodic axis, the centre of mass of every
 *    selected snapshot, and starts at the later of the two.
 */
#ifndef CG_STEADINESS_H
#define CG_STEADINESS_H

#include <stddef.h>

#include "cg_opts.h"
#include "status.h"

#define CG_STEADINESS_MIN_SAMPLES 8 /* fewest samples the drift criterion judges */

typedef struct {
    size_t samples; /* n */
    int known;      /* 0: fewer than CG_STEADINESS_MIN_SAMPLES samples, no verdict */
    double drift;   /* the relative drift, rounded to 4 significant digits [-] */
    double tol;     /* the tolerance it was held against [-] */
    int steady;     /* known && drift <= tol */
} cg_steadiness_verdict;

/* The drift criterion on v[0..n-1] (finite values) with tolerance tol. */
cg_steadiness_verdict cg_steadiness_drift(const double *v, size_t n, double tol);

/* Steady-state start index of x[0..n-1] by MSER-5 (0 if n < 10). */
size_t cg_steadiness_mser(const double *x, size_t n);

/* The monitor series of a DEM run: column `column` (1-based, as awk's $N)
 * of the lines of path that do not start with '#' and have at least
 * max(2, column) blank-separated fields; every such value must be a
 * finite number. *v is malloc'ed (free() it), *n its length. */
ekm_status cg_steadiness_monitor_read(const char *path, int column, double **v, size_t *n, ekm_error *err);

/* `cg --steady`: read the selection of o once and return the time at
 * which the steady window starts (MSER-5, see above; notes and a warning
 * on o->log). */
ekm_status cg_steadiness_start(const cg_run_opts *o, double *t_start, ekm_error *err);

#endif
