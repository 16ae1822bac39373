/* metric.h: the scoring metric of docs/model-notes.md section 9, as a pure function
 * of the matched points (no files: score.c reads, interpolates and
 * writes).
 *
 * Over the points whose model and DEM values are both finite (`points`):
 *   rel_l2 = sqrt(sum (m - d)^2 / sum d^2)          (NAN if no point or
 *                                                    sum d^2 = 0)
 *   noise  = sqrt(mean over the points with se > floor of ((m - d)/se)^2)
 *            (NAN if there is none; `points_se` of them)
 * with floor = floor_rel x RMS(d) over the points: standard errors at or
 * below it are round-off (a bin one grain crossed once), not noise. Sums
 * run in the order of the points.
 */
#ifndef CG_METRIC_H
#define CG_METRIC_H

#include <stddef.h>

typedef struct {
    size_t points;    /* points compared (both values finite) */
    size_t points_se; /* of which with se > floor */
    double rel_l2;    /* relative L2 error [-], NAN if undefined */
    double noise;     /* noise-normalised error [-], NAN if undefined */
    double se_floor;  /* the floor used [field units] (0 without points) */
} cg_metric;

/* model[i], dem[i], se[i] for n candidate points (se may be NAN or <= 0:
 * such points count in rel_l2 only). */
cg_metric cg_metric_compute(const double *model, const double *dem, const double *se, size_t n,
                            double floor_rel);

#endif
