/* window.h: averaging windows of `ekmcompare cg`: the primary sums of the
 * snapshots of one window go into a block store (stats.h); closing the
 * window derives the fields from the mean and from every block mean, and
 * the standard error of each value from the block values (blocking,
 * cg_stats_se). One window (the whole selection) for a steady profile,
 * several for --every / --window time series.
 */
#ifndef CG_WINDOW_H
#define CG_WINDOW_H

#include <stddef.h>

#include "cg.h"
#include "status.h"
#include "stats.h"

#define CG_WINDOW_BLOCKS 64 /* block store size (cg_blocks bmax) */

/* The profiles of the closed windows. */
typedef struct {
    size_t n;              /* bins */
    size_t nt, cap;        /* windows stored, capacity */
    double *t;             /* window mid-times [s] */
    double *nsnap;         /* snapshots per window */
    double *f[CG_NFIELD];  /* nt x n fields */
    double *se[CG_NFIELD]; /* nt x n standard errors */
} cg_window_results;

/* A growing series of windows, shared by the 1D and the 2D results: the
 * window times t, snapshots per window nsnap and nfield fields and their
 * SEs of n values each per window.  Grows the arrays (doubling, from
 * first) so that one more window fits; *cap is updated. */
ekm_status cg_series_grow(double **t, double **nsnap, double **f, double **se, int nfield, size_t n,
                          size_t nt, size_t *cap, size_t first, ekm_error *err);
/* Frees what cg_series_grow allocated. */
void cg_series_free(double *t, double *nsnap, double **f, double **se, int nfield);

/* The open window. */
typedef struct {
    const cg_grid *g;
    cg_blocks *b;
    double *mean;   /* CG_NPRIM x n */
    double *fld;    /* CG_NFIELD x n */
    double *bf;     /* CG_WINDOW_BLOCKS x CG_NFIELD x n */
    double *series; /* CG_WINDOW_BLOCKS */
    double *work;   /* CG_WINDOW_BLOCKS */
} cg_window;

/* Block store and scratch for the grid g (kept by pointer). */
ekm_status cg_window_alloc(cg_window *fz, const cg_grid *g, ekm_error *err);
void cg_window_free(cg_window *fz);

/* Add one snapshot's primary sums (CG_NPRIM x n). */
void cg_window_add(cg_window *fz, const double *prim);

/* Close the window: mean fields and their standard errors, appended to r
 * (d: mean particle diameter [m], rho_p: material density [kg/m^3] or 0,
 * as cg_profile_derive); the window is emptied for the next one. */
ekm_status cg_window_finish(cg_window *fz, cg_window_results *r, double t_mid, double d, double rho_p,
                            ekm_error *err);

void cg_window_results_free(cg_window_results *r);

#endif
