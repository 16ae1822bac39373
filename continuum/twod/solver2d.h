/* solver2d.h: the EKM in 2D (x horizontal, z vertical, plane strain):
 * the run API that ekm run (run2d.c) and the tests drive, over the
 * semi-implicit step (step2d.h; docs/model/twod.md "The semi-implicit 2D
 * step").
 *
 * Grid (grid2d.h): nx x nz cells of dx = width/nx by dz = length/nz on a
 * PETSc DMStag; phi and T at cell centres, vx on the x-faces, vz on the
 * z-faces, shear stresses at the corners: the 1D solver's grid (state.h)
 * in each column, so that a state uniform in x takes the 1D step's values.
 * Per step (step2d.h): explicit conservative mass and convection, one
 * linear system for vx and vz (velocity2d.c; the solid cells' hypoplastic
 * stresses linearly implicit in it), Newton on the temperature's 5-point
 * system, the regime switches (regime2d.c); the step size from control2d.c.
 *
 * Boundaries: bottom and top from [bottom] / [top]: wall (no slip or
 * Navier slip, adiabatic), free (zero stress, nothing enters, vz follows
 * the interior), inflow (w, phi, u, T over an inlet segment or the whole
 * end, from t_start until t_stop, then a resting wall); x periodic
 * ([domain] periodic_x = 1) or side walls at x = 0 and x = width.
 * PETSc options with the prefixes ekm_v_ (velocity system) and ekm_t_
 * (temperature system) override the linear solvers.
 */
#ifndef EKM2D_SOLVER2D_H
#define EKM2D_SOLVER2D_H

#include <mpi.h>

#include "out2d.h"
#include "scenario.h"
#include "state.h"
#include "status.h"
#include "step2d.h"

typedef struct ekm2d_solver ekm2d_solver;

/* What a scenario needs that the 2D solver does not have yet: EKM_EUNAVAILABLE
 * naming the key; a bad 2D scenario: EKM_EINPUT naming the key. */
ekm_status ekm2d_supported(const ekm_scenario *sc, ekm_error *err);

/* Create the solver on comm with the initial state of sc, or (init not
 * NULL) with the 1D state init (sc's cells and length) in every column. */
ekm_status ekm2d_solver_create(const ekm_scenario *sc, MPI_Comm comm, const ekm_state *init,
                               ekm2d_solver **out, ekm_error *err);
void ekm2d_solver_destroy(ekm2d_solver *s);

/* Advance to time t_to [s] (collective).  EKM_ENUMERIC with a diagnostic
 * when the step falls below dt_min (the last rejection's reason). */
ekm_status ekm2d_solver_advance(ekm2d_solver *s, double t_to, ekm_error *err);

/* The output fields (out2d.h order) on the cells, gathered to rank 0 into
 * fields[k] (nz * nx doubles each, x fastest; ignored on other ranks). */
ekm_status ekm2d_solver_fields(ekm2d_solver *s, double *const fields[EKM2D_NFIELDS], ekm_error *err);

/* The solver's whole state, to resume a run from it with the same steps
 * (step2d.h: ekm2d_restart; collective; out->values on rank 0), and the
 * state set from it (collective; EKM_EINPUT: another grid).  A run resumed
 * at a time it was advanced to (ekm2d_solver_advance's t_to) takes the
 * steps the uninterrupted run takes: each advance starts with fresh
 * factorisations of the linear systems, as a resumed run does. */
ekm_status ekm2d_solver_save(ekm2d_solver *s, ekm2d_restart *out, ekm_error *err);
ekm_status ekm2d_solver_load(ekm2d_solver *s, const ekm2d_restart *in, ekm_error *err);

typedef struct {
    double t;               /* model time [s] */
    long steps;             /* accepted time steps */
    long rejected;          /* rejected steps (retried shorter) */
    long newton;            /* temperature Newton iterations */
    double mass;            /* sum rho_p phi dx dz per unit depth [kg/m] */
    double dz;              /* cell size along z [m] (a moving top wall: the gap / cells) */
    double mass_in;         /* net mass entered through the boundaries per unit depth [kg/m] */
    double phi_max;         /* largest phi [-] */
    double cell_updates;    /* accepted steps x cells */
    long to_solid;          /* switches flow -> solid (solid regime) */
    long to_flow;           /* switches solid -> flow */
    double solid_lag_max;   /* the largest lag error of the solid cells' law of an accepted step
                             * longer than their acoustic step (at most [numerics] solid_lag_tol) [-] */
    long solid_floor_steps; /* accepted steps at that acoustic step with a larger error */
} ekm2d_stats;

/* The run's statistics so far (the mass is a reduction over the ranks:
 * collective); EKM_EINTERNAL on a PETSc error. */
ekm_status ekm2d_solver_stats(ekm2d_solver *s, ekm2d_stats *out, ekm_error *err);

#endif
