/* pile_base.h: `ekmcompare base`: the base pressure profile p(x) of a pile
 * from the forces on its floor grains, with its standard errors.
 *
 * Dump contract (the sandpile decks): atoms.dump with a position along x
 * (x, xu, xs or xsu; orthogonal box), `type` (an integer: the reader
 * refuses 1.5 at its line and column) and `fz` (the decks dump
 * fx fy fz); the floor grains (type --floor-type, default 2) are not
 * integrated, feel no gravity and do not interact with each other, so a
 * floor grain's fz is the sum of the pile's contact forces on it. Per
 * snapshot, bin k of width dx along x:
 *     p_k = -(sum of fz over the floor grains in bin k) / (dx L_y)   [Pa]
 * with L_y the box length along y (BOX BOUNDS; the slab's period); a bin
 * with no floor grain has p = NaN. Each run (one DUMP argument: an
 * independent pile) is averaged over its selected snapshots (--from/--to,
 * --steps, then --last N: the last N of those; a pile at rest). Over the
 * R runs: p = the mean of the runs' profiles; p_se = their sd / sqrt(R)
 * (NaN for one run); p_fold_se = |p(x_c + s) - p(x_c - s)| / 2, the
 * asymmetry of the mean profile about the centre x_c (a symmetric pile
 * has p(x_c + s) = p(x_c - s): half their difference is the SE of their
 * mean from that one pair). The grid is symmetric about x_c (--centre,
 * default the middle of the box or of --range) so that bin k mirrors bin
 * n-1-k.
 */
#ifndef CG_PILE_BASE_H
#define CG_PILE_BASE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "cg_keys.h"
#include "cg_select.h"
#include "status.h"

typedef struct {
    const char *const *inputs; /* one dump per run (independent piles) */
    size_t ninputs;
    const char *out;           /* HDF5 output, or NULL */
    const char *csv;           /* CSV output, or NULL */
    int floor_type;            /* atom type of the floor grains */
    double dx;                 /* bin width [m]; 0: from bins or 2 floor-grain diameters */
    size_t bins;               /* number of bins; 0: from dx */
    int have_range;            /* 1: grid over [range_lo, range_hi] */
    double range_lo, range_hi; /* [m] */
    int have_centre;           /* 1: fold about centre */
    double centre;             /* x_c [m] */
    cg_select select;          /* --dt, --from, --to, --steps (cg_select.h) */
    size_t last;               /* > 0: only the last `last` selected snapshots of each run */
    FILE *log;                 /* notes, or NULL */
} cg_base_opts;

/* Set an option `base` shares with `cg` (-o, --csv, --range, --dt, --from,
 * --to, --steps), parsed by ekm_cg_keys_parse (scenario/cg_keys.h). */
void cg_base_opts_apply(cg_base_opts *o, const ekm_cg_value *v);

cg_base_opts cg_base_opts_default(void);

ekm_status cg_base_run(const cg_base_opts *o, ekm_error *err);

#endif
