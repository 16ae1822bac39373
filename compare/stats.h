/* stats.h: block averages with bounded memory and standard errors of
 * correlated series.
 *
 * cg_blocks keeps the running sum of m values per snapshot and at most
 * `bmax` block sums of `bsize` successive snapshots; when the store is
 * full, neighbouring blocks are merged and bsize doubles (so memory does
 * not grow with the number of snapshots, and between bmax/2 and bmax
 * complete blocks are kept). A trailing incomplete block counts in the mean
 * but not in the error estimate.
 *
 * cg_stats_se: standard error of the mean of a series of block values by
 * Flyvbjerg-Petersen blocking: the naive SE sqrt(var/nb) is computed after
 * 0, 1, 2, ... pairwise mergings; the reported SE is the largest among the
 * levels with at least 8 blocks (the plateau; level 0 if there are fewer).
 * Non-finite values (empty bins) are skipped.
 *
 * The start of the steady state (MSER-5) is in steadiness.h.
 */
#ifndef CG_STATS_H
#define CG_STATS_H

#include <stddef.h>

#include "status.h"

typedef struct {
    size_t m;       /* values per snapshot */
    size_t bmax;    /* most blocks kept (even, >= 2) */
    size_t bsize;   /* snapshots per block */
    size_t nblocks; /* complete blocks kept */
    size_t ncur;    /* snapshots in the current block */
    size_t nsnap;   /* snapshots added */
    double *blocks; /* bmax x m block sums */
    double *cur;    /* m: sum of the current block */
    double *total;  /* m: sum of all snapshots */
} cg_blocks;

ekm_status cg_blocks_alloc(cg_blocks **b, size_t m, size_t bmax, ekm_error *err);
void cg_blocks_free(cg_blocks *b);
void cg_blocks_reset(cg_blocks *b);
void cg_blocks_add(cg_blocks *b, const double *x);
/* Mean of all snapshots, and of complete block j, into out (m values). */
void cg_blocks_mean(const cg_blocks *b, double *out);
void cg_blocks_block_mean(const cg_blocks *b, size_t j, double *out);

/* Standard error of the mean of x[0..n-1] (block values); NAN if < 2. */
double cg_stats_se(const double *x, size_t n, double *work);

#endif
