/* point.h: the EKM state one campaign point is compared at, by the one
 * steady policy of ekmbench, for callers that run the EKM in-process (the
 * calibration, calibrate/fit_scen.c) and the campaign's agreement test
 * (`ekm agree`, scripts/campaign/ekm_step.sh).
 *
 * The policy. A scenario that runs to its steady state ([run] stop =
 * steady) is solved by Newton from its initial state (steady_solve.h, `ekm
 * steady`; a local rheology, mu_i: local_slab.h's steady solve, and its
 * time stepping below); one the steady solver does not take, or where Newton finds no
 * steady state, is run by time stepping from its initial state (run.h,
 * `ekm run`). With check, the Newton state is also compared with the
 * time-stepped run: a slab can have more than one steady state, and the
 * one compared with the DEM is the one the initial state flows to. The
 * Newton state is kept when the run ended steady and the two agree
 * (ekm_point_agreement <= EKM_POINT_AGREE_TOL); otherwise the run's state
 * is the point's. Any other scenario is run by time stepping.
 *
 * Agreement: the largest of max |A - B| / max |B| over phi (the column),
 * vx, T and P (the cells where both have material, phi >= EKM_POINT_SUPPORT
 * x the run's largest phi: the scores' common support, docs/compare.md)
 * and the gap (a pressure-held wall), B the run's. 5e-2: the run stops at
 * its own steady test, 1.1e-2 short of the fixed point on the chute at 24
 * degrees.
 */
#ifndef EKM_POINT_H
#define EKM_POINT_H

#include <stddef.h>

#include "model.h"
#include "scenario.h"
#include "status.h"

#define EKM_POINT_AGREE_TOL 5e-2
#define EKM_POINT_SUPPORT   0.1

/* One state's profiles at its cell centres, as ekm writes them (fields.h). */
typedef struct {
    size_t n;
    const double *phi, *vx, *T, *P; /* [-], [m/s], [m^2/s^2], [Pa] */
    double gap;                     /* the gap of a pressure-held wall [m], NAN: none */
} ekm_point_view;

/* The agreement measure above of state a against the run's state b (the
 * same n); *field (may be NULL) names the field of the largest difference
 * ("phi", "vx", "T", "P", "gap", or "support" when no cell has material in
 * both: then INFINITY). */
double ekm_point_agreement(const ekm_point_view *a, const ekm_point_view *b, const char **field);

typedef enum { EKM_POINT_NEWTON = 1, EKM_POINT_RUN = 2 } ekm_point_solver;

/* The point's state: its profiles (owned) and how it was made. */
typedef struct {
    size_t n;
    double *z;                      /* cell centres of the state's grid [m] */
    double *phi, *vx, *T, *P, *sxz; /* [-], [m/s], [m^2/s^2], [Pa], [Pa] */
    ekm_point_solver solver;        /* which state it is */
    int checked;                    /* 1: Newton's state was compared with a run */
    int run_steady;                 /* (checked) the run ended steady */
    double agreement;               /* (checked) ekm_point_agreement of the two [-] */
} ekm_point;

/* The point's state of scenario sc at material m (checked as a scenario
 * file's [material] would be: a material the scenario refuses is
 * EKM_EINPUT; sc itself is not changed), by the policy above; check:
 * compare Newton's state with a run. Fills *p (ekm_point_free, also after
 * a failure); a failed solve returns its status. */
ekm_status ekm_point_solve(const ekm_scenario *sc, const ekm_material *m, int check, ekm_point *p,
                           ekm_error *err);
void ekm_point_free(ekm_point *p);

#endif
