/* solver2d.h: the EKM in 2D (x horizontal, z vertical, plane strain) on a
 * PETSc DMStag staggered grid, integrated in time by PETSc TS with a fully
 * implicit method, nonlinear systems by SNES (docs/model.md, "2D solver").
 *
 * Grid: nx x nz cells of dx = width/nx by dz = length/nz; the scalars phi
 * and T at cell centres (DMSTAG_ELEMENT), vx on the x-faces (DMSTAG_LEFT),
 * vz on the z-faces (DMSTAG_DOWN), the shear stress at the corners: the 1D
 * solver's grid (state.h) in each column, so that a run that is uniform in
 * x has the 1D solver's discrete steady equations (steady_solve.h).
 *
 * The discrete equations (method of lines, F(t, U, dU/dt) = 0):
 *   cells, mass:    dphi/dt + div F = 0, F = v phi_upwind on every face
 *                   (flux form: mass changes only through the boundaries)
 *   cells, T:       rho (dT/dt + upwind v.grad T) = 2/3 (div(lambda grad T)
 *                   + eta s2 + zeta div^2) - rho eps T  (model.h's
 *                   ekm_temperature_source_coeffs_plane); lambda at faces the
 *                   harmonic mean of the two cells, zero flux at the sides
 *   faces, momentum: rho_f (dv/dt + upwind v.grad v) = div sigma + rho_f g,
 *                   sigma from ekm_stress_plane at cells and eta (dvx/dz +
 *                   dvz/dx) at corners with the harmonic mean of the corner's
 *                   cells' eta (1D: of the face's two cells), rho_f the mean
 *                   of the face's two cells
 * Empty cells (phi < phi_dry at the start of the step) have no stress and
 * T = T_floor; a face between two empty cells (mean phi < phi_dry) has
 * v = 0 (the 1D solver's rules).  The bound 0 <= phi < phi_cp: the
 * residual is not finite at a state outside it (and at T <= 0 in a
 * non-empty cell), so Newton's line search backs off and a step that cannot
 * converge is retried shorter by TS; accepted states are inside the bound.
 *
 * Boundaries: bottom and top from [bottom] / [top]: wall (no slip or
 * Navier slip, adiabatic), free (zero stress, nothing enters, vz follows
 * the interior), inflow (w, phi, u, T over the whole top or bottom until
 * t_stop, then a resting wall); x periodic ([domain] periodic_x = 1) or
 * frictionless walls at x = 0 and x = width.
 */
#ifndef EKM2D_SOLVER2D_H
#define EKM2D_SOLVER2D_H

#include <mpi.h>

#include "out2d.h"
#include "scenario.h"
#include "state.h"
#include "status.h"

typedef struct ekm2d_solver ekm2d_solver;

/* What a scenario needs that the 2D solver does not have yet: EKM_EUNAVAILABLE
 * naming the key; a bad 2D scenario: EKM_EINPUT naming the key. */
ekm_status ekm2d_supported(const ekm_scenario *sc, ekm_error *err);

/* Create the solver on comm with the initial state of sc, or (init not
 * NULL) with the 1D state init (sc's cells and length) in every column;
 * PETSc options (-ts_*, -snes_*, -ksp_*, -pc_*) override its defaults. */
ekm_status ekm2d_solver_create(const ekm_scenario *sc, MPI_Comm comm, const ekm_state *init,
                               ekm2d_solver **out, ekm_error *err);
void ekm2d_solver_destroy(ekm2d_solver *s);

/* Advance to time t_to [s] (collective).  EKM_ENUMERIC with a diagnostic
 * when TS cannot (the step fell below dt_min, SNES never converged). */
ekm_status ekm2d_solver_advance(ekm2d_solver *s, double t_to, ekm_error *err);

/* The output fields (out2d.h order) on the cells, gathered to rank 0 into
 * fields[k] (nz * nx doubles each, x fastest; ignored on other ranks). */
ekm_status ekm2d_solver_fields(ekm2d_solver *s, double *const fields[EKM2D_NFIELDS], ekm_error *err);

typedef struct {
    double t;            /* model time [s] */
    long steps;          /* accepted time steps */
    long rejected;       /* rejected steps (TS's retries) */
    long newton;         /* SNES iterations */
    double mass;         /* sum rho_p phi dx dz per unit depth [kg/m] */
    double mass_in;      /* net mass entered through the boundaries per unit depth [kg/m] */
    double phi_max;      /* largest phi [-] */
    double cell_updates; /* accepted steps x cells */
    long to_solid;       /* switches flow -> solid (solid regime) */
    long to_flow;        /* switches solid -> flow */
} ekm2d_stats;

/* The run's statistics so far (the mass is a reduction over the ranks:
 * collective); EKM_EINTERNAL on a PETSc error. */
ekm_status ekm2d_solver_stats(ekm2d_solver *s, ekm2d_stats *out, ekm_error *err);

#endif
