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
 * The switch counts and the first failure are kept in the stepper
 * (to_solid, to_flow, jump_max, fail_*).
 */
#ifndef EKM_REGIME_H
#define EKM_REGIME_H

#include "bc.h"
#include "state.h"
#include "step.h"

/* Before the step: the old state's rates (the lagged ||kappa||) and which
 * faces carry a rate-law shear stress.  Returns the number of solid cells. */
int ekm_regime_begin(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt);

/* The rates the solid step lags its norm on (u'^2 and w' at cells, u' at
 * faces) from the velocities of s; dry marks the cells without shear. */
void ekm_regime_lagged_rates(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb,
                             const ekm_bc_face *bt, const unsigned char *dry);

/* Phase 4 for solid cells: the prepared rate-law step of each (st->hyp);
 * the normal solve sees its stress as P = -E_zz, its stiffness as mu_n = V_zz. */
void ekm_regime_properties(ekm_stepper *st, const ekm_state *s, double dt);

/* Phase 6 coefficients of every face: tau_f = kface_f (jump of u) + t0face_f. */
void ekm_regime_shear_faces(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                            double dt);

/* After the solves: the new stresses of the solid cells and faces. */
void ekm_regime_finish(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt);

/* Phase 9 (after an accepted step): the flow face stresses and the
 * per-cell switches flow <-> solid. */
void ekm_regime_switch(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt);

#endif
