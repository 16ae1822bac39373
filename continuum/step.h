/* step.h: one time step of the EKM slab solver, as a fixed sequence of
 * phases (operator splitting, first order in time):
 *
 *   1. boundaries    face data of both ends at time t (bc.h)
 *   2. mass          face volume fluxes F = w phi_face (upwind or TVD);
 *                    phi* = phi - dt/dz dF, exactly conservative; the step
 *                    is rejected if phi* < 0 or if one step would close more
 *                    than phi_step_max of the gap to phi_cp in any cell, so
 *                    phi < phi_cp holds by construction
 *   3. convection    (rho u)*, (rho T)* with the same fluxes; face momentum
 *                    with the cell-centre fluxes (flux.h)
 *   4. properties    T* = (rho T)* / rho, eta, mu_n, lambda, P at (phi*, T*)
 *   5. normal mom.   gravity explicit, viscous implicit; the pressure
 *                    gradient implicit, linearised in the next mass update
 *                    ([numerics] normal_coupling = implicit, implicit.h),
 *                    or explicit at (phi*, T*) (= explicit)
 *   6. shear mom.    gravity explicit, viscous implicit
 *   7. temperature   heating from the new gradients, conduction and
 *                    dissipation implicit (Newton)
 *   8. accept        finite state -> t += dt; else the state is restored
 *   9. regimes       ([hypo] enabled) per-cell switching flow <-> solid
 *
 * Solid cells and the switching between the regimes (phases 4-7 and 9):
 * regime.h.  The step size, and where a step must end: control.h; the
 * loop that retries a rejected step with half of it: run.h.  Gravity (a
 * tilting base) is taken at the end of the step.
 *
 * A pressure-controlled top wall (bc.h) moves the top face at dL/dt: the
 * grid stretches uniformly (z = zeta L(t), every cell L/n), the faces move
 * at w_g = zeta dL/dt, phases 2-3 use the fluxes relative to them,
 * F = (w - w_g) phi_face, and conserve the content of each cell,
 * (phi dz)' = phi dz - dt dF (likewise rho u, rho T, the face momentum);
 * the new dz then holds for phases 4-9.  Other runs take the fixed-grid
 * arithmetic unchanged.
 *
 * Empty cells (phi < phi_dry) keep their (tiny) mass but have T = u = 0 and
 * no stress; a wet cell's T never falls below T_floor.
 */
#ifndef EKM_STEP_H
#define EKM_STEP_H

#include "bc.h"
#include "flux.h"
#include "implicit.h"
#include "regime.h"
#include "scenario.h"
#include "state.h"

typedef struct {
    const ekm_scenario *sc;
    ekm_limiter_fn psi; /* NULL: first-order upwind */
    double g_x, g_z;    /* gravity [m/s^2] */
    int n;
    double *F;                       /* face volume flux [m/s], n+1 */
    double *qF;                      /* face flux of a cell quantity, n+1 */
    double *phi_new;                 /* n */
    double *rhoU, *rhoT;             /* after convection [kg/(m^2 s)], [kg/(m s^2)], n */
    double *T_star;                  /* n */
    double *P, *eta, *mu_n, *lambda; /* [Pa], [Pa s], [Pa s], [kg/(m s)], n */
    double *u2, *w2;                 /* squared gradients at cells [1/s^2], n */
    double *mom_c;                   /* centre momentum fluxes, n */
    ekm_source_coeffs *src;          /* temperature source coefficients, n */
    double *rho_face, *rhs_face;     /* n+1 */
    double *rhs_cell;                /* n */
    unsigned char *dry, *dry_face;   /* n, n+1 */
    ekm_implicit_work *wk;
    ekm_state *backup;       /* state before the step, for rejection */
    ekm_regime_work regime;  /* the solid regime's arrays and switch counts (regime.h) */
    ekm_regime_flow flow;    /* this stepper's arrays as the solid regime sees them */
    double *rhs_face0;       /* face momentum after convection (second pass), n+1 */
    int moving;              /* 1: pressure-controlled top wall, the grid stretches */
    double gap_rate;         /* dL/dt of this step [m/s] (moving) */
    double dz_new;           /* cell height at the end of this step [m] (moving) */
    int newton_iterations;   /* of the last accepted step */
    char reject_reason[512]; /* why the last step was rejected */
    long rejected_phi;       /* steps rejected by the phi bound (phase 2) so far */
    /* implicit pressure coupling of the normal solve ([numerics] normal_coupling, implicit.h) */
    double *dP_dphi;         /* dP/dphi at (phi*, T*) [Pa], n */
    double *phi_coupled;     /* phi the next mass update carries through each face [-], n+1 */
    double *g_cell, *Y_cell; /* density factor g [-] and yield temperature Y [m^2/s^2] at phi*, n */
    /* the first Newton iterate of the temperature (phase 7) */
    double *T_change; /* T - T* of each cell in the last step that solved it [m^2/s^2] (0: none), n */
    double dt_change; /* that step's dt [s] (0: none yet) */
    /* the thermal relaxation rate of the state the last accepted step left
     * (its end-of-step check), for the next step's limit (run.c) */
    int end_rate_valid; /* 1: rate and cell are those of the state after step end_rate_step */
    long end_rate_step; /* s->steps after that step */
    double end_rate;    /* [1/s] */
    int end_rate_cell;
} ekm_stepper;

ekm_stepper *ekm_step_alloc(const ekm_scenario *sc, ekm_error *err);
void ekm_step_free(ekm_stepper *st);

/* Advance s by dt.  *accepted = 0 means the step was rejected (reason in
 * st->reject_reason, s unchanged): retry with a smaller dt.  A non-OK
 * status is a hard failure, described in err (a dt that is not positive
 * and finite: EKM_ENUMERIC). */
ekm_status ekm_step_apply(ekm_stepper *st, ekm_state *s, double dt, int *accepted, ekm_error *err);

#endif
