/* score.h: `ekmcompare score`: the EKM against coarse-grained DEM
 * (docs/model-notes.md section 9).
 *
 * The EKM fields (ekm's HDF5: /z, /t, [nt][nz] fields) are interpolated
 * linearly in z and t onto the DEM grid and times (cg HDF5: axis dataset,
 * /t, fields and FIELD_se); the EKM's grid at a time is its /z row of that
 * frame (cg_score_centres: also the older layouts). Over the points
 * both cover (DEM coordinate inside the EKM cell-centre range at that time,
 * DEM time inside the EKM output times, both values finite), per field:
 *   rel_l2 = ||f_EKM - f_DEM|| / ||f_DEM||
 *   noise  = sqrt(mean(((f_EKM - f_DEM) / SE_DEM)^2))
 *            over the points with SE_DEM > 1e-6 RMS(f_DEM) (smaller SEs are
 *            round-off: a bin one grain crossed once)
 * When the second file is itself coarse-grained DEM (engine against engine:
 * it has FIELD_se), SE_DEM is replaced by the two standard errors added in
 * quadrature.
 * With --ekm-time last (or automatically, with a note, when no DEM time is
 * inside the EKM's), every DEM time is compared with the EKM's last output
 * (a steady state).
 */
#ifndef CG_SCORE_H
#define CG_SCORE_H

#include <stddef.h>
#include <stdio.h>

#include "status.h"

typedef struct {
    const char *dem;                  /* cg HDF5 file */
    const char *ekm;                  /* ekm HDF5 file */
    const char *fields;               /* comma-separated list, or NULL for the default */
    const char *json;                 /* JSON output path, or NULL */
    int ekm_last;                     /* 1: compare with the EKM's last output time */
    double shift;                     /* added to the DEM coordinate before comparing [m] */
    double support;                   /* common support: a point counts only where phi >
                                         support x max(DEM phi) on both sides (0: every
                                         point; default CG_SCORE_SUPPORT) */
    const char *scalars;              /* comma-separated scalar names or set names
                                         (scalars.h), or NULL */
    const char *dem_sha256;           /* the inputs' SHA-256 digests (64 hex digits) to */
    const char *ekm_sha256;           /* record in the JSON's "inputs", or NULL (both or neither) */
    struct cg_score_summary *summary; /* free surface and scalars out, or NULL */
    FILE *table;                      /* markdown table (stdout), or NULL */
    FILE *log;                        /* notes, or NULL */
} cg_score_opts;

/* Standard errors at or below this fraction of the DEM field's RMS are
 * round-off (a bin one grain crossed once), not noise: those points are left
 * out of the noise-normalised error. */
#define CG_SCORE_SE_FLOOR 1e-6

/* Default common-support threshold, a fraction of the DEM's largest phi:
 * 10% of a bulk phi of about 0.6 cuts the dilute tail above a free surface
 * (a few saltating grains under the kernel) and keeps the surface layer. */
#define CG_SCORE_SUPPORT 0.1

#define CG_SCORE_MAX_SCALARS 128

cg_score_opts cg_score_opts_default(void);

/* One scalar observable of both sides (scalars.h); NaN: undefined. */
typedef struct {
    char name[48]; /* e.g. flow_rate, bed_height@0.54s */
    const char *units;
    double t; /* DEM time it was taken at [s] */
    double dem, dem_se, model, model_se;
} cg_score_scalar;

/* The free surface (the layer height of scalars.h, at the last DEM time
 * compared) and the scalars. */
typedef struct cg_score_summary {
    double support_phi;   /* the absolute phi threshold (0: none) */
    double t;             /* DEM time of the layer heights [s] */
    double dem_height;    /* [m], DEM coordinate with --shift; NaN: none */
    double model_height;  /* [m] */
    double mean_diameter; /* [m] (the DEM file's, else the model file's), NaN */
    /* the model file's run, when it is an EKM run with [run] stop = steady
     * (its root attributes run.stop, steady, steady_time, steady_drift,
     * steady_acceleration); run_until_steady 0: not such a run */
    int run_until_steady;
    int run_steady;                 /* 1: reached its steady state; 0: ended at t_end */
    double run_steady_time;         /* [s], NaN when not reached */
    double run_steady_drift;        /* relative change per unit time at its end [1/s] */
    double run_steady_acceleration; /* d(flow rate)/dt at its end, run.h [m^2/s^2] */
    size_t nscalars;
    cg_score_scalar scalar[CG_SCORE_MAX_SCALARS];
} cg_score_summary;

/* Per-field result. */
typedef struct {
    char name[32];
    size_t points;          /* points compared */
    size_t points_se;       /* of which with a positive standard error */
    size_t points_left_out; /* covered points off the common support */
    double rel_l2;          /* relative L2 error (NAN if undefined) */
    double noise;           /* noise-normalised error (NAN if undefined) */
    int se_both;            /* 1: the --ekm file had FIELD_se too (a second DEM
                               run): SE = sqrt(SE_dem^2 + SE_other^2) */
    const char *na;         /* NULL: scored; else why the field is n/a ("no temperature":
                               T of a model whose root attribute has_temperature is 0, a
                               closure without one; its numbers NAN, points 0) */
} cg_score_field;

/* The interpolation of `score`, as pure functions (also used by
 * `ekmcompare fit --scenario`, fit_scen.c):
 * cg_score_locate: index i and fraction a in a sorted array x[0..n-1] with
 * x[i] + a (x[i+1]-x[i]) = v (a clipped to [0, 1]); 0 if v is outside
 * [x_0, x_n-1] (1e-12 relative tolerance): the point is not compared.
 * cg_score_interp: the model's value there, linear in z between cells zi
 * and zi+1 (fraction az) of the two output rows r0, r1 (nze values each),
 * then linear in time (fraction at). With --ekm-time last r0 = r1 = the
 * last row and at = 0. */
int cg_score_locate(const double *x, size_t n, double v, size_t *i, double *a);
double cg_score_interp(const double *r0, const double *r1, size_t nze, size_t zi, double az, double at);

/* cg_score_centres: the model's cell centres at the time level of
 * cg_score_interp (rows i0, i1, fraction at) into z[0..n-1], from its /z
 * (zm) by the rule of its layout (docs/output-format.md, docs/compare.md):
 *  - per_frame (an ekm output: /z [nt][n], the centres of each frame):
 *    row i0 + at (row i1 - row i0), linear in time as the fields are;
 *  - else /z is one row [n] for every frame (an ekmcompare cg output, or an
 *    ekm output written before /z had a row per frame): with gap (such an
 *    ekm output of a pressure-held wall, whose /z was its first frame's)
 *    zm gap(t) / gap[0], gap(t) = gap[i0] + at (gap[i1] - gap[i0]); without
 *    (gap NULL) zm itself.
 * Every use of the model's grid in `score` (the field scores, the common
 * support, the free surface, the scalars) goes through this. */
void cg_score_centres(const double *zm, int per_frame, size_t n, const double *gap, size_t i0, size_t i1,
                      double at, double *z);

/* Score; results (up to 16 fields) in res/nres when res != NULL. */
ekm_status cg_score(const cg_score_opts *o, cg_score_field *res, size_t *nres, ekm_error *err);

/* SCORE.json (score_json.c), written with jansson (common/json_out.h).
 *
 * The keys, in this order: dem, ekm (the input paths), time (how the model
 * times were matched), code_version, options (everything that produced the
 * numbers: fields, ekm_time, shift_m, model, se, se_floor_rel_rms, support,
 * support_phi, scalars), free_surface, fields, model_run, scalars, and
 * inputs (each input's path and sha256) when the caller gave the checksums.
 * Reals are printed to 9 significant digits (the options too: give --shift
 * and --support with at most 9); a value that is not finite is null.
 * cg_score_json_write writes o->json atomically. time_mode: "ekm last output" or
 * "interpolated"; scalar_kinds (nkinds): the scalars asked for, sets
 * expanded (scalars.h kinds). */
ekm_status cg_score_json_write(const cg_score_opts *o, const cg_score_field *res, size_t nres,
                               const char *time_mode, const int *scalar_kinds, size_t nkinds,
                               const cg_score_summary *sm, ekm_error *err);

/* 1 when s is a SHA-256 digest as sha256sum prints it (64 hexadecimal digits, lower case). */
int cg_score_is_sha256(const char *s);

#endif
