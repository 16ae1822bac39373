/* step2d_impl.h: the semi-implicit 2D stepper's data, shared by its phases
 * (step2d.c: the step; velocity2d.c: the velocity system; temperature2d.c:
 * the temperature Newton).  Not a public header.
 *
 * Work arrays span this rank's ghosted box (grid2d.h, ekm2d_box_index):
 * a cell's entry is at its (i, j), an x-face's and a z-face's at theirs,
 * a corner's at its lower left cell's.  A phase fills them wherever its
 * inputs are in the box (the state's ghosts are two cells wide), so that
 * every row this rank owns finds its neighbours' values.
 */
#ifndef EKM2D_STEP2D_IMPL_H
#define EKM2D_STEP2D_IMPL_H

#include <petscksp.h>

#include "grid2d.h"
#include "hypo.h"
#include "model.h"
#include "step2d.h"

/* The largest growth of the step from one step to the next (control2d.c). */
#define EKM2D_GROWTH 1.5

struct ekm2d_step {
    ekm2d_grid g;
    const ekm_scenario *sc;
    Vec U;      /* the state (global, dm) */
    Vec U_back; /* the state at the start of the step */
    Vec Ul;     /* local (ghosted) copy of U during a step */
    Vec W, Wl;  /* a global and a local vector of dm for exchanges */
    Mat A;      /* the velocity system (dmv) */
    Vec V, Vb;  /* its solution and right-hand side (global, dmv) */
    Vec Vl;     /* the solution, local */
    KSP ksp_v;
    int v_keep_factor; /* 1: the next velocity solve keeps the LU factorisation */
    long v_refactors;  /* solves that failed with a kept factorisation */
    Mat J;             /* the temperature Newton's Jacobian (dmt) */
    Vec dT, R;         /* its update and the negative residual (global, dmt) */
    Vec Tn, Tl;        /* the iterate (global) and its local copy */
    Vec Rl;            /* a local vector of dmt (the residual, then the update) */
    KSP ksp_t;
    int t_keep_factor; /* 1: the next temperature solve keeps the LU factorisation */
    long t_refactors;  /* solves that failed with a kept factorisation */
    /* box arrays */
    double *Fx, *Fz;           /* face volume fluxes of the step [m/s] (x-faces, z-faces) */
    double *phi_new;           /* phi* after the mass update [-] */
    double *rhoT;              /* (rho T)* after convection [kg/(m s^2)] */
    double *T_star;            /* T* [m^2/s^2] (0: empty) */
    ekm_cell_properties *prop; /* at (phi*, T*) (zeros: empty) */
    unsigned char *dry;        /* cells: phi* < phi_dry */
    double *K;                 /* dP/dphi at (phi*, T*) [Pa] (0: empty) */
    double *fill;              /* cells: the fill fraction of a surface cell (surface2d.c), else 1 [-] */
    double *rhs_x, *rhs_z;     /* the momentum equations' known parts [kg/(m^2 s)] (faces) */
    double *pu_x, *pu_z;       /* phi the next mass update carries through each face (coupling) [-] */
    double *eta_c;             /* corners: the corner viscosity of the current assembly [Pa s] */
    long *eta_c_stamp;         /* corners: the assembly eta_c was computed in */
    long assembly;             /* the velocity assembly under way (0: none) */
    long assemblies;           /* assemblies so far */
    double *T_it;              /* the temperature iterate [m^2/s^2] */
    double *T_lin;             /* where an iteration linearises (T_it, or a cell's restart) [m^2/s^2] */
    double *T_change;          /* T - T* of the last step (the first Newton iterate) */
    double *upd;               /* |dT| of the last Newton iteration */
    ekm_source_coeffs *src;    /* the temperature source of each cell */
    double dt_change;          /* the step of T_change [s] (0: none) */
    /* the solid regime (regime2d.c); box arrays NULL without [hypo] */
    int n_solid;                     /* solid cells at the step's start, all ranks */
    unsigned char *solid;            /* cells: solid at the step's start */
    unsigned char *solid_c;          /* corners: carry the solid's sxz this step */
    ekm_hypo_plane_rate *rate_old;   /* cells: the rates the law lags its norm on [1/s] */
    ekm_hypo_plane_rate *rate_c_old; /* corners: the same (exx, ezz the mean of the wet cells) */
    ekm_hypo_implicit *hyp, *hyp_c;  /* the prepared law of solid cells and corners */
    double *t0_c;                    /* solid corners: sxz^n xz_scale [Pa] */
    double *T_keep;                  /* solid cells: T at the step's start [m^2/s^2] */
    double *eta_new;                 /* switching: eta at the new state [Pa s] */
    double *sxz_c;                   /* switching: the corners' shear stresses [Pa] */
    long to_solid, to_flow;          /* switches so far (this rank's cells) */
    /* PETSc log events of the phases (-log_view: the cost of a step) */
    PetscLogEvent ev_explicit; /* phases 1-4: boundaries, mass, convection, properties */
    PetscLogEvent ev_v_asm;    /* the velocity system's assembly */
    PetscLogEvent ev_v_solve;  /* its solve */
    PetscLogEvent ev_temp;     /* the temperature Newton (assembly and solves) */
    PetscLogEvent ev_regime;   /* the solid regime's phases (regime2d.c) */
    /* the step */
    ekm2d_end bottom, top;  /* the ends at the start of the step */
    double g_x, g_z;        /* gravity [m/s^2] */
    double t;               /* [s] */
    int monitor;            /* -ekm_step_monitor: print each rejection */
    double dt_prev;         /* the last accepted step (0: none yet) [s] (control2d.c) */
    double dt_solid;        /* the solid regime's next step from the last step's lag error (regime2d.c:
                             * ekm2d_regime_lag_error; INFINITY: no limit) [s] */
    double dt_solid_floor;  /* the acoustic step of the solid cells at the step's start, all ranks
                             * (INFINITY: none) [s] (control2d.c) */
    double solid_lag_max;   /* the largest lag error of an accepted step above dt_solid_floor [-] */
    long solid_floor_steps; /* accepted steps at dt_solid_floor with an error above solid_lag_tol */
    long steps, rejected;
    double mass_in;    /* [kg/m] */
    double gap_rate;   /* a moving top wall: its speed dL/dt this step [m/s] */
    double dz_start;   /* ... dz at the step's start [m] (restored by a rejection) */
    double dz_new;     /* ... dz after the step [m] (no moving wall: dz) */
    int newton;        /* iterations of the last temperature solve */
    long newton_total; /* ... of every accepted step */
    char reason[600];
};

/* Return EKM_EINTERNAL naming `what` when a PETSc call fails (in a
 * function with an ekm_error *err). */
#define PTRY(call, what)                                                               \
    do {                                                                               \
        if ((call) != 0)                                                               \
            return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error in %s", (what)); \
    } while (0)

/* Access to a box array at (i, j). */
#define BOX(st, arr, i, j) ((st)->arr[ekm2d_box_index(&(st)->g, (i), (j))])

/* The volume flux F = v phi_up [m/s] through x-face (i, j) of the state u
 * (dm's local array): upwind by the sign of v, 0 at v = 0 (flux.h) and
 * through a side wall. */
static inline double ekm2d_flux_x(const ekm2d_grid *g, PetscScalar ***u, PetscInt i, PetscInt j)
{
    if (ekm2d_side_face(g, i))
        return 0.0;
    const double v = u[j][i][g->s_vx];
    return v == 0.0 ? 0.0 : v * (v > 0.0 ? u[j][i - 1][g->s_phi] : u[j][i][g->s_phi]);
}

/* ... through z-face (i, j) (along +z), relative to the face (a moving
 * top wall: face j moves at j w_grid, the walls carry none); an end face
 * carries its inlet's phi_in when the flow enters (times the face's
 * covered fraction: ekm2d_inlet_phi; nothing beside the inlet), its cell's
 * phi when it leaves. */
static inline double ekm2d_flux_z(const ekm2d_grid *g, const ekm2d_end *bottom, const ekm2d_end *top,
                                  PetscScalar ***u, PetscInt i, PetscInt j)
{
    if (g->top_moving) {
        if (j == 0 || j == g->nz)
            return 0.0;
        const double v = u[j][i][g->s_vz] - j * g->w_grid;
        return v == 0.0 ? 0.0 : v * (v > 0.0 ? u[j - 1][i][g->s_phi] : u[j][i][g->s_phi]);
    }
    const double v = u[j][i][g->s_vz];
    if (j == 0)
        return v * (v > 0.0 ? ekm2d_inlet_phi(g, bottom, i) : u[0][i][g->s_phi]);
    if (j == g->nz)
        return v * (v < 0.0 ? ekm2d_inlet_phi(g, top, i) : u[j - 1][i][g->s_phi]);
    return v == 0.0 ? 0.0 : v * (v > 0.0 ? u[j - 1][i][g->s_phi] : u[j][i][g->s_phi]);
}

/* Which box points step2d.c's phase 2 (mass) reaches: an x-face's flux needs both cells
 * beside it (a side-wall face carries none), a z-face's both cells or its
 * end's; a cell's new phi its four faces. */
static inline int ekm2d_fx_ok(const ekm2d_grid *g, PetscInt i)
{
    return i < g->gx0 + g->gnx && (ekm2d_side_face(g, i) || i > g->gx0);
}

static inline int ekm2d_fz_ok(const ekm2d_grid *g, PetscInt j)
{
    return j < g->gz0 + g->gnz && (j == 0 || j == g->nz || j > g->gz0);
}

static inline int ekm2d_cell_ok(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return ekm2d_cell_exists(g, i, j) && i >= g->gx0 && j >= g->gz0 && ekm2d_fx_ok(g, i) &&
           ekm2d_fx_ok(g, i + 1) && ekm2d_fz_ok(g, j) && ekm2d_fz_ok(g, j + 1);
}

/* surface2d.c: with [numerics] surface_fill, a partly filled surface cell's
 * properties are those of the dense material filling part of it (after
 * phase 4 has set every cell's own); st->fill its fill fraction (1 elsewhere). */
void ekm2d_surface_properties(ekm2d_step *st);

/* The cell-mean properties of cell (i, j) for its normal stress in the
 * velocity system (phase 5, after phase 4 has set st->prop and st->fill
 * at phi*; model.h's ekm_stress_plane): a surface cell's eta is the material's
 * (its corners lie in the material: surface2d.c), its cell mean f eta, as
 * mu_n and zeta are; with eta unscaled the full variant's lam = mu_n -
 * 2 eta would fall below -mu_n, a normal viscous stress that feeds a
 * compression instead of resisting it. */
static inline ekm_cell_properties ekm2d_cell_mean_properties(const ekm2d_step *st, PetscInt i, PetscInt j)
{
    ekm_cell_properties p = BOX(st, prop, i, j);
    p.eta *= BOX(st, fill, i, j);
    return p;
}

/* Phase 5: assemble and solve the velocity system; the new vx, vz into
 * u's face slots (u: dm's local array, ghosts included after the
 * solve).  1: solved; 0: the solve failed (st->reason), the step is
 * rejected; -1: an error (err). */
int ekm2d_velocity_solve(ekm2d_step *st, PetscScalar ***u, double dt, ekm_error *err);

/* Phase 6: the temperature of the step by Newton into u's T slots
 * (ghosts included).  1, 0 (not converged: st->reason), -1 (err). */
int ekm2d_temperature_solve(ekm2d_step *st, PetscScalar ***u, double dt, ekm_error *err);

/* Shear rate dvx/dz + dvz/dx at corner (i, j) [1/s] of the velocities in
 * u and (eta not NULL) its viscosity [Pa s] (the harmonic mean of its wet cells' eta; on
 * a wall the slip rate over dz/2 + slip_length): *has = 0 where the
 * corner carries none (a free end, beside an inlet face or an empty cell,
 * the box's corners). */
double ekm2d_corner_rate(const ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j, double *eta,
                         int *has);

/* The squared shear rate of cell (i, j) [1/s^2]: the mean square of its
 * corners' that carry one (ekm2d_corner_rate; 0 if none), the 1D cell's
 * u'^2 (step.h: ekm_step_shear_rates). */
double ekm2d_cell_shear2(const ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j);

/* The most GMRES iterations with a kept LU factorisation before it is
 * made anew (one rank). */
#define EKM2D_REFACTOR_ITS 15

/* From this many cells the velocity system is solved by GMRES with
 * BoomerAMG (setup2d.c), below by a kept LU (one rank) or GMRES with block
 * Jacobi (several ranks).  The 112 x 56 pile (6272 cells) ran 2.0x faster
 * with the kept LU (docs/model/twod.md "Linear solvers in 2D"). */
#define EKM2D_AMG_CELLS 16384

/* Solve ksp's system for b into x (collective).  With GMRES + LU (one
 * rank, small grids: setup2d.c) the factorisation is kept across solves while they
 * converge in at most EKM2D_REFACTOR_ITS iterations (*keep); a solve that
 * needs more refactors at the next one, a solve that fails with a kept
 * factorisation is repeated at once with a new one (++*refactors).  *why:
 * the converged reason of the last solve.  Nonzero: a PETSc error. */
PetscErrorCode ekm2d_kept_solve(KSP ksp, int *keep, long *refactors, Vec b, Vec x, KSPConvergedReason *why);

/* The corner viscosity [Pa s] of corner (i, j): the harmonic mean of its
 * cells' eta (eta_box: a box array of them; NULL: the step's properties),
 * beside a solid cell that of its flowing cells only (fields.h's
 * ekm_face_viscosity); cell (oi, oj) counts as flowing with viscosity
 * o_eta (oi = -1: none); 0 next to an empty cell. */
double ekm2d_corner_eta(const ekm2d_step *st, PetscInt i, PetscInt j, const double *eta_box, PetscInt oi,
                        PetscInt oj, double o_eta);

/* The solid regime (regime2d.c).  begin: the flags and lagged rates of the
 * step's start state (returns n_solid, collective); lagged_rates: the
 * rates of the velocities in u (the second momentum pass); properties:
 * the prepared law of the solid cells and corners at phi*; finish: their
 * new stresses into u (owned); vacuum: step.c's vacuum rule on the
 * z-faces after a velocity solve; switch: the regime switches of the
 * accepted state in st->U (collective); relaxation: the law's relaxation
 * rate [1/s] of solid cell (i, j) of the state u (the step limit). */
int ekm2d_regime_begin(ekm2d_step *st, PetscScalar ***u);
void ekm2d_regime_lagged_rates(ekm2d_step *st, PetscScalar ***u);
void ekm2d_regime_properties(ekm2d_step *st, PetscScalar ***u, double dt);
void ekm2d_regime_finish(ekm2d_step *st, PetscScalar ***u);
double ekm2d_regime_lag_error(const ekm2d_step *st, PetscScalar ***u, double dt);
void ekm2d_regime_vacuum(ekm2d_step *st, PetscScalar ***u);
ekm_status ekm2d_regime_switch(ekm2d_step *st, ekm_error *err);

#endif
