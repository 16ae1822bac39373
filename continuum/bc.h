/* bc.h: boundary conditions at the two ends of the slab (docs/model-notes.md section 5).
 *
 * Each kind is one function that describes its boundary face for the
 * current state: the normal velocity there (prescribed, or following the
 * adjacent interior face = zero gradient), the phi, u and T carried in when
 * the flow enters, and the tangential wall friction.
 *
 *   wall     w = 0; u: no slip or Navier slip, tau = eta (u_wall - u)/(dz/2 + b)
 *            (b = slip_length); adiabatic (zero heat flux)
 *   inflow   w = w_in; brings phi_in, u_in, T_in; no conduction, no shear;
 *            after t_stop it is a resting wall
 *   outflow  zero gradient of w, phi, u, T; no conduction, no shear
 *   free     open to vacuum: zero gradient of w, nothing enters, zero stress
 *   piston   w = w, w_return alternating each half period (a driven sample);
 *            zero gradient of phi, u, T; no slip
 *
 * A top wall with `pressure` P moves normally (massless wall with
 * relaxation): dL/dt = pressure_rate L (-szz_top - P) / P, szz_top the
 * normal stress of the top cell (fields.h) at the start of the step; the
 * grid stretches uniformly with the gap (step.h), so the steady state has
 * szz = -P at the wall.  With `shear_rate` R as well, its tangential speed
 * is u_bottom + R L(t) at every instant ([bottom] velocity u_bottom, a wall;
 * the scenario reader stores it in the top wall's velocity): the walls
 * impose the shear rate R exactly while the gap follows the pressure.
 */
#ifndef EKM_BC_H
#define EKM_BC_H

#include "scenario.h"
#include "state.h"

typedef enum { EKM_SIDE_BOTTOM = 0, EKM_SIDE_TOP = 1 } ekm_side;

typedef struct {
    int w_follows;           /* 1: w at the face equals w at the adjacent interior face */
    double w;                /* prescribed normal velocity at the face when !w_follows [m/s] */
    double phi_in;           /* volume fraction carried in by an entering flow [-] */
    double u_in;             /* tangential velocity carried in [m/s] */
    double T_in;             /* temperature carried in [m^2/s^2] */
    double wall_conductance; /* 1/(dz/2 + slip_length) for walls, 0: stress-free [1/m] */
    double u_wall;           /* tangential wall velocity [m/s] */
} ekm_bc_face;

/* The face description of boundary `side` at time t. */
ekm_bc_face ekm_bc_evaluate(const ekm_bc *bc, ekm_side side, double t, const ekm_state *s);

/* dL/dt [m/s] of a pressure-controlled top wall for the state s and a step
 * of dt [s] (the top cell's response to the wall is implicit, bc.c). */
double ekm_bc_gap_rate(const ekm_scenario *sc, const ekm_state *s, double dt);

/* The load of one top cell on a pressure-controlled wall, linear in the
 * wall's speed dL/dt: -szz_top = load - stiffness dL/dt / dz (bc.c). */
typedef struct {
    double load;      /* -szz_top at dL/dt = 0 [Pa] */
    double stiffness; /* its response to dL/dt [Pa s] */
} ekm_bc_top_cell;

/* ... of a top cell at (phi, T) (solid: its stress szz [Pa]) whose lower
 * face moves at w_below [m/s], height dz [m], for a step of dt [s]. */
ekm_bc_top_cell ekm_bc_top_cell_load(const ekm_scenario *sc, double phi, double T, int solid, double szz,
                                     double w_below, double dz, double dt);

/* dL/dt [m/s] of a pressure-controlled top wall over n cells of height dz
 * [m] whose top cells' mean load and mean stiffness are `mean` (a 2D
 * box: the means over its columns, the wall moving as one body). */
double ekm_bc_gap_rate_of(const ekm_scenario *sc, ekm_bc_top_cell mean, int n, double dz);

/* Normal velocity at the boundary face given the interior solution. */
double ekm_bc_face_w(const ekm_bc_face *b, ekm_side side, const ekm_state *s);

#endif
