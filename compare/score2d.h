/* score2d.h: `ekmcompare score2d`: a 2D EKM run (or a second DEM map)
 * against a sand pile's DEM map (docs/compare.md "Scoring a 2D pile").
 *
 * The DEM side is one group of a pile-map file (scripts/dem/pile_map.py,
 * results/sandpile/maps-ref.h5): x [nx], z [nz] (cell centres, z from the
 * plate's top), fields [nz][nx] with their standard errors FIELD_se (over
 * the group's runs) and mask (the pile's interior: away from the plate's
 * layering and the loose surface). Its stresses are compression positive.
 * Or (no --group) an `ekmcompare cg --axes x,z` output (x, z, t, fields
 * [nt][nz][nx] with FIELD_se; with --ensemble the SE over the runs): its
 * last window; its stresses, negative in compression, are negated; it has
 * no mask (no interior region).
 *
 * The model side is either an `ekm run` output of a 2D scenario (x, z,
 * t and fields [nt][nz][nx]: one frame, the last or the one at --time;
 * its stresses, tension positive, are negated to the DEM's sign), or,
 * engine against engine (the standard errors of both added in
 * quadrature), a group of a second pile-map file or a second cg 2D output
 * (its last window, or the one at --time).
 *
 * The model's values are interpolated bilinearly onto the DEM's cell
 * centres (exact where the grids coincide); a DEM centre outside the
 * model's centres is left out. Per field, over two regions:
 *   support   the common support: DEM phi and model phi both above
 *             support x the DEM's largest phi (default CG_SCORE_SUPPORT)
 *   interior  the support and the DEM's mask
 * metric.h's rel_l2 and noise-normalised error.
 */
#ifndef CG_SCORE2D_H
#define CG_SCORE2D_H

#include <stddef.h>
#include <stdio.h>

#include "metric.h"
#include "status.h"

typedef struct {
    const char *dem;         /* pile-map file */
    const char *group;       /* its group, e.g. /liggghts/plain/hopper; NULL: dem is a cg 2D output */
    const char *model;       /* ekm 2D run output, or a second pile-map file */
    const char *model_group; /* NULL: model is an ekm run; else the map group to compare */
    double time;             /* the ekm run's output time [s]; NAN: its last output */
    const char *fields;      /* comma-separated (phi, P, sxx, szz, sxz), or NULL: those of
                                phi,P,sxx,szz,sxz both files have */
    double support;          /* common support threshold, a fraction of the DEM's largest phi */
    int no_noise;            /* 1: the inputs carry no noise estimate (one pile at rest: its time
                                SE is not its pile-to-pile scatter): noise-normalised null */
    const char *json;        /* JSON output path, or NULL */
    const char *dem_sha256;  /* the inputs' SHA-256 digests to record in the */
    const char *ekm_sha256;  /* JSON's "inputs" (score.h's), or NULL (both or neither) */
    FILE *table;             /* markdown table (stdout), or NULL */
} cg_score2d_opts;

cg_score2d_opts cg_score2d_opts_default(void);

enum { CG_SCORE2D_MAX_ROWS = 16 };

typedef struct {
    char field[16];     /* phi, P, sxx, szz or sxz */
    const char *units;  /* "1" or "Pa" */
    const char *region; /* "support" or "interior" */
    cg_metric m;
    size_t left_out; /* DEM cells with material (phi above the threshold) not compared */
} cg_score2d_row;

/* Score o->model against o->dem; rows[0..*nrows-1] (may be NULL) the
 * results, two per field (support, interior); writes the table and the
 * JSON. EKM_EUSAGE bad options; EKM_EINPUT a file of the wrong kind, a
 * missing group, field or output time, grids that share no point;
 * EKM_EIO unreadable files or an output that would overwrite an input. */
ekm_status cg_score2d(const cg_score2d_opts *o, cg_score2d_row *rows, size_t *nrows, ekm_error *err);

#endif
