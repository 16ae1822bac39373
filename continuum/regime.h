/* regime.h: the solid (hypoplastic) regime inside the time step (step.h)
 * and the per-cell switching between flow and solid.
 *
 * Solid cells (hypo.h) enter phases 4-7 of the step through their linearly
 * implicit rate law: in the normal solve as a known stress (P = -E_zz) and
 * a viscosity mu_n = V_zz = dt f (A_h + 2 B_h)/(...); in the shear solve
 * through their faces (k = dt f B_h/(...)/dz and a known face stress; a
 * solid face is the material point of sigma_xz: its rate law uses the
 * face's rate and P_Y at the face, phi the mean of the two cells or, at a
 * wall, extrapolated); their T is not evolved and they exchange no heat.
 * After the solves the new stress is E + V * gradient, the one the momentum
 * balance used; at an outflow end the solid edge cell then takes its
 * neighbour's stress (zero gradient).  A face between a flowing and a solid
 * cell carries the flowing cell's viscosity (ekm_face_viscosity).
 *
 * Switching (phase 9): the rules of switching.h, shared with the 2D
 * solver. A cell turning solid takes the EKM stress; one turning flow the
 * quasi-static T of its current rates (ekm_switch_flow_temperature).
 * The switch counts and the first failure are kept in the regime's work
 * (to_solid, to_flow, jump_max, fail_*), which the stepper holds.
 */
#ifndef EKM_REGIME_H
#define EKM_REGIME_H

#include "bc.h"
#include "hypo.h"
#include "scenario.h"
#include "state.h"
#include "status.h"

/* The solid regime's own arrays (n cells, n+1 faces) and its record of the
 * switches. */
typedef struct {
    ekm_hypo_implicit *hyp;  /* the prepared rate-law step of each solid cell, n */
    double *u2_old, *dw_old; /* squared shear rate [1/s^2], w' [1/s] at the start of the step, n */
    double *du_face_old;    /* u' at faces at the start of the step (lagged norm of solid faces) [1/s], n+1 */
    double *kface, *t0face; /* shear solve face coefficients [Pa s/m], [Pa], n+1 */
    unsigned char *solid_face; /* 1: the face carries a rate-law stress, n+1 */
    unsigned char *dry_T;      /* cells without a T equation (empty or solid), n */
    double *T_keep;            /* T of solid cells [m^2/s^2], n */
    long to_solid, to_flow;    /* switches so far */
    double jump_max;           /* largest relative stress jump at a switch [-] */
    double fail_time;          /* time of the first solid -> flow switch [s] (-1: none) */
    double fail_angle;         /* gravity angle then [deg] */
    double fail_fY;            /* f_Y of the failing cell's stress then [-] */
    int fail_cell;             /* the failing cell (-1: none) */
    double fail_phi; /* its phi (the law's: [hypo] phi_fixed when set) [-] and its stress then [Pa] (sigma_xz:
                        mean of its faces) */
    ekm_hypo_stress fail_stress;
} ekm_regime_work;

/* The time step's per-cell arrays the solid regime reads (sc, dry, phi_new,
 * u2) and sets for its solid cells (P, mu_n, lambda, T_star, eta): step.h's
 * phases 4-9, n each. */
typedef struct {
    const ekm_scenario *sc;
    const unsigned char *dry; /* empty cells */
    const double *phi_new;    /* phi after the mass update [-] */
    const double *u2;         /* squared shear rate of the new velocities [1/s^2] */
    double *P, *mu_n;         /* [Pa], [Pa s] */
    double *lambda;           /* [kg/(m s)] */
    double *T_star;           /* [m^2/s^2] */
    double *eta;              /* [Pa s] */
} ekm_regime_flow;

/* Allocate rw for n cells (no failure recorded yet); ekm_regime_free. */
ekm_status ekm_regime_alloc(ekm_regime_work *rw, int n, ekm_error *err);
void ekm_regime_free(ekm_regime_work *rw);

/* Before the step: the old state's rates (the lagged ||kappa||) and which
 * faces carry a rate-law shear stress.  Returns the number of solid cells. */
int ekm_regime_begin(ekm_regime_work *rw, const ekm_regime_flow *fl, const ekm_state *s,
                     const ekm_bc_face *bb, const ekm_bc_face *bt);

/* The rates the solid step lags its norm on (u'^2 and w' at cells, u' at
 * faces) from the velocities of s; dry marks the cells without shear. */
void ekm_regime_lagged_rates(ekm_regime_work *rw, const ekm_state *s, const ekm_bc_face *bb,
                             const ekm_bc_face *bt, const unsigned char *dry);

/* Phase 4 for solid cells: the prepared rate-law step of each (rw->hyp);
 * the normal solve sees its stress as P = -E_zz, its stiffness as mu_n = V_zz. */
void ekm_regime_properties(ekm_regime_work *rw, const ekm_regime_flow *fl, const ekm_state *s, double dt);

/* Phase 6 coefficients of every face: tau_f = kface_f (jump of u) + t0face_f. */
void ekm_regime_shear_faces(ekm_regime_work *rw, const ekm_regime_flow *fl, const ekm_state *s,
                            const ekm_bc_face *bb, const ekm_bc_face *bt, double dt);

/* After the solves: the new stresses of the solid cells and faces. */
void ekm_regime_finish(ekm_regime_work *rw, const ekm_regime_flow *fl, ekm_state *s, const ekm_bc_face *bb,
                       const ekm_bc_face *bt);

/* Phase 9 (after an accepted step): the flow face stresses and the
 * per-cell switches flow <-> solid. */
void ekm_regime_switch(ekm_regime_work *rw, const ekm_regime_flow *fl, ekm_state *s, const ekm_bc_face *bb,
                       const ekm_bc_face *bt);

#endif
