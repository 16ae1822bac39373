/* steady_stop.h: the steady-state test of a run with [run] stop = steady.
 *
 * At every output time t_k (the check cadence is output_dt) the drift is
 * the largest of the relative changes per unit model time since the
 * previous output t_{k-1} of
 *
 *   phi, vx, T   (T: a closure with a temperature) ||a_k - a_{k-1}||_2 / max(||a_k||_2, floor sqrt(N)) / (t_k
 * - t_{k-1}), L2 over the N cells with material (phi >= phi_dry) at either time; floors 1e-3 (phi), 1e-4 m/s
 * (vx), 1e-8 m^2/s^2 (T), so that a zero profile counts as steady when it stays (near) zero flow rate    Q =
 * sum phi vx dz [m^2/s]: |Q_k - Q_{k-1}| / max(|Q_k|, 1e-4 m/s sum phi dz) / (t_k - t_{k-1})
 *
 * [1/s].  The run is steady once the drift has stayed below steady_tol at
 * every check from steady_time on for at least steady_window; the run then
 * ends (at that output: the last frame is the final state).  Otherwise it
 * ends at t_end with steady = 0; its acceleration is the change of the
 * mass-weighted mean velocity Q / sum(phi dz) over the last steady_window
 * (or the whole run when shorter) [m/s^2].
 */
#ifndef EKM_STEADY_STOP_H
#define EKM_STEADY_STOP_H

#include "scenario.h"
#include "state.h"
#include "status.h"

typedef struct {
    int n;                   /* cells */
    double *phi, *u, *T;     /* profiles at the previous check, n */
    unsigned char *mask;     /* cells with material now or then, n */
    double t_prev;           /* time of the previous check [s], < 0: none yet */
    double Q_prev;           /* flow rate then [m^2/s] */
    double drift;            /* drift at the last check [1/s] (NAN before the second) */
    double steady_since;     /* first check of the current run of drifts below tol [s], NAN: none */
    int steady;              /* 1: steady (held over the window) */
    double steady_time;      /* steady_since when it became steady [s], NAN: never */
    size_t n_hist, cap;      /* mean-velocity history of every check */
    double *hist_t, *hist_v; /* [s], [m/s] */
} ekm_steady_stop;

ekm_status ekm_steady_stop_init(ekm_steady_stop *sd, int n, ekm_error *err);
void ekm_steady_stop_free(ekm_steady_stop *sd);

/* The check at an output time: updates the drift; *stop = 1 when the run
 * is steady (held over steady_window). */
ekm_status ekm_steady_stop_check(ekm_steady_stop *sd, const ekm_scenario *sc, const ekm_state *s, int *stop,
                                 ekm_error *err);

/* d(mean vx)/dt over the last steady_window of checks [m/s^2] (0 with
 * fewer than two checks). */
double ekm_steady_stop_acceleration(const ekm_steady_stop *sd, const ekm_scenario *sc);

#endif
