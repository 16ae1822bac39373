/* step2d.h: one semi-implicit time step of the EKM in 2D (x horizontal, z
 * vertical, plane strain), the 1D solver's step (step.h) in two
 * dimensions, phase by phase (docs/model/twod.md "2D solver"):
 *
 *   1. boundaries   the ends' face velocities at the start of the step
 *                   (grid2d.h), gravity at its end
 *   2. mass         explicit, conservative: face volume fluxes F = v phi_up
 *                   (upwind by the sign of v), phi* = phi - dt div F; a
 *                   step that takes a cell below 0 or closes more than
 *                   phi_step_max of its gap to phi_cp is rejected
 *   3. convection   rho T and the face momenta with the same fluxes (the
 *                   face momenta by the mean fluxes of their control
 *                   volumes' sides, as flux.h's centre fluxes)
 *   4. properties   at (phi*, T*): empty cells (phi* < phi_dry), eta, zeta,
 *                   lambda, P, K = dP/dphi (model.h)
 *   5. velocity     vx and vz together, one linear system (velocity2d.h):
 *                   backward-Euler viscous stresses and the pressure
 *                   linearised in the next mass update
 *   6. temperature  Newton on the 5-point system (temperature2d.h)
 *   7. accept       a finite state; the thermal relaxation limit at the end
 *                   of the step (control.h's rule)
 *   8. regimes      with [hypo]: the switches flow <-> solid (regime2d.c)
 *
 * With the solid regime ([hypo] enabled) the solid cells' stresses are
 * the hypoplastic law's, linearly implicit in the velocity system, and
 * the regimes switch after each accepted step (regime2d.c).  A state
 * uniform in x takes the 1D step's values.
 */
#ifndef EKM2D_STEP2D_H
#define EKM2D_STEP2D_H

#include <mpi.h>

#include "scenario.h"
#include "state.h"
#include "status.h"

typedef struct ekm2d_step ekm2d_step;

/* What the semi-implicit step cannot run yet: EKM_EUNAVAILABLE naming the key. */
ekm_status ekm2d_step_supported(const ekm_scenario *sc, ekm_error *err);

/* The stepper of sc on comm (collective), its state the scenario's initial
 * state (init NULL) or the 1D state init in every column. */
ekm_status ekm2d_step_create(const ekm_scenario *sc, MPI_Comm comm, const ekm_state *init, ekm2d_step **out,
                             ekm_error *err);
void ekm2d_step_destroy(ekm2d_step *st);

/* Advance by dt [s] (collective).  *accepted = 0: the step was rejected
 * (the state is the one before it; ekm2d_step_reason says why) and should
 * be retried shorter; a status other than EKM_OK is an error. */
ekm_status ekm2d_step_apply(ekm2d_step *st, double dt, int *accepted, ekm_error *err);

/* Advance to t_to [s] with the step control of control2d.c (collective):
 * steps end at t_to and where the driving changes; EKM_ENUMERIC when the
 * step falls below dt_min. */
ekm_status ekm2d_step_advance(ekm2d_step *st, double t_to, ekm_error *err);

/* Why the last step was rejected. */
const char *ekm2d_step_reason(const ekm2d_step *st);

/* Column i of the state into the 1D state out (n = cells along z), on
 * every rank (collective): phi, T, u = vx of the column's left x-faces,
 * w = vz of its z-faces. */
ekm_status ekm2d_step_column(ekm2d_step *st, int i, ekm_state *out, ekm_error *err);

/* The output fields (out2d.h's order) of the cells, gathered to rank 0
 * into fields[k] (nz * nx doubles each, x fastest; ignored elsewhere). */
ekm_status ekm2d_step_fields(ekm2d_step *st, double *const fields[], ekm_error *err);

typedef struct {
    double t;               /* model time [s] */
    long steps;             /* accepted steps */
    long rejected;          /* rejected steps */
    double mass;            /* sum rho_p phi dx dz [kg/m] */
    double dz;              /* cell size along z [m] (a moving top wall: the gap / cells) */
    double mass_in;         /* net mass entered through the ends [kg/m] */
    int newton;             /* temperature Newton iterations of the last step */
    long newton_total;      /* ... of every accepted step */
    double phi_max;         /* largest phi [-] */
    long to_solid;          /* regime switches flow -> solid so far */
    long to_flow;           /* ... solid -> flow */
    double solid_lag_max;   /* the largest lag error of the solid cells' law (regime2d.c) of an
                             * accepted step longer than their acoustic step [-] */
    long solid_floor_steps; /* accepted steps at that acoustic step with a larger error than
                             * [numerics] solid_lag_tol */
} ekm2d_step_info;

/* The stepper's whole state between two steps, in an order that does not
 * depend on the ranks (a checkpoint: checkpoint2d.h).  values holds, for
 * each element (i, j) of the (nx + 1) x (nz + 1) elements of the state's
 * DMStag (a cell with its left x-face, bottom z-face and lower left
 * corner; the last column and row carry the right and top faces), its
 * dof entries of the state vector and then the temperature change of
 * its cell over the last step (the Newton's first iterate; 0 beside the
 * domain): values[((j * (nx + 1)) + i) * (dof + 1) + k].  Resuming from
 * it continues the run with the same steps: the scalars are those of
 * step2d_impl.h. */
typedef struct {
    int nx, nz, dof;      /* cells along x and z; state entries per element */
    double *values;       /* (nx + 1) (nz + 1) (dof + 1) entries (rank 0 only) */
    double t;             /* [s] */
    double dz;            /* cell size along z [m] */
    double dt_prev;       /* the last accepted step [s] (0: none yet) */
    double dt_solid;      /* the solid regime's next step limit [s] (INFINITY: none) */
    double dt_change;     /* the step of the temperature change [s] (0: none) */
    double mass_in;       /* [kg/m] */
    double solid_lag_max; /* [-] */
    long steps, rejected, newton_total, to_solid, to_flow, solid_floor_steps;
} ekm2d_restart;

/* Gather the state into *out (collective; out->values allocated on rank 0,
 * freed by ekm2d_restart_free). */
ekm_status ekm2d_step_save(ekm2d_step *st, ekm2d_restart *out, ekm_error *err);
/* Set the state from in (collective; in->values read on rank 0, the
 * scalars on every rank): EKM_EINPUT when in's grid is not this one's. */
ekm_status ekm2d_step_load(ekm2d_step *st, const ekm2d_restart *in, ekm_error *err);
void ekm2d_restart_free(ekm2d_restart *r);

/* Statistics (collective: the mass is a reduction). */
ekm_status ekm2d_step_stats(ekm2d_step *st, ekm2d_step_info *out, ekm_error *err);

#endif
