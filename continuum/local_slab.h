/* local_slab.h: the dense slab solver of a local rheology without a
 * granular temperature: a closure with local_stress and local_phi
 * (law/closure.h; today mu_i), docs/model/closures.md "The slab solver of
 * mu_i".
 *
 * The layer's mass per area M = rho_p phi_init min(layer_height, length)
 * is cut into the material cells j = 0 .. nm - 1 (bottom up) of equal mass
 * dm = M / nm: a Lagrangian grid in the mass coordinate, so mass is
 * conserved exactly and the layer's thickness is a result. nm is
 * [domain] cells times the filled fraction of the domain; the cells above
 * the layer (a free top) are vacuum (phi = 0, u = 0), spread over the rest
 * of the domain, so that the output has the free surface the scores look
 * for.
 *
 * The normal momentum balance is quasi-static (w = 0): the pressure is the
 * top's plus the weight of the material above,
 *
 *   P = P_top + g_n m,    m the mass per area above, g_n = G cos(angle),
 *
 * at every instant (the closure has no equation of state at rest). The
 * volume fraction is slaved to the closure's dilatancy law at the local
 * pressure and shear rate (local_phi; cell j: the mean of the law at its
 * two faces, each at its own P and |du/dz|; a free top cell: its lower
 * face's), which sets each cell's
 * thickness h_j = dm / (rho_p phi_j). The tangential momentum balance
 *
 *   dm du_j/dt = tau_{j+1/2} - tau_{j-1/2} + dm g_x,
 *   tau_f = local_stress(P_f, gdot_f, gdot_min),  gdot_f = (u_above - u_below) / delta_f
 *
 * (delta_f: the distance between the two centres, or between the centre
 * and a wall; a free top carries tau = 0) is integrated by backward Euler,
 * solved by Newton's method (its Jacobian is tridiagonal, symmetric and
 * diagonally dominant, implicit.h) with the cells' phi lagged and updated
 * after each iteration until u and phi have both converged.
 *
 * Boundaries: a no-slip wall at the bottom (resting or moving); at the top
 * a free surface (P_top = 0) or a wall held at a pressure (P_top = its
 * pressure; its speed is its velocity, or [bottom] velocity + shear_rate
 * times the gap, bc.h). Anything else is refused by name
 * (ekm_local_slab_check). [numerics] gdot_min is required.
 *
 * The state (state.h) holds the cell centres z (one per cell, not
 * uniform), phi, u, T = NAN (no temperature), w = 0 and dz = the domain's
 * height over the cells (the gap over the cells with a top wall, as the
 * EKM's: bc.h reads the gap as n dz).
 */
#ifndef EKM_LOCAL_SLAB_H
#define EKM_LOCAL_SLAB_H

#include "fields.h"
#include "run.h"
#include "scenario.h"
#include "state.h"
#include "status.h"

typedef struct ekm_local_slab ekm_local_slab;

/* 1 when sc's closure is a local rheology this solver runs (local_stress
 * and local_phi), 0 when it is the EKM's (the time stepper of step.h). */
int ekm_local_slab_applies(const ekm_scenario *sc);

/* EKM_OK when this solver takes sc (see above); else EKM_EINPUT (a key it
 * needs: gdot_min) or EKM_EUNAVAILABLE (a boundary or option it does not
 * solve), the message naming the file and the key. */
ekm_status ekm_local_slab_check(const ekm_scenario *sc, ekm_error *err);

/* The solver of sc (checked with ekm_local_slab_check); NULL on error. */
ekm_local_slab *ekm_local_slab_alloc(const ekm_scenario *sc, ekm_error *err);
void ekm_local_slab_free(ekm_local_slab *ls);

/* The initial state of sc in s (sc->cells cells): u from [initial]
 * velocity and shear_rate at the initial centres, phi from the dilatancy
 * law at that u. */
ekm_status ekm_local_slab_init(ekm_local_slab *ls, ekm_state *s, ekm_error *err);

/* One backward Euler step of dt [s] from s: *accepted = 1 and s advanced
 * when Newton converged, else *accepted = 0 and s unchanged (the caller
 * halves dt). */
ekm_status ekm_local_slab_step(ekm_local_slab *ls, ekm_state *s, double dt, int *accepted, ekm_error *err);

/* The time loop of run.h (its hooks: frames at 0, every output_dt and the
 * end, the step hook gets st = NULL; [run] stop = steady with
 * steady_stop.h): dt starts at min(1e-4 s, output_dt), grows x1.5 per
 * accepted step up to [numerics] dt_max, and is halved when Newton fails
 * or the step changes u by more than a tenth of max|u| (+ 1e-3 m/s). The
 * statistics of run.h that apply (no regime switches), newton_iterations
 * the step's Newton iterations. */
ekm_status ekm_local_slab_run(ekm_local_slab *ls, ekm_state *s, const ekm_run_hooks *hooks,
                              ekm_run_stats *stats, ekm_error *err);

/* What ekm_local_slab_steady did. */
typedef struct {
    int attempts;         /* steady Newton solves (dt = infinity) tried */
    long warm_steps;      /* backward Euler steps between them */
    double warm_time;     /* model time those stepped [s] */
    int verify_steps;     /* steps of output_dt from the solution */
    double verify_time;   /* model time they stepped [s] */
    double verify_change; /* largest change of u over them, relative to max|u| + 1e-3 m/s, or of phi [-] */
    double wall_s;        /* wall-clock time [s] */
} ekm_local_slab_steady_report;

/* The steady state from s (the initial state, or a guess): the steady
 * equations (the step's with dt = infinity) solved by Newton, tried before
 * every step of a pseudo-transient continuation (backward Euler steps from
 * min(1e-4 s, output_dt), doubled when accepted, halved when not) until one
 * converges, then verified by 10 steps of output_dt, which must change u
 * and phi by less than 1e-6 (relative to max|u| + 1e-3 m/s; phi absolute).
 * EKM_ENOTSTEADY "SOURCE: no steady state: ..." when no solve converges
 * within 400 steps (a chute steeper than the friction's upper bound
 * accelerates for ever) or the verification fails; s is then the last
 * state. On success t and steps are those of the start. */
ekm_status ekm_local_slab_steady(ekm_local_slab *ls, ekm_state *s, ekm_local_slab_steady_report *rep,
                                 ekm_error *err);

/* The largest number of cells whose phi was held at the end of the
 * dilatancy law's range in any accepted step (closure.h local_phi). */
int ekm_local_slab_beyond_max(const ekm_local_slab *ls);

/* The output fields of a state of this solver (fields.h): vx = u, vz = 0,
 * P from the weight above, sxz the mean of the cell's two face stresses
 * (a free top: 0), szz = -P, regime dense flow (empty above the layer). */
void ekm_local_slab_fields(const ekm_scenario *sc, const ekm_state *s, double t, ekm_fields *out);

/* The output fields of a 1D state of sc, whichever solver made it: this
 * solver's (ekm_local_slab_applies) or the EKM's (fields.h). What ekm
 * writes (h5out.c) and what the campaign's points compare (point.c). */
void ekm_slab_fields(const ekm_scenario *sc, const ekm_state *s, double t, ekm_fields *out);

/* Mass per area of a state of this solver, sum rho_p phi_j h_j [kg/m^2]. */
double ekm_local_slab_mass(const ekm_scenario *sc, const ekm_state *s);

#endif
