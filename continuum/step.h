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
 *   5. normal mom.   pressure gradient and gravity explicit, viscous implicit
 *   6. shear mom.    gravity explicit, viscous implicit
 *   7. temperature   heating from the new gradients, conduction and
 *                    dissipation implicit (Newton)
 *   8. accept        finite state -> t += dt; else the state is restored
 *   9. regimes       ([hypo] enabled) per-cell switching flow <-> solid
 *
 * Solid cells (hypo.h) enter phases 4-7 through their linearly implicit
 * rate law: in the normal solve as a known stress (P = -E_zz) and a
 * viscosity mu_n = V_zz = dt f (A_h + 2 B_h)/(...); in the shear solve
 * through their faces (k = dt f B_h/(...)/dz and a known face stress; a
 * solid face is the material point of sigma_xz: its rate law uses the
 * face's rate and P_Y at the face, phi the mean of the two cells or, at a
 * wall, extrapolated); their T is not evolved and they exchange no heat.
 * After the solves the new stress is E + V * gradient, the one the momentum
 * balance used; at an outflow end the solid edge cell then takes its
 * neighbour's stress (zero gradient).  Gravity (a tilting base) is taken
 * at the end of the step.  A face between a flowing and a solid cell
 * carries the flowing cell's viscosity (ekm_face_viscosity).
 *
 * Switching (phase 9, thresholds in [hypo], docs/model.md):
 *   flow -> solid  phi > phi_co + phi_margin, T < T_ratio Y, and the cell
 *                  compresses (w' < 0, |u'|/sqrt2 <= |w'|) or rests
 *                  (|w'|, |u'| <= rest_rate; near the limit surface,
 *                  f_Y >= -10 yield_tol, only while its rates do not grow);
 *                  stress := the EKM stress
 *   solid -> flow  phi <= phi_co, or f_Y >= -yield_tol while the rate is
 *                  not compression-dominated and the cell's stress equals
 *                  its flow stress (output definitions, fields.h) at the
 *                  quasi-static T of the current rates within jump_tol;
 *                  T := that quasi-static T (below phi_co, where the solid
 *                  has no limit surface: the T that gives the solid's
 *                  sigma_zz, ekm_hypo_flow_T_for_stress)
 *
 * Empty cells (phi < phi_dry) keep their (tiny) mass but have T = u = 0 and
 * no stress; a wet cell's T never falls below T_floor.
 */
#ifndef EKM_STEP_H
#define EKM_STEP_H

#include "flux.h"
#include "hypo.h"
#include "implicit.h"
#include "scenario.h"
#include "state.h"

typedef struct {
    const ekm_scenario *sc;
    ekm_limiter_fn psi;     /* NULL: first-order upwind */
    double g_x, g_z;        /* gravity [m/s^2] */
    int n;
    double *F;              /* face volume flux [m/s], n+1 */
    double *qF;             /* face flux of a cell quantity, n+1 */
    double *phi_new;        /* n */
    double *rhoU, *rhoT;    /* after convection [kg/(m^2 s)], [kg/(m s^2)], n */
    double *T_star;         /* n */
    double *P, *eta, *mu_n, *lambda; /* [Pa], [Pa s], [Pa s], [kg/(m s)], n */
    double *u2, *w2;        /* squared gradients at cells [1/s^2], n */
    double *mom_c;          /* centre momentum fluxes, n */
    ekm_source_coeffs *src; /* temperature source coefficients, n */
    double *rho_face, *rhs_face; /* n+1 */
    double *rhs_cell;       /* n */
    unsigned char *dry, *dry_face; /* n, n+1 */
    ekm_implicit_work *wk;
    ekm_state *backup;      /* state before the step, for rejection */
    /* solid regime */
    ekm_hypo_implicit *hyp; /* the prepared rate-law step of each solid cell, n */
    double *u2_old, *dw_old;/* squared shear rate, w' at the start of the step, n */
    double *du_face_old;    /* u' at faces at the start of the step (lagged norm of solid faces), n+1 */
    double *rate_prev;      /* sqrt(u'^2 + w'^2) of each cell after the previous step [1/s], n */
    double *kface, *t0face; /* shear solve face coefficients, n+1 */
    unsigned char *solid_face; /* n+1 */
    unsigned char *dry_T;   /* cells without a T equation (empty or solid), n */
    double *T_keep;         /* T of solid cells, n */
    double *rhs_face0;      /* face momentum after convection (second pass), n+1 */
    long to_solid, to_flow; /* switches so far */
    double jump_max;        /* largest relative stress jump at a switch [-] */
    double fail_time;       /* time of the first solid -> flow switch [s] (-1: none) */
    double fail_angle;      /* gravity angle then [deg] */
    double fail_fY;         /* f_Y of the failing cell's stress then [-] */
    int fail_cell;          /* the failing cell (-1: none) */
    double fail_phi;        /* its phi (the law's: [hypo] phi_fixed when set) [-] and its stress then [Pa] (sigma_xz: mean of its faces) */
    ekm_hypo_stress fail_stress;
    int newton_iterations;  /* of the last accepted step */
    char reject_reason[512];/* why the last step was rejected */
} ekm_stepper;

ekm_stepper *ekm_step_alloc(const ekm_scenario *sc, ekm_error *err);
void ekm_step_free(ekm_stepper *st);

/* Largest step for the state: cfl dz / max(|w| + c) over the flowing
 * cells, the solid cells' accuracy limit ([numerics] solid_relax_step,
 * never below their own acoustic step), the compression limit and dt_max. */
double ekm_step_max_dt(const ekm_stepper *st, const ekm_state *s);

/* The step to restart from after a change of the driving (an inflow
 * closes, the base starts tilting, a piston reverses): the acoustic step
 * cfl dz / max(|w| + c) over every cell, solid ones included, so that the
 * lagged rates of the solid law follow the new load within a few short
 * steps before the step grows again (at most 1.5x per step). */
double ekm_step_restart_dt(const ekm_stepper *st, const ekm_state *s);

/* Advance s by dt.  *accepted = 0 means the step was rejected (reason in
 * st->reject_reason, s unchanged): retry with a smaller dt.  A non-OK
 * status is a hard failure. */
ekm_status ekm_step_apply(ekm_stepper *st, ekm_state *s, double dt, int *accepted, ekm_error *err);

#endif
