/* metric.c: relative L2 and noise-normalised errors (see metric.h). */
#include "metric.h"

#include <math.h>

cg_metric cg_metric_compute(const double *model, const double *dem, const double *se, size_t n,
                            double floor_rel)
{
    cg_metric r;
    double sd2 = 0, se2 = 0, sn2 = 0;
    size_t np = 0, npse = 0;
    for (size_t q = 0; q < n; q++) {
        double e = model[q], d = dem[q];
        if (!isfinite(e) || !isfinite(d))
            continue;
        sd2 += d * d;
        se2 += (e - d) * (e - d);
        np++;
    }
    /* the noise-normalised error uses the points whose standard error is
     * meaningful: SE > floor_rel of the field's RMS (a bin that one grain
     * crossed once has an SE of round-off size, and would swamp it) */
    double floor_se = np ? floor_rel * sqrt(sd2 / (double)np) : 0.0;
    for (size_t q = 0; q < n; q++) {
        double e = model[q], d = dem[q];
        if (!isfinite(e) || !isfinite(d))
            continue;
        double diff = e - d;
        if (isfinite(se[q]) && se[q] > floor_se) {
            npse++;
            sn2 += diff * diff / (se[q] * se[q]);
        }
    }
    r.points = np;
    r.points_se = npse;
    r.rel_l2 = (np && sd2 > 0) ? sqrt(se2 / sd2) : NAN;
    r.noise = npse ? sqrt(sn2 / (double)npse) : NAN;
    r.se_floor = floor_se;
    return r;
}
