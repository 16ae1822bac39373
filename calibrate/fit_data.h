/* fit_data.h: one rheology point of `ekmcompare fit --rheology` from an
 * `ekmcompare cg` output of steady homogeneous simple shear.
 *
 * From the profiles along the axis (one averaging window, every bin
 * filled):
 *   phi, P, |sxz|, T, mu  profile means (plain means over the bins);
 *   their SEs             the mean of the bins' SEs: the bins of one
 *                         window share the same snapshots, and in a
 *                         homogeneous box their fluctuations are largely
 *                         common, so the fully correlated bound is used
 *                         (sqrt(sum se^2)/n, the independent-bin value,
 *                         would be too small by up to sqrt(n));
 *   gdot                  |b| of the least-squares line vx = a + b z
 *                         (unweighted; the bins' vx SEs are not used);
 *   gdot_se               its SE from the scatter about the line,
 *                         sqrt(SS_res/(n-2) / sum (z - zbar)^2).
 * The profile is simple shear when the line explains the vx profile:
 * R^2 = 1 - SS_res/SS_tot >= CG_FIT_MIN_R2 (0.995; a Bagnold chute
 * profile sampled at 8-10 bins has 0.98, a plug 0). Otherwise the file
 * is refused.
 */
#ifndef CG_FIT_DATA_H
#define CG_FIT_DATA_H

#include <stddef.h>

#include "status.h"

#define CG_FIT_MIN_R2   0.995
#define CG_FIT_PATH_MAX 512

/* Observables a residual can be formed of. */
enum cg_fit_field { CG_FIT_P, CG_FIT_SXZ, CG_FIT_T, CG_FIT_MU, CG_FIT_NFIELD };

/* "P", "sxz", "T", "mu". */
const char *cg_fit_field_name(int f);

typedef struct {
    char file[CG_FIT_PATH_MAX];  /* the CG file it came from */
    size_t nbins;                /* bins of the profile */
    double phi, phi_se;          /* volume fraction [-] */
    double gdot, gdot_se;        /* |dvx/dz| [1/s] */
    double r2;                   /* R^2 of the linear vx profile [-] */
    double value[CG_FIT_NFIELD]; /* P [Pa], |sxz| [Pa], T [m^2/s^2], mu [-]; NAN if not read */
    double se[CG_FIT_NFIELD];    /* their standard errors, same units */
    int at_pressure;             /* 1: a pressure-controlled run (--control pressure): the model is
                                  * given P and gdot, and the P residual is that of phi, the response */
} cg_fit_point;

/* The profiles of one window, n bins each (NULL: not available). */
typedef struct {
    size_t n;
    const double *z; /* bin centres along the axis [m] */
    const double *phi, *phi_se;
    const double *vx, *vx_se;
    const double *f[CG_FIT_NFIELD]; /* P, sxz, T, mu */
    const double *se[CG_FIT_NFIELD];
} cg_fit_profiles;

/* Reduce the profiles of `file` to a point; `fields` is a bit mask
 * (1 << CG_FIT_P | ...) of the observables needed (they must be present,
 * finite, with SE > 0). EKM_EINPUT with one line naming the file. */
ekm_status cg_fit_point_from_profiles(const char *file, const cg_fit_profiles *pr, unsigned fields,
                                      cg_fit_point *pt, ekm_error *err);

/* Read `file` (an ekmcompare cg HDF5 output) and reduce it. EKM_EIO when
 * it cannot be opened, EKM_EINPUT when its content is not what is
 * expected. All HDF5 reading of the fit is here. */
ekm_status cg_fit_point_read(const char *file, unsigned fields, cg_fit_point *pt, ekm_error *err);

#endif
