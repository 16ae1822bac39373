/* solver2d.c: the 2D EKM on DMStag + TS + SNES (solver2d.h). */
#include "solver2d.h"

#include <math.h>
#include <petscdmda.h>
#include <petscdmstag.h>
#include <petscts.h>
#include <stdlib.h>
#include <string.h>

#include "fields.h"
#include "hypo.h"
#include "model.h"
#include "step2d.h"
#include "switching.h"

/* Boundary data of one end (bottom or top) at one time. */
typedef struct {
    ekm_bc_kind kind;            /* wall, free or inflow (closed inflow: wall) */
    double w;                    /* prescribed vz [m/s] (wall 0, inflow w) */
    double phi_in;               /* entering phi (inflow) [-] */
    double u_in, T_in;           /* entering vx [m/s] and T [m^2/s^2] (inflow) */
    double u_wall;               /* wall: tangential speed [m/s] */
    double conductance;          /* wall, and an inflow end's wall beside its inlet: 1/(dz/2 + slip_length)
                                  * [1/m]; 0 otherwise */
    PetscInt inlet_lo, inlet_hi; /* inflow: the columns of the inlet's faces, lo..hi */
} end_data;

struct ekm2d_solver {
    /* the flow regimes run on the semi-implicit step (step2d.h; issue 33)
     * unless -ekm_fully_implicit is given; then everything below is unused */
    ekm2d_step *semi;
    const ekm_scenario *sc;
    MPI_Comm comm;
    DM dm;
    TS ts;
    Vec U;            /* the solution (global) */
    Vec U_start;      /* the solution at the start of the current step (global) */
    Vec row_scale;    /* 1 / magnitude of each row's terms at the start of the step (global) */
    Vec row_mag;      /* global: those magnitudes without the time derivative's |U_start| / dt */
    double row_dt;    /* the step the row scales are for [s] (0: none yet) */
    Vec row_age;      /* global: how many steps in a row (this one included) each row has been its
                       * physical equation, not an empty cell's or a dry face's placeholder */
    Vec lte_atol;     /* global: the step error's absolute tolerance of each row (TSSetTolerances) */
    Vec T_unit;       /* global: T_ref at the temperature slots, 1 elsewhere: U holds T / T_ref */
    Vec T_unit_local; /* the same, local */
    Vec dry_local;    /* local, frozen for a step: slot phi of an element 1 when the cell is empty;
                       * slot vx (vz) of a face the side its upwind cell lies on, +1 the lower
                       * index (left, below), -1 the higher */
    Mat J;
    int nx, nz;                        /* cells */
    double dx, dz;                     /* cell sizes [m] */
    int periodic;                      /* 1: periodic in x */
    double side_conductance[2];        /* side walls x = 0, x = width: 1/(dx/2 + slip_length) [1/m] */
    PetscInt inlet_lo[2], inlet_hi[2]; /* bottom, top inflow: the inlet's face columns (lo..hi) */
    double g_x, g_z;                   /* gravity [m/s^2] */
    PetscInt s_phi, s_T, s_vx, s_vz;   /* slots in the local arrays */
    /* ghosted box of this rank (element indices) and the per-cell properties there */
    PetscInt gx0, gz0, gnx, gnz;
    ekm_cell_properties *prop; /* gnx * gnz */
    unsigned char *wet;        /* gnx * gnz: the cell exists and is not empty this step */
    double *mag;               /* NULL, or local: the magnitude of each row's terms (scaling pass) */
    double t_step;             /* time at the start of the step [s] */
    double dt_step;            /* the step's length as it starts (the row scales) [s] */
    long steps, rejected, newton;
    double dt_failed; /* > 0: a step was tried below dt_min, this long [s] */
    double mass_in;   /* [kg/m] */
    /* the solid (hypoplastic) regime ([hypo] enabled; docs/model.md "2D solver") */
    int hypo;                            /* 1: on */
    PetscInt s_sxx, s_syy, s_szz, s_sxz; /* solid stress slots [Pa] (cells; sxz: vertices) */
    Vec regime;             /* global, persistent: slot phi of an element 1 for a solid cell, slot T
                             * its rate at the last switch test [1/s] */
    unsigned char *solid;   /* gnx * gnz, frozen for a step: the cell is solid */
    double *knorm, *ktr;    /* gnx * gnz: the lagged ||kappa|| and |tr kappa| of owned cells [1/s] */
    double *knorm_c;        /* (gnx + 1) * (gnz + 1): the lagged ||kappa|| of owned corners [1/s] */
    double *corner_scratch; /* (gnx + 1) * (gnz + 1): the switch's corner stresses [Pa] */
    long to_solid, to_flow; /* switches so far */
};

/* The most negative phi an accepted step may leave in an empty cell: the
 * round-off of Newton's converged iterate (the discrete upwind equations
 * themselves keep phi >= 0). */
#define EKM2D_PHI_ROUNDOFF 1e-13

#define PCALL(call)                        \
    do {                                   \
        PetscErrorCode pcall_rc_ = (call); \
        if (pcall_rc_)                     \
            return pcall_rc_;              \
    } while (0)

/* The temperature unknowns are T / T_ref with T_ref = [numerics] T_floor,
 * so that every wet cell's unknown is >= 1: the finite-difference Jacobian
 * (MatFDColoring) steps each column by a relative 1.5e-8 of its value only
 * above umin = 1.5e-6 (one threshold for all columns), and a cold bed's T
 * (1e-15..1e-11 in the thesis filling) was stepped by more than itself,
 * leaving Newton linear (docs/model.md "2D solver"). The linear scaling
 * changes neither the equations nor backward Euler; the physics code sees
 * T itself: every local copy of U is brought to T on the way in
 * (to_physical) and back on the way out (to_unknowns). */
static PetscErrorCode to_physical(const ekm2d_solver *s, Vec local)
{
    return VecPointwiseMult(local, local, s->T_unit_local);
}

static PetscErrorCode to_unknowns(const ekm2d_solver *s, Vec local)
{
    return VecPointwiseDivide(local, local, s->T_unit_local);
}

static PetscErrorCode update_row_scale(ekm2d_solver *s, double dt);

/* ---- boundaries ---------------------------------------------------------------------------------- */

/* End `top` (0: bottom, 1: top) at time t: an inflow is open from t_start
 * to t_stop, a resting no-slip wall otherwise; beside its inlet segment
 * the end is a resting no-slip wall too. */
static end_data end_at(const ekm2d_solver *s, int top, double t)
{
    const ekm_bc *bc = top ? &s->sc->top : &s->sc->bottom;
    end_data e = {0};
    e.kind = bc->kind;
    if (bc->kind == EKM_BC_INFLOW && (t < bc->t_start || t >= bc->t_stop))
        e.kind = EKM_BC_WALL; /* closed: a resting wall */
    if (e.kind == EKM_BC_WALL || e.kind == EKM_BC_INFLOW) {
        e.u_wall = bc->kind == EKM_BC_WALL ? bc->velocity : 0.0;
        e.conductance = 1.0 / (0.5 * s->dz + (bc->kind == EKM_BC_WALL ? bc->slip_length : 0.0));
    }
    if (e.kind == EKM_BC_INFLOW) {
        e.w = bc->w;
        e.phi_in = bc->phi;
        e.u_in = bc->u;
        e.T_in = bc->T;
        e.inlet_lo = s->inlet_lo[top];
        e.inlet_hi = s->inlet_hi[top];
    }
    return e;
}

/* Face column i (a periodic image wrapped) of end e is part of an open inlet. */
static inline int inlet_face(const ekm2d_solver *s, const end_data *e, PetscInt i)
{
    if (e->kind != EKM_BC_INFLOW)
        return 0;
    if (s->periodic)
        i = (i % s->nx + s->nx) % s->nx;
    return i >= e->inlet_lo && i <= e->inlet_hi;
}

/* The prescribed vz on face column i of end e [m/s]: the inflow's w on its inlet, 0 on a wall. */
static inline double end_w(const ekm2d_solver *s, const end_data *e, PetscInt i)
{
    return inlet_face(s, e, i) ? e->w : 0.0;
}

ekm_status ekm2d_supported(const ekm_scenario *sc, ekm_error *err)
{
    const char *src = sc->source;
    if (!(sc->cells_x >= 2))
        return EKM_FAIL(err, EKM_EINPUT, "%s: [domain] cells_x = %d: the 2D solver needs cells_x >= 2", src,
                        sc->cells_x);
    if (sc->cells < 2)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [domain] cells = %d: the 2D solver needs at least 2 cells along z", src,
                        sc->cells);
    if (sc->angle_rate != 0.0)
        return EKM_FAIL(
            err, EKM_EUNAVAILABLE,
            "%s: [gravity] angle_rate = %g: a tilting base is not in the 2D solver yet (issue 14)", src,
            sc->angle_rate);
    if (sc->stop == EKM_STOP_STEADY)
        return EKM_FAIL(err, EKM_EUNAVAILABLE,
                        "%s: [run] stop = steady: the 2D solver stops at t_end only (issue 14)", src);
    if (sc->numerics.convection == EKM_CONVECTION_TVD)
        return EKM_FAIL(err, EKM_EUNAVAILABLE,
                        "%s: [numerics] convection = tvd: the 2D solver is first-order upwind (issue 14)",
                        src);
    const ekm_bc *ends[2] = {&sc->bottom, &sc->top};
    const char *names[2] = {"bottom", "top"};
    for (int k = 0; k < 2; k++) {
        const ekm_bc *bc = ends[k];
        if (bc->kind != EKM_BC_WALL && bc->kind != EKM_BC_FREE && bc->kind != EKM_BC_INFLOW)
            return EKM_FAIL(err, EKM_EUNAVAILABLE,
                            "%s: [%s] type = %s: the 2D solver has wall, free and inflow ends (issue 14)",
                            src, names[k], ekm_bc_kind_name(bc->kind));
        if (bc->kind == EKM_BC_WALL && (isfinite(bc->pressure) || isfinite(bc->shear_rate)))
            return EKM_FAIL(
                err, EKM_EUNAVAILABLE,
                "%s: [%s] pressure: a pressure-controlled wall is not in the 2D solver yet (issue 14)", src,
                names[k]);
    }
    if (sc->bottom.kind == EKM_BC_INFLOW && sc->bottom.w < 0.0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [bottom] w = %g: an inflow through the bottom needs w > 0 [m/s]", src,
                        sc->bottom.w);
    if (sc->top.kind == EKM_BC_INFLOW && sc->top.w > 0.0)
        return EKM_FAIL(err, EKM_EINPUT, "%s: [top] w = %g: an inflow through the top needs w < 0 [m/s]", src,
                        sc->top.w);
    return EKM_OK;
}

/* ---- the discrete equations -------------------------------------------------------------------------- */

typedef struct {
    const PetscScalar ***u;      /* the state, local */
    const PetscScalar ***frozen; /* dry_local's array: empty cells, upwind sides */
    end_data bottom, top;
    const ekm2d_solver *s;
} eval_ctx;

static inline size_t cell_index(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return (size_t)(j - s->gz0) * (size_t)s->gnx + (size_t)(i - s->gx0);
}

/* The cell (i, j) exists (inside the domain, or a periodic image) and is in this rank's ghosted box. */
static inline int cell_exists(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    if (j < 0 || j >= s->nz || j < s->gz0 || j >= s->gz0 + s->gnz || i < s->gx0 || i >= s->gx0 + s->gnx)
        return 0;
    return s->periodic || (i >= 0 && i < s->nx);
}

static inline int is_wet(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return cell_exists(s, i, j) && s->wet[cell_index(s, i, j)];
}

static inline double harmonic(double a, double b)
{
    return a + b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
}

/* The cell (i, j) exists and is solid this step. */
static inline int is_solid(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return s->hypo && cell_exists(s, i, j) && s->solid[cell_index(s, i, j)];
}

static inline size_t corner_index(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return (size_t)(j - s->gz0) * (size_t)(s->gnx + 1) + (size_t)(i - s->gx0);
}

static inline const ekm_cell_properties *props(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return &s->prop[cell_index(s, i, j)];
}

/* x-face i of row j lies on a side wall (no periodic image). */
static inline int side_face(const ekm2d_solver *s, PetscInt i)
{
    return !s->periodic && (i == 0 || i == s->nx);
}

/* The rows of the loop point (i, j) of DMStagGetCorners' range (with its
 * extra points) that exist: a cell's (phi, T), an x-face's (vx), a
 * z-face's (vz). */
static inline int has_cell_rows(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return i < s->nx && j < s->nz && (s->periodic || i >= 0);
}

static inline int has_xface_row(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return j < s->nz && (i < s->nx || !s->periodic);
}

static inline int has_zface_row(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return j <= s->nz && i < s->nx && (s->periodic || i >= 0);
}

/* ... a corner's (sxz, solid regime only) */
static inline int has_vertex_row(const ekm2d_solver *s, PetscInt i, PetscInt j)
{
    return s->hypo && j <= s->nz && (i < s->nx || !s->periodic);
}

/* Face volume flux through x-face (i, j) [m/s] (positive along +x). */
static inline double flux_x(const eval_ctx *c, PetscInt i, PetscInt j)
{
    const ekm2d_solver *s = c->s;
    if (side_face(s, i))
        return 0.0;
    const double v = c->u[j][i][s->s_vx];
    return v * (c->frozen[j][i][s->s_vx] > 0.0 ? c->u[j][i - 1][s->s_phi] : c->u[j][i][s->s_phi]);
}

/* Face volume flux through z-face (i, j) [m/s] (positive along +z). */
static inline double flux_z(const eval_ctx *c, PetscInt i, PetscInt j)
{
    const ekm2d_solver *s = c->s;
    const double v = c->u[j][i][s->s_vz];
    if (j == 0) {
        if (c->bottom.kind == EKM_BC_INFLOW)
            return inlet_face(s, &c->bottom, i) ? c->bottom.w * c->bottom.phi_in : 0.0;
        if (c->bottom.kind == EKM_BC_FREE)
            return v < 0.0 ? v * c->u[0][i][s->s_phi] : 0.0;
        return 0.0;
    }
    if (j == s->nz) {
        if (c->top.kind == EKM_BC_INFLOW)
            return inlet_face(s, &c->top, i) ? c->top.w * c->top.phi_in : 0.0;
        if (c->top.kind == EKM_BC_FREE)
            return v > 0.0 ? v * c->u[j - 1][i][s->s_phi] : 0.0;
        return 0.0;
    }
    return v * (c->frozen[j][i][s->s_vz] > 0.0 ? c->u[j - 1][i][s->s_phi] : c->u[j][i][s->s_phi]);
}

/* The face momentum's control volumes have the mean of the two face
 * fluxes at their sides (the 1D solver's centre fluxes, flux.h): the
 * upwind phi of a face next door is two cells away, so the grid's stencil
 * is two cells wide. */

/* Corner (i, j) carries the solid regime's shear stress (its sxz row):
 * it carries a rate (corner_stress) and every cell beside it that exists
 * is solid (on a wall: the two cells beside it). */
static int corner_is_solid(const eval_ctx *c, PetscInt i, PetscInt j)
{
    const ekm2d_solver *s = c->s;
    if (!s->hypo)
        return 0;
    if (side_face(s, i)) {
        if (j == 0 || j == s->nz)
            return 0;
        const PetscInt ic = i == 0 ? 0 : s->nx - 1;
        return is_solid(s, ic, j - 1) && is_solid(s, ic, j);
    }
    if (j == 0 || j == s->nz) {
        const end_data *e = j == 0 ? &c->bottom : &c->top;
        if (e->kind == EKM_BC_FREE || inlet_face(s, e, i - 1) || inlet_face(s, e, i))
            return 0;
        const PetscInt jc = j == 0 ? 0 : s->nz - 1;
        return is_solid(s, i - 1, jc) && is_solid(s, i, jc);
    }
    return is_solid(s, i - 1, j - 1) && is_solid(s, i, j - 1) && is_solid(s, i - 1, j) && is_solid(s, i, j);
}

/* The viscosity of a corner between two cells a, b of which at least one
 * is solid: the flowing one's (a face between a flowing and a solid cell
 * carries the flowing cell's viscosity, as in 1D: regime.h); 0 if none flows. */
static inline double eta_beside_solid(const ekm2d_solver *s, PetscInt ia, PetscInt ja, PetscInt ib,
                                      PetscInt jb)
{
    if (is_wet(s, ia, ja) && !is_solid(s, ia, ja))
        return props(s, ia, ja)->eta;
    if (is_wet(s, ib, jb) && !is_solid(s, ib, jb))
        return props(s, ib, jb)->eta;
    return 0.0;
}

/* Shear stress and rate at corner (i, j) (x-face index i, z-face index j):
 * *rate = dvx/dz + dvz/dx [1/s], returns sigma_xz [Pa]; *has_rate = 0
 * where the corner carries no rate (a free end, an inlet's face beside
 * it, an empty cell next to it, a corner of the box). On a wall the rate
 * is the slip rate over half a cell plus the slip length (the 1D wall's).
 * A solid corner (corner_is_solid) returns its state's sxz; next to a
 * solid cell a corner takes the viscosity of its flowing cells only. */
static double corner_stress(const eval_ctx *c, PetscInt i, PetscInt j, double *rate, int *has_rate)
{
    const ekm2d_solver *s = c->s;
    *rate = 0.0;
    *has_rate = 0;
    if (side_face(s, i)) {
        if (j == 0 || j == s->nz)
            return 0.0; /* a corner of the box: no velocity beside it moves */
        const PetscInt ic = i == 0 ? 0 : s->nx - 1;
        if (!is_wet(s, ic, j - 1) || !is_wet(s, ic, j))
            return 0.0;
        const double v = c->u[j][ic][s->s_vz];
        *rate = (i == 0 ? v : -v) * s->side_conductance[i == 0 ? 0 : 1];
        *has_rate = 1;
        if (is_solid(s, ic, j - 1) || is_solid(s, ic, j))
            return corner_is_solid(c, i, j) ? c->u[j][i][s->s_sxz]
                                            : eta_beside_solid(s, ic, j - 1, ic, j) * *rate;
        return harmonic(props(s, ic, j - 1)->eta, props(s, ic, j)->eta) * *rate;
    }
    if (j == 0 || j == s->nz) {
        const end_data *e = j == 0 ? &c->bottom : &c->top;
        if (e->kind == EKM_BC_FREE || inlet_face(s, e, i - 1) || inlet_face(s, e, i))
            return 0.0;
        const PetscInt jc = j == 0 ? 0 : s->nz - 1;
        const double v = c->u[jc][i][s->s_vx];
        *rate = (j == 0 ? v - e->u_wall : e->u_wall - v) * e->conductance;
        *has_rate = 1;
        if (is_solid(s, i - 1, jc) || is_solid(s, i, jc))
            return corner_is_solid(c, i, j) ? c->u[j][i][s->s_sxz]
                                            : eta_beside_solid(s, i - 1, jc, i, jc) * *rate;
        const double eta_w = harmonic(is_wet(s, i - 1, jc) ? props(s, i - 1, jc)->eta : 0.0,
                                      is_wet(s, i, jc) ? props(s, i, jc)->eta : 0.0);
        return eta_w * *rate;
    }
    const int wet4 = is_wet(s, i - 1, j - 1) && is_wet(s, i, j - 1) && is_wet(s, i - 1, j) && is_wet(s, i, j);
    if (!wet4)
        return 0.0;
    *rate = (c->u[j][i][s->s_vx] - c->u[j - 1][i][s->s_vx]) / s->dz +
            (c->u[j][i][s->s_vz] - c->u[j][i - 1][s->s_vz]) / s->dx;
    *has_rate = 1;
    const PetscInt cells[4][2] = {{i - 1, j - 1}, {i, j - 1}, {i - 1, j}, {i, j}};
    double inv = 0.0;
    int flowing = 0;
    for (int q = 0; q < 4; q++)
        if (!is_solid(s, cells[q][0], cells[q][1])) {
            inv += 1.0 / props(s, cells[q][0], cells[q][1])->eta;
            flowing++;
        }
    if (flowing == 0)
        return c->u[j][i][s->s_sxz];
    return flowing / inv * *rate; /* the harmonic mean of the flowing cells' eta */
}

/* Rates of strain of cell (i, j): exx, ezz [1/s]. */
static inline void cell_rates(const eval_ctx *c, PetscInt i, PetscInt j, double *exx, double *ezz)
{
    const ekm2d_solver *s = c->s;
    *exx = (c->u[j][i + 1][s->s_vx] - c->u[j][i][s->s_vx]) / s->dx;
    *ezz = (c->u[j + 1][i][s->s_vz] - c->u[j][i][s->s_vz]) / s->dz;
}

/* The mean squared shear rate of the corners of cell (i, j) that carry
 * one [1/s^2] (0 if none does). */
static double mean_corner_shear2(const eval_ctx *c, PetscInt i, PetscInt j)
{
    double sum2 = 0.0;
    int count = 0;
    const PetscInt cn[4][2] = {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}};
    for (int q = 0; q < 4; q++) {
        double rate;
        int has;
        (void)corner_stress(c, cn[q][0], cn[q][1], &rate, &has);
        if (has) {
            sum2 += rate * rate;
            count++;
        }
    }
    return count ? sum2 / count : 0.0;
}

/* Normal stresses of cell (i, j) (empty cells: none). */
static inline ekm_plane_stress cell_stress(const eval_ctx *c, PetscInt i, PetscInt j)
{
    ekm_plane_stress z = {0};
    if (!is_wet(c->s, i, j))
        return z;
    if (is_solid(c->s, i, j)) {
        const PetscScalar *v = c->u[j][i];
        z.sxx = v[c->s->s_sxx];
        z.szz = v[c->s->s_szz];
        z.syy = v[c->s->s_syy];
        z.P = -(z.sxx + z.szz + z.syy) / 3.0;
        return z;
    }
    double exx, ezz;
    cell_rates(c, i, j, &exx, &ezz);
    return ekm_stress_plane(props(c->s, i, j), c->s->sc->variant, exx, ezz);
}

/* The data frozen for a step, from the state u at its start, into fr (a
 * local array of the grid): the empty cells (phi < phi_dry) and each
 * face's upwind side, the side the face velocity comes from (at rest:
 * the fuller cell). The mass fluxes take the upwind phi from the frozen
 * side, so that the discrete equations are smooth in the step's unknowns:
 * with the side following the sign of v, the flux's derivative jumps at
 * v = 0 (phi of one cell or the other), and Newton failed at the edges of
 * a narrow stream, where a face next to an empty cell sits at v ~ 0.
 * Within a step a velocity may turn against its frozen side; the flux is
 * then v times the frozen side's phi, and a step that would take a cell
 * below phi = 0 so is rejected (check_stage). */
static void freeze_step_data(const ekm2d_solver *s, const PetscScalar ***u, PetscScalar ***fr)
{
    const double phi_dry = s->sc->numerics.phi_dry;
    for (PetscInt j = s->gz0; j < s->gz0 + s->gnz; j++)
        for (PetscInt i = s->gx0; i < s->gx0 + s->gnx; i++) {
            if (cell_exists(s, i, j))
                fr[j][i][s->s_phi] = u[j][i][s->s_phi] < phi_dry ? 1.0 : 0.0;
            const int has_w = i - 1 >= s->gx0, has_s = j - 1 >= s->gz0;
            const double vx = u[j][i][s->s_vx], vz = u[j][i][s->s_vz];
            double side = vx > 0.0 ? 1.0 : -1.0;
            if (vx == 0.0 && has_w && j < s->nz)
                side = u[j][i - 1][s->s_phi] >= u[j][i][s->s_phi] ? 1.0 : -1.0;
            fr[j][i][s->s_vx] = side;
            side = vz > 0.0 ? 1.0 : -1.0;
            if (vz == 0.0 && has_s && j < s->nz && j > 0)
                side = u[j - 1][i][s->s_phi] >= u[j][i][s->s_phi] ? 1.0 : -1.0;
            fr[j][i][s->s_vz] = side;
        }
}

/* Properties of every cell of the ghosted box; 0: a non-empty cell is
 * outside 0 < phi < phi_cp, T > 0 (or a value is not finite). */
static int compute_properties(ekm2d_solver *s, const PetscScalar ***u, const PetscScalar ***dry)
{
    const ekm_material *m = &s->sc->material;
    int ok = 1;
    for (PetscInt j = s->gz0; j < s->gz0 + s->gnz; j++)
        for (PetscInt i = s->gx0; i < s->gx0 + s->gnx; i++) {
            const size_t k = cell_index(s, i, j);
            s->wet[k] = 0;
            if (!cell_exists(s, i, j))
                continue;
            const double phi = u[j][i][s->s_phi], T = u[j][i][s->s_T];
            if (!(phi < m->phi_cp) || !isfinite(phi))
                ok = 0;
            /* an empty cell's phi enters only the fluxes: Newton's iterates may
             * take it below 0 (the converged step may not: check_stage) */
            if (dry[j][i][s->s_phi] != 0.0)
                continue;
            if (!(phi > 0.0 && phi < m->phi_cp && T > 0.0 && isfinite(T))) {
                ok = 0;
                continue;
            }
            s->wet[k] = 1;
            s->prop[k] = ekm_cell_properties_at(m, s->sc->variant, phi, T);
        }
    return ok;
}

/* The mean of the existing cells' phi beside corner (i, j) (the phi of
 * its solid stress). */
static double corner_phi(const ekm2d_solver *s, const PetscScalar ***u, PetscInt i, PetscInt j)
{
    const PetscInt cells[4][2] = {{i - 1, j - 1}, {i, j - 1}, {i - 1, j}, {i, j}};
    double sum = 0.0;
    int n = 0;
    for (int q = 0; q < 4; q++) {
        const PetscInt a = cells[q][0], b = cells[q][1];
        if (b >= 0 && b < s->nz && cell_exists(s, a, b)) {
            sum += u[b][a][s->s_phi];
            n++;
        }
    }
    return n ? sum / n : 0.0;
}

/* The heating and dissipation of flowing cell (i, j) (properties p):
 * the mean squared corner shear rate and the normal rates. */
static ekm_source_coeffs temperature_source(const eval_ctx *c, PetscInt i, PetscInt j,
                                            const ekm_cell_properties *p)
{
    const ekm2d_solver *s = c->s;
    double exx, ezz;
    cell_rates(c, i, j, &exx, &ezz);
    return ekm_temperature_source_coeffs_plane(&s->sc->material, s->sc->variant, c->u[j][i][s->s_phi], p->g,
                                               p->Y, mean_corner_shear2(c, i, j), exx, ezz);
}

/* The temperature row of flowing wet cell (i, j) per rho_p, with the
 * cell's T, dT/dt and conductivity lambda given (the neighbours' from the
 * state): phi dT/dt + upwind convection - conduction - source.  mag
 * non-NULL: the sum of its terms' magnitudes there. */
static double temperature_row(const eval_ctx *c, PetscInt i, PetscInt j, double T, double dT_dt,
                              double lambda, const ekm_source_coeffs *src, double *mag)
{
    const ekm2d_solver *s = c->s;
    const PetscScalar ***u = c->u;
    const double rho_p = s->sc->material.rho_p, dx = s->dx, dz = s->dz;
    const double T_floor = s->sc->numerics.T_floor;
    const double Fw = flux_x(c, i, j), Fe = flux_x(c, i + 1, j);
    const double Fs = flux_z(c, i, j), Fn = flux_z(c, i, j + 1);
    double r = u[j][i][s->s_phi] * dT_dt, rm = fabs(r);
    /* upwind convection: what enters through each face brings its T */
    const double T_w = is_wet(s, i - 1, j) ? u[j][i - 1][s->s_T] : T_floor;
    const double T_e = is_wet(s, i + 1, j) ? u[j][i + 1][s->s_T] : T_floor;
    double T_s = is_wet(s, i, j - 1) ? u[j - 1][i][s->s_T] : T_floor;
    double T_n = is_wet(s, i, j + 1) ? u[j + 1][i][s->s_T] : T_floor;
    if (j == 0 && inlet_face(s, &c->bottom, i))
        T_s = c->bottom.T_in;
    if (j == s->nz - 1 && inlet_face(s, &c->top, i))
        T_n = c->top.T_in;
    /* the faces whose upwind side (frozen for the step) is the neighbour */
    double adv = 0.0;
    if (c->frozen[j][i][s->s_vx] > 0.0)
        adv += Fw * (T - T_w) / dx;
    if (c->frozen[j][i + 1][s->s_vx] < 0.0)
        adv += -Fe * (T - T_e) / dx;
    if (c->frozen[j][i][s->s_vz] > 0.0)
        adv += Fs * (T - T_s) / dz;
    if (c->frozen[j + 1][i][s->s_vz] < 0.0)
        adv += -Fn * (T - T_n) / dz;
    r += adv;
    rm += fabs(adv);
    /* conduction, 2/3 div(lambda grad T), per rho_p */
    const PetscInt nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
    for (int q = 0; q < 4; q++) {
        const PetscInt a = nb[q][0], b = nb[q][1];
        if (!is_wet(s, a, b) || is_solid(s, a, b))
            continue;
        const double h2 = q < 2 ? dx * dx : dz * dz;
        const double term =
            harmonic(lambda, props(s, a, b)->lambda) * (u[b][a][s->s_T] - T) / h2 * (2.0 / 3.0) / rho_p;
        r -= term;
        rm += fabs(term);
    }
    double dS;
    const double S = ekm_source_eval(src, T, &dS) / rho_p;
    r -= S;
    if (mag) {
        const double heat = (src->k_heat_a * sqrt(T) + src->k_heat_y / sqrt(T)) / rho_p;
        *mag = rm + heat + fabs(heat - S);
    }
    return r;
}

/* The solid stress rows of cell (i, j): in a solid cell the rate law
 * (hypo.h, plane strain) with its plastic norms lagged at the start of the
 * step (the 1D solver's linearly implicit step, regime.h: the equations
 * are linear in the stress and the velocities, and a state at rest is a
 * fixed point); elsewhere the stress is 0. */
static void solid_cell_rows(const eval_ctx *c, PetscInt i, PetscInt j, const PetscScalar ***ud,
                            PetscScalar ***f, PetscScalar ***mg)
{
    const ekm2d_solver *s = c->s;
    const PetscScalar *v = c->u[j][i];
    const PetscInt slot[3] = {s->s_sxx, s->s_syy, s->s_szz};
    if (!is_solid(s, i, j)) {
        for (int q = 0; q < 3; q++) {
            f[j][i][slot[q]] = v[slot[q]];
            if (mg)
                mg[j][i][slot[q]] = fabs(v[slot[q]]) + 1.0;
        }
        return;
    }
    const size_t k = cell_index(s, i, j);
    ekm_hypo_plane_rate r = {0.0, 0.0, 0.0};
    cell_rates(c, i, j, &r.exx, &r.ezz);
    const ekm_hypo_stress sg = {v[s->s_sxx], v[s->s_syy], v[s->s_szz], 0.0};
    const ekm_hypo_stress d =
        ekm_hypo_rate_plane(&s->sc->material, s->sc->variant, v[s->s_phi], &sg, &r, s->knorm[k], s->ktr[k]);
    const double rate[3] = {d.xx, d.yy, d.zz};
    ekm_hypo_stress dm = {0};
    if (mg)
        dm = ekm_hypo_rate_plane_magnitude(&s->sc->material, s->sc->variant, v[s->s_phi], &sg, &r,
                                           s->knorm[k], s->ktr[k]);
    const double mag[3] = {dm.xx, dm.yy, dm.zz};
    for (int q = 0; q < 3; q++) {
        f[j][i][slot[q]] = ud[j][i][slot[q]] - rate[q];
        if (mg)
            mg[j][i][slot[q]] = fabs(ud[j][i][slot[q]]) + mag[q];
    }
}

/* The sxz row of corner (i, j): the rate law's shear part at a solid
 * corner (its phi the mean of its cells', its norm lagged), 0 elsewhere. */
static void solid_corner_row(const eval_ctx *c, PetscInt i, PetscInt j, const PetscScalar ***ud,
                             PetscScalar ***f, PetscScalar ***mg)
{
    const ekm2d_solver *s = c->s;
    const double sxz = c->u[j][i][s->s_sxz];
    if (!corner_is_solid(c, i, j)) {
        f[j][i][s->s_sxz] = sxz;
        if (mg)
            mg[j][i][s->s_sxz] = fabs(sxz) + 1.0;
        return;
    }
    ekm_hypo_plane_rate r = {0.0, 0.0, 0.0};
    int has;
    (void)corner_stress(c, i, j, &r.gxz, &has);
    const ekm_hypo_stress sg = {0.0, 0.0, 0.0, sxz};
    const ekm_hypo_stress d = ekm_hypo_rate_plane(&s->sc->material, s->sc->variant, corner_phi(s, c->u, i, j),
                                                  &sg, &r, s->knorm_c[corner_index(s, i, j)], 0.0);
    f[j][i][s->s_sxz] = ud[j][i][s->s_sxz] - d.xz;
    if (mg) {
        /* where sxz and its rate vanish (a line of symmetry, a bed at rest)
         * the row's own terms are round-off: its scale is the normal stress
         * of its cells over the step and their elastic rate, as theirs */
        const PetscInt cells[4][2] = {{i - 1, j - 1}, {i, j - 1}, {i - 1, j}, {i, j}};
        double szz = 0.0;
        for (int q = 0; q < 4; q++)
            if (is_solid(s, cells[q][0], cells[q][1]))
                szz = fmax(szz, fabs(c->u[cells[q][1]][cells[q][0]][s->s_szz]));
        const double fB =
            ekm_hypo_density_factor(&s->sc->material, corner_phi(s, c->u, i, j)) * s->sc->material.B_h;
        mg[j][i][s->s_sxz] =
            fabs(ud[j][i][s->s_sxz]) + fabs(d.xz) + szz / s->dt_step + fB * s->knorm_c[corner_index(s, i, j)];
    }
}

/* Add |term| to the row's magnitude (scaling pass only). */
#define MAG(row, term)           \
    do {                         \
        if (mg)                  \
            (row) += fabs(term); \
    } while (0)

/* The residual of every owned row into f (local array); mg non-NULL: also
 * each row's sum of term magnitudes into mg (same layout).  Rows are per
 * unit rho_p (momentum, T) so that they compare across cells. */
static void residual_rows(const eval_ctx *c, const PetscScalar ***ud, PetscScalar ***f, PetscScalar ***mg,
                          double t)
{
    const ekm2d_solver *s = c->s;
    const ekm_scenario *sc = s->sc;
    const ekm_material *m = &sc->material;
    const double rho_p = m->rho_p, dx = s->dx, dz = s->dz;
    const double T_floor = sc->numerics.T_floor;
    const PetscScalar ***u = c->u;
    PetscInt x0, z0, nxl, nzl, ex, ez;
    DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL);
    (void)t;
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++) {
            const int cell = has_cell_rows(s, i, j);
            /* ---- cell rows: mass and temperature ---- */
            if (cell) {
                const double phi = u[j][i][s->s_phi], T = u[j][i][s->s_T];
                const double Fw = flux_x(c, i, j), Fe = flux_x(c, i + 1, j);
                const double Fs = flux_z(c, i, j), Fn = flux_z(c, i, j + 1);
                f[j][i][s->s_phi] = ud[j][i][s->s_phi] + (Fe - Fw) / dx + (Fn - Fs) / dz;
                if (mg)
                    mg[j][i][s->s_phi] =
                        fabs(ud[j][i][s->s_phi]) + (fabs(Fe) + fabs(Fw)) / dx + (fabs(Fn) + fabs(Fs)) / dz;
                if (!is_wet(s, i, j)) {
                    f[j][i][s->s_T] = T - T_floor;
                    if (mg)
                        mg[j][i][s->s_T] = fabs(T) + T_floor;
                } else if (is_solid(s, i, j)) {
                    /* a solid cell's T is not evolved; it exchanges no heat (regime.h) */
                    f[j][i][s->s_T] = phi * ud[j][i][s->s_T];
                    if (mg)
                        mg[j][i][s->s_T] = fabs(f[j][i][s->s_T]);
                } else {
                    const ekm_cell_properties *p = props(s, i, j);
                    const ekm_source_coeffs src = temperature_source(c, i, j, p);
                    f[j][i][s->s_T] = temperature_row(c, i, j, T, ud[j][i][s->s_T], p->lambda, &src,
                                                      mg ? &mg[j][i][s->s_T] : NULL);
                }
                if (s->hypo)
                    solid_cell_rows(c, i, j, ud, f, mg);
            }
            if (has_vertex_row(s, i, j))
                solid_corner_row(c, i, j, ud, f, mg);
            /* ---- x-face rows (i, j): vx ---- */
            if (has_xface_row(s, i, j)) {
                const double v = u[j][i][s->s_vx];
                const double phi_f =
                    side_face(s, i) ? 0.0 : 0.5 * (u[j][i - 1][s->s_phi] + u[j][i][s->s_phi]);
                const int wall = side_face(s, i);
                const int dry_face =
                    !wall && 0.5 * ((is_wet(s, i - 1, j) ? 1.0 : 0.0) + (is_wet(s, i, j) ? 1.0 : 0.0)) == 0.0;
                if (wall || dry_face) {
                    f[j][i][s->s_vx] = v;
                    if (mg)
                        mg[j][i][s->s_vx] = fabs(v) + 1.0;
                } else {
                    double r = phi_f * ud[j][i][s->s_vx], rm = fabs(r);
                    /* upwind convection with the fluxes at the control volume's sides */
                    const double Fc_w = 0.5 * (flux_x(c, i - 1, j) + flux_x(c, i, j));
                    const double Fc_e = 0.5 * (flux_x(c, i, j) + flux_x(c, i + 1, j));
                    const double Fc_s = 0.5 * (flux_z(c, i - 1, j) + flux_z(c, i, j));
                    const double Fc_n = 0.5 * (flux_z(c, i - 1, j + 1) + flux_z(c, i, j + 1));
                    const double v_s = j > 0 ? u[j - 1][i][s->s_vx] : c->bottom.u_in;
                    const double v_n = j < s->nz - 1 ? u[j + 1][i][s->s_vx] : c->top.u_in;
                    double adv = 0.0;
                    if (Fc_w > 0.0)
                        adv += Fc_w * (v - u[j][i - 1][s->s_vx]) / dx;
                    if (Fc_e < 0.0)
                        adv += -Fc_e * (v - u[j][i + 1][s->s_vx]) / dx;
                    if (Fc_s > 0.0)
                        adv += Fc_s * (v - v_s) / dz;
                    if (Fc_n < 0.0)
                        adv += -Fc_n * (v - v_n) / dz;
                    r += adv;
                    MAG(rm, adv);
                    const ekm_plane_stress sw = cell_stress(c, i - 1, j), se = cell_stress(c, i, j);
                    double rate;
                    int has;
                    const double t_s = corner_stress(c, i, j, &rate, &has);
                    const double t_n = corner_stress(c, i, j + 1, &rate, &has);
                    const double div = ((se.sxx - sw.sxx) / dx + (t_n - t_s) / dz) / rho_p;
                    const double grav = phi_f * s->g_x;
                    r -= div + grav;
                    if (mg)
                        mg[j][i][s->s_vx] = rm + (fabs(se.sxx) + fabs(sw.sxx)) / dx / rho_p +
                                            (fabs(t_n) + fabs(t_s)) / dz / rho_p + fabs(grav);
                    f[j][i][s->s_vx] = r;
                }
            }
            /* ---- z-face rows (i, j): vz ---- */
            if (has_zface_row(s, i, j)) {
                const double v = u[j][i][s->s_vz];
                if (j == 0 || j == s->nz) {
                    const end_data *e = j == 0 ? &c->bottom : &c->top;
                    if (e->kind == EKM_BC_FREE) {
                        const double v_in = u[j == 0 ? 1 : s->nz - 1][i][s->s_vz];
                        f[j][i][s->s_vz] = v - v_in;
                        if (mg)
                            mg[j][i][s->s_vz] = fabs(v) + fabs(v_in) + 1.0;
                    } else {
                        const double w = end_w(s, e, i);
                        f[j][i][s->s_vz] = v - w;
                        if (mg)
                            mg[j][i][s->s_vz] = fabs(v) + fabs(w) + 1.0;
                    }
                } else if (!is_wet(s, i, j - 1) && !is_wet(s, i, j)) {
                    f[j][i][s->s_vz] = v;
                    if (mg)
                        mg[j][i][s->s_vz] = fabs(v) + 1.0;
                } else {
                    const double phi_f = 0.5 * (u[j - 1][i][s->s_phi] + u[j][i][s->s_phi]);
                    double r = phi_f * ud[j][i][s->s_vz], rm = fabs(r);
                    const double Fc_s = 0.5 * (flux_z(c, i, j - 1) + flux_z(c, i, j));
                    const double Fc_n = 0.5 * (flux_z(c, i, j) + flux_z(c, i, j + 1));
                    const double Fc_w = 0.5 * (flux_x(c, i, j - 1) + flux_x(c, i, j));
                    const double Fc_e = 0.5 * (flux_x(c, i + 1, j - 1) + flux_x(c, i + 1, j));
                    const double v_s = j - 1 > 0 ? u[j - 1][i][s->s_vz] : end_w(s, &c->bottom, i);
                    const double v_n = j + 1 < s->nz ? u[j + 1][i][s->s_vz] : end_w(s, &c->top, i);
                    const int has_w = s->periodic || i > 0, has_e = s->periodic || i < s->nx - 1;
                    double adv = 0.0;
                    if (Fc_s > 0.0)
                        adv += Fc_s * (v - v_s) / dz;
                    if (Fc_n < 0.0)
                        adv += -Fc_n * (v - v_n) / dz;
                    if (Fc_w > 0.0 && has_w)
                        adv += Fc_w * (v - u[j][i - 1][s->s_vz]) / dx;
                    if (Fc_e < 0.0 && has_e)
                        adv += -Fc_e * (v - u[j][i + 1][s->s_vz]) / dx;
                    r += adv;
                    MAG(rm, adv);
                    const ekm_plane_stress sb = cell_stress(c, i, j - 1), sa = cell_stress(c, i, j);
                    double rate;
                    int has;
                    const double t_w = corner_stress(c, i, j, &rate, &has);
                    const double t_e = corner_stress(c, i + 1, j, &rate, &has);
                    const double div = ((sa.szz - sb.szz) / dz + (t_e - t_w) / dx) / rho_p;
                    const double grav = phi_f * s->g_z;
                    r -= div + grav;
                    if (mg)
                        mg[j][i][s->s_vz] = rm + (fabs(sa.szz) + fabs(sb.szz)) / dz / rho_p +
                                            (fabs(t_e) + fabs(t_w)) / dx / rho_p + fabs(grav);
                    f[j][i][s->s_vz] = r;
                }
            }
        }
}

/* TS's implicit function: F(t, U, Udot), rows scaled by row_scale. */
static PetscErrorCode ifunction(TS ts, PetscReal t, Vec U, Vec Udot, Vec F, void *vctx)
{
    ekm2d_solver *s = vctx;
    PetscReal dt_try;
    PCALL(TSGetTimeStep(ts, &dt_try));
    if (dt_try < s->sc->numerics.dt_min) {
        s->dt_failed = dt_try; /* TS would retry ever shorter steps: stop (ekm2d_solver_advance) */
        return PETSC_ERR_NOT_CONVERGED;
    }
    if (dt_try != s->row_dt)
        PCALL(update_row_scale(s, dt_try));
    Vec Ul, Udl, Fl;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(DMGetLocalVector(s->dm, &Udl));
    PCALL(DMGetLocalVector(s->dm, &Fl));
    PCALL(DMGlobalToLocalBegin(s->dm, U, INSERT_VALUES, Ul));
    PCALL(DMGlobalToLocalEnd(s->dm, U, INSERT_VALUES, Ul));
    PCALL(DMGlobalToLocalBegin(s->dm, Udot, INSERT_VALUES, Udl));
    PCALL(DMGlobalToLocalEnd(s->dm, Udot, INSERT_VALUES, Udl));
    PCALL(to_physical(s, Ul));
    PCALL(to_physical(s, Udl));
    PCALL(VecSet(Fl, 0.0));
    const PetscScalar ***u, ***ud, ***dry;
    PetscScalar ***f;
    PCALL(DMStagVecGetArrayRead(s->dm, Ul, (void *)&u));
    PCALL(DMStagVecGetArrayRead(s->dm, Udl, (void *)&ud));
    PCALL(DMStagVecGetArrayRead(s->dm, s->dry_local, (void *)&dry));
    PCALL(DMStagVecGetArray(s->dm, Fl, &f));
    const int ok = compute_properties(s, u, dry);
    eval_ctx c = {.u = u, .frozen = dry, .s = s};
    c.bottom = end_at(s, 0, s->t_step);
    c.top = end_at(s, 1, s->t_step);
    if (ok)
        residual_rows(&c, ud, f, NULL, t);
    PCALL(DMStagVecRestoreArrayRead(s->dm, Ul, (void *)&u));
    PCALL(DMStagVecRestoreArrayRead(s->dm, Udl, (void *)&ud));
    PCALL(DMStagVecRestoreArrayRead(s->dm, s->dry_local, (void *)&dry));
    PCALL(DMStagVecRestoreArray(s->dm, Fl, &f));
    if (!ok)
        PCALL(VecSet(Fl, NAN)); /* outside the domain: the line search backs off */
    PCALL(DMLocalToGlobal(s->dm, Fl, INSERT_VALUES, F));
    PCALL(VecPointwiseMult(F, F, s->row_scale));
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    PCALL(DMRestoreLocalVector(s->dm, &Udl));
    PCALL(DMRestoreLocalVector(s->dm, &Fl));
    return 0;
}

/* A cell that joins the flow this step (empty in the step before, by its
 * frozen flag, and now phi >= phi_dry: its T is still the empty cells'
 * T_floor) starts from the largest T of its wet neighbours, or the
 * inflow's T under an open inlet: Newton from T_floor (1e-16) overshoots
 * to T < 0 where the cell expands into its empty neighbours. An empty
 * cell's T carries no information, so the state is unchanged otherwise.
 * (Until 2026-12-04 a cell counted as joining when its T was <= T_floor:
 * a cold bed's quasi-static T falls below T_floor, 6e-17 in the thesis
 * filling's bottom row at 1.77 s, and was reset to its neighbours' 9e-15
 * before every step, which then took 10 Newton iterations and stalled the
 * run at dt = 2.5e-6 s.) */
static PetscErrorCode seed_joining_cells(ekm2d_solver *s, Vec U, double t)
{
    const double phi_dry = s->sc->numerics.phi_dry, T_floor = s->sc->numerics.T_floor;
    const end_data bottom = end_at(s, 0, t), top = end_at(s, 1, t);
    Vec Ul;
    PetscScalar ***u;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(DMGlobalToLocal(s->dm, U, INSERT_VALUES, Ul));
    PCALL(to_physical(s, Ul));
    PCALL(DMStagVecGetArray(s->dm, Ul, &u));
    const PetscScalar **
        *was_dry; /* the frozen flags of the step before (prestep freezes this step's after) */
    PCALL(DMStagVecGetArrayRead(s->dm, s->dry_local, (void *)&was_dry));
    PetscInt x0, z0, nxl, nzl;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, NULL, NULL, NULL));
    int seeded = 0;
    for (PetscInt j = z0; j < z0 + nzl; j++)
        for (PetscInt i = x0; i < x0 + nxl; i++) {
            if (!(u[j][i][s->s_phi] >= phi_dry && was_dry[j][i][s->s_phi] != 0.0))
                continue;
            double T_seed = 0.0;
            const PetscInt nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
            for (int q = 0; q < 4; q++) {
                const PetscInt a = nb[q][0], b = nb[q][1];
                if (b < 0 || b >= s->nz || (!s->periodic && (a < 0 || a >= s->nx)))
                    continue;
                if (u[b][a][s->s_phi] >= phi_dry)
                    T_seed = fmax(T_seed, u[b][a][s->s_T]);
            }
            if (j == 0 && inlet_face(s, &bottom, i))
                T_seed = fmax(T_seed, bottom.T_in);
            if (j == s->nz - 1 && inlet_face(s, &top, i))
                T_seed = fmax(T_seed, top.T_in);
            if (T_seed > T_floor) {
                u[j][i][s->s_T] = T_seed;
                seeded = 1;
            }
        }
    PCALL(DMStagVecRestoreArrayRead(s->dm, s->dry_local, (void *)&was_dry));
    PCALL(DMStagVecRestoreArray(s->dm, Ul, &u));
    /* writing U makes TS restart its step history (TSPreStep sees the change): only when a cell joined */
    int any;
    MPI_Allreduce(&seeded, &any, 1, MPI_INT, MPI_MAX, s->comm);
    if (any) {
        PCALL(to_unknowns(s, Ul));
        PCALL(DMLocalToGlobal(s->dm, Ul, INSERT_VALUES, U));
    }
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    return 0;
}

/* The step's error estimate (TSBDF: the new state against the polynomial
 * through it and the two states before it) is measured in the conserved
 * densities: phi, phi v and phi T, with the absolute tolerance
 * EKM2D_LTE_ATOL of a close-packed cell (phi_cp): a velocity's or a
 * temperature's tolerance is EKM2D_LTE_ATOL phi_cp / phi. The dilute head
 * of a falling stream (phi ~ phi_dry) then does not set the step of the
 * whole box, as it did with the tolerance on v itself (its velocity
 * relaxes on the viscous time of a nearly empty cell; measured at the
 * thesis filling's front: the step fell from 1e-3 to 2e-5 s at each cell
 * the front entered). A row that has not been its physical equation over
 * the three states is left out: its estimate measures a switch of the
 * model (an empty cell's T_floor replaced by its neighbours' T, a dry
 * face's v = 0 by the stream's velocity), not the integration's error. */
#define EKM2D_LTE_ATOL      1e-4
#define EKM2D_LTE_RTOL      1e-3
#define EKM2D_LTE_EXCLUDED  1e30
#define EKM2D_LTE_MIN_STEPS 3

static inline double lte_atol_per_phi(const ekm2d_solver *s, double phi)
{
    const double a = EKM2D_LTE_ATOL * s->sc->material.phi_cp;
    return phi > a / EKM2D_LTE_EXCLUDED ? fmin(a / phi, EKM2D_LTE_EXCLUDED) : EKM2D_LTE_EXCLUDED;
}

/* Each owned row's absolute error tolerance this step into a (local
 * array; 0: not its physical equation), from the state u and the frozen
 * wet cells (compute_properties). */
static void row_tolerances(const eval_ctx *c, PetscScalar ***a)
{
    const ekm2d_solver *s = c->s;
    const PetscScalar ***u = c->u;
    /* a solid stress: EKM2D_LTE_ATOL of the weight of a close-packed column of the box's height */
    const double g = sqrt(s->g_x * s->g_x + s->g_z * s->g_z);
    const double stress_atol =
        EKM2D_LTE_ATOL * s->sc->material.rho_p * s->sc->material.phi_cp * fmax(g, 1.0) * s->sc->length;
    PetscInt x0, z0, nxl, nzl, ex, ez;
    DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL);
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++) {
            if (has_cell_rows(s, i, j)) {
                a[j][i][s->s_phi] = EKM2D_LTE_ATOL;
                a[j][i][s->s_T] =
                    is_wet(s, i, j) && !is_solid(s, i, j) ? lte_atol_per_phi(s, u[j][i][s->s_phi]) : 0.0;
                if (s->hypo) {
                    const double on = is_solid(s, i, j) ? stress_atol : 0.0;
                    a[j][i][s->s_sxx] = a[j][i][s->s_syy] = a[j][i][s->s_szz] = on;
                }
            }
            if (has_vertex_row(s, i, j))
                a[j][i][s->s_sxz] = corner_is_solid(c, i, j) ? stress_atol : 0.0;
            if (has_xface_row(s, i, j)) {
                const int on = !side_face(s, i) && (is_wet(s, i - 1, j) || is_wet(s, i, j));
                a[j][i][s->s_vx] =
                    on ? lte_atol_per_phi(s, 0.5 * (u[j][i - 1][s->s_phi] + u[j][i][s->s_phi])) : 0.0;
            }
            if (has_zface_row(s, i, j)) {
                const int on = j > 0 && j < s->nz && (is_wet(s, i, j - 1) || is_wet(s, i, j));
                a[j][i][s->s_vz] =
                    on ? lte_atol_per_phi(s, 0.5 * (u[j - 1][i][s->s_phi] + u[j][i][s->s_phi])) : 0.0;
            }
        }
}

/* The rows' ages and error tolerances for the step about to start (Al: a
 * local vector to fill, Ag a global one; wet cells computed). */
static PetscErrorCode update_lte_tolerances(ekm2d_solver *s, const eval_ctx *c, Vec Al, Vec Ag)
{
    PetscScalar ***a;
    PCALL(VecSet(Al, 0.0));
    PCALL(DMStagVecGetArray(s->dm, Al, &a));
    row_tolerances(c, a);
    PCALL(DMStagVecRestoreArray(s->dm, Al, &a));
    PCALL(DMLocalToGlobal(s->dm, Al, INSERT_VALUES, Ag));
    PCALL(VecPointwiseDivide(Ag, Ag, s->T_unit)); /* the error is measured on the unknowns (T / T_ref) */
    PetscScalar *age, *atol;
    const PetscScalar *tol;
    PetscInt n;
    PCALL(VecGetLocalSize(Ag, &n));
    PCALL(VecGetArrayRead(Ag, &tol));
    PCALL(VecGetArray(s->row_age, &age));
    PCALL(VecGetArray(s->lte_atol, &atol));
    for (PetscInt k = 0; k < n; k++) {
        age[k] = tol[k] != 0.0 ? age[k] + 1.0 : 0.0;
        atol[k] = age[k] >= EKM2D_LTE_MIN_STEPS ? tol[k] : EKM2D_LTE_EXCLUDED;
    }
    PCALL(VecRestoreArray(s->lte_atol, &atol));
    PCALL(VecRestoreArray(s->row_age, &age));
    PCALL(VecRestoreArrayRead(Ag, &tol));
    return 0;
}

/* The solid cells of the ghosted box from the persistent regime vector
 * into s->solid (collective). */
static PetscErrorCode load_solid_flags(ekm2d_solver *s)
{
    if (!s->hypo)
        return 0;
    Vec Rl;
    const PetscScalar ***r;
    PCALL(DMGetLocalVector(s->dm, &Rl));
    PCALL(DMGlobalToLocal(s->dm, s->regime, INSERT_VALUES, Rl));
    PCALL(DMStagVecGetArrayRead(s->dm, Rl, (void *)&r));
    for (PetscInt j = s->gz0; j < s->gz0 + s->gnz; j++)
        for (PetscInt i = s->gx0; i < s->gx0 + s->gnx; i++)
            s->solid[cell_index(s, i, j)] = cell_exists(s, i, j) && r[j][i][s->s_phi] > 0.5;
    PCALL(DMStagVecRestoreArrayRead(s->dm, Rl, (void *)&r));
    PCALL(DMRestoreLocalVector(s->dm, &Rl));
    return 0;
}

/* The rates of cell (i, j) for its solid law's norm: exx, ezz and as gxz
 * the root mean square of its corners' shear rates (the heating's). */
static ekm_hypo_plane_rate cell_plane_rate(const eval_ctx *c, PetscInt i, PetscInt j)
{
    ekm_hypo_plane_rate r;
    cell_rates(c, i, j, &r.exx, &r.ezz);
    r.gxz = sqrt(mean_corner_shear2(c, i, j));
    return r;
}

/* The plastic norms of the solid law lagged at the step's start state
 * (c: its wet cells computed, the solid flags loaded): ||kappa|| and
 * |tr kappa| of each owned cell, ||kappa|| of each owned corner from its
 * shear rate and the mean normal rates of its cells. */
static void lagged_norms(const eval_ctx *c)
{
    ekm2d_solver *s = (ekm2d_solver *)c->s;
    const ekm_material *m = &s->sc->material;
    PetscInt x0, z0, nxl, nzl, ex, ez;
    DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL);
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++) {
            if (has_cell_rows(s, i, j)) {
                const ekm_hypo_plane_rate r = cell_plane_rate(c, i, j);
                const size_t k = cell_index(s, i, j);
                s->knorm[k] = ekm_hypo_rate_norm_plane(m, &r);
                s->ktr[k] = fabs(r.exx + r.ezz);
            }
            if (!has_vertex_row(s, i, j))
                continue;
            ekm_hypo_plane_rate r = {0.0, 0.0, 0.0};
            int has, n = 0;
            (void)corner_stress(c, i, j, &r.gxz, &has);
            const PetscInt cells[4][2] = {{i - 1, j - 1}, {i, j - 1}, {i - 1, j}, {i, j}};
            double exx = 0.0, ezz = 0.0;
            for (int q = 0; q < 4; q++) {
                const PetscInt a = cells[q][0], b = cells[q][1];
                if (b < 0 || b >= s->nz || !is_wet(s, a, b))
                    continue;
                double e1, e2;
                cell_rates(c, a, b, &e1, &e2);
                exx += e1;
                ezz += e2;
                n++;
            }
            if (n) {
                r.exx = exx / n;
                r.ezz = ezz / n;
            }
            s->knorm_c[corner_index(s, i, j)] = ekm_hypo_rate_norm_plane(m, &r);
        }
}

/* Newton's first iterate: TSBDF's extrapolation of the last two states,
 * except in rows whose role changed within them (row_age below
 * EKM2D_LTE_MIN_STEPS: a cell that joined the flow, a face that became
 * wet), and where it leaves phi < 0 or T <= 0: there the state at the
 * start of the step. The extrapolated T of a joining cell (T_floor to its
 * neighbours' T) and the extrapolated head of a stream (phi < 0) made
 * Newton fail and the step be retried. */
static PetscErrorCode initial_guess(SNES snes, Vec X, void *vctx)
{
    (void)snes;
    ekm2d_solver *s = vctx;
    Vec Xl, Sl, Al;
    PetscScalar ***x;
    const PetscScalar ***u0, ***age;
    PCALL(DMGetLocalVector(s->dm, &Xl));
    PCALL(DMGetLocalVector(s->dm, &Sl));
    PCALL(DMGetLocalVector(s->dm, &Al));
    PCALL(DMGlobalToLocal(s->dm, X, INSERT_VALUES, Xl));
    PCALL(DMGlobalToLocal(s->dm, s->U_start, INSERT_VALUES, Sl));
    PCALL(DMGlobalToLocal(s->dm, s->row_age, INSERT_VALUES, Al));
    PCALL(DMStagVecGetArray(s->dm, Xl, &x));
    PCALL(DMStagVecGetArrayRead(s->dm, Sl, (void *)&u0));
    PCALL(DMStagVecGetArrayRead(s->dm, Al, (void *)&age));
    PetscInt x0, z0, nxl, nzl, ex, ez;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL));
    const PetscInt slots[8] = {s->s_phi, s->s_T, s->s_vx, s->s_vz, s->s_sxx, s->s_syy, s->s_szz, s->s_sxz};
    const int nslots = s->hypo ? 8 : 4;
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++)
            for (int q = 0; q < nslots; q++) {
                const PetscInt k = slots[q];
                const int bad = (q == 0 && x[j][i][k] < 0.0) || (q == 1 && !(x[j][i][k] > 0.0));
                if (bad || age[j][i][k] < EKM2D_LTE_MIN_STEPS)
                    x[j][i][k] = u0[j][i][k];
            }
    PCALL(DMStagVecRestoreArrayRead(s->dm, Al, (void *)&age));
    PCALL(DMStagVecRestoreArrayRead(s->dm, Sl, (void *)&u0));
    PCALL(DMStagVecRestoreArray(s->dm, Xl, &x));
    PCALL(DMLocalToGlobal(s->dm, Xl, INSERT_VALUES, X));
    PCALL(DMRestoreLocalVector(s->dm, &Al));
    PCALL(DMRestoreLocalVector(s->dm, &Sl));
    PCALL(DMRestoreLocalVector(s->dm, &Xl));
    return 0;
}

/* The row scales of a step of length dt: 1 / (the magnitude of the row's
 * terms at the start of the step + the time derivative's |U_start| / dt,
 * in the row's units: T itself for the T rows). Computed again when TS
 * retries the step shorter (ifunction): with the scale of the first try a
 * phi row's round-off, eps phi / dt, grew past the tolerance as dt fell,
 * and no retry could converge (the thesis filling at 1.52 s: 2-cycles at
 * a scaled residual of 5e-10 at dt = 1e-6 s after a failure at 4.5e-4 s). */
static PetscErrorCode update_row_scale(ekm2d_solver *s, double dt)
{
    Vec Up;
    PCALL(DMGetGlobalVector(s->dm, &Up));
    PCALL(VecPointwiseMult(Up, s->U_start, s->T_unit));
    PetscScalar *scale;
    const PetscScalar *uu, *mag;
    PetscInt n;
    PCALL(VecGetLocalSize(s->row_scale, &n));
    PCALL(VecGetArray(s->row_scale, &scale));
    PCALL(VecGetArrayRead(s->row_mag, &mag));
    PCALL(VecGetArrayRead(Up, &uu));
    for (PetscInt k = 0; k < n; k++) {
        const double m = mag[k] + fabs(uu[k]) / dt;
        scale[k] = m > 0.0 ? 1.0 / m : 1.0;
    }
    PCALL(VecRestoreArray(s->row_scale, &scale));
    PCALL(VecRestoreArrayRead(s->row_mag, &mag));
    PCALL(VecRestoreArrayRead(Up, &uu));
    PCALL(DMRestoreGlobalVector(s->dm, &Up));
    s->row_dt = dt;
    return 0;
}

/* Before each step: the empty cells of the step and the row scales from
 * the state at its start; the step no longer than the convective limit. */
static PetscErrorCode prestep(TS ts)
{
    ekm2d_solver *s;
    PCALL(TSGetApplicationContext(ts, &s));
    Vec U;
    PetscReal t;
    PCALL(TSGetSolution(ts, &U));
    PCALL(TSGetTime(ts, &t));
    s->t_step = t;
    PCALL(seed_joining_cells(s, U, t));
    PCALL(VecCopy(U, s->U_start));
    Vec Ul, Ml, Zl;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(DMGetLocalVector(s->dm, &Ml));
    PCALL(DMGetLocalVector(s->dm, &Zl));
    PCALL(DMGlobalToLocalBegin(s->dm, U, INSERT_VALUES, Ul));
    PCALL(DMGlobalToLocalEnd(s->dm, U, INSERT_VALUES, Ul));
    PCALL(to_physical(s, Ul));
    /* empty cells: phi < phi_dry */
    PetscScalar ***dry;
    const PetscScalar ***u, ***zero;
    PCALL(VecSet(s->dry_local, 0.0));
    PCALL(DMStagVecGetArray(s->dm, s->dry_local, &dry));
    PCALL(DMStagVecGetArrayRead(s->dm, Ul, (void *)&u));
    double vmax_x = 0.0, vmax_z = 0.0;
    freeze_step_data(s, u, dry);
    PetscInt x0, z0, nxl, nzl, ex, ez;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL));
    /* the convective limit counts what a face carries into a cell of other
     * content: |v| / h times the relative contrast of phi across the face
     * (a front, an empty cell filling: 1; a uniform layer sheared along
     * itself: 0), so that the frozen empty set of a step and the upwind
     * transport stay accurate; the implicit scheme is stable without it */
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++) {
            if (j < s->nz && !side_face(s, i) && i <= s->nx && (s->periodic || i > 0)) {
                const double a = u[j][i - 1][s->s_phi], b = u[j][i][s->s_phi];
                const double top = fmax(a, b);
                if (top > 0.0)
                    vmax_x = fmax(vmax_x, fabs(u[j][i][s->s_vx]) * fabs(a - b) / top);
            }
            if (i < s->nx && j > 0 && j < s->nz) {
                const double a = u[j - 1][i][s->s_phi], b = u[j][i][s->s_phi];
                const double top = fmax(a, b);
                if (top > 0.0)
                    vmax_z = fmax(vmax_z, fabs(u[j][i][s->s_vz]) * fabs(a - b) / top);
            }
        }
    PCALL(DMStagVecRestoreArray(s->dm, s->dry_local, &dry));
    /* row magnitudes at the start state (Udot = 0) */
    PetscScalar ***mg, ***f;
    PCALL(VecSet(Ml, 0.0));
    PCALL(VecSet(Zl, 0.0));
    Vec Fl;
    PCALL(DMGetLocalVector(s->dm, &Fl));
    PCALL(DMStagVecGetArray(s->dm, Ml, &mg));
    PCALL(DMStagVecGetArray(s->dm, Fl, &f));
    PCALL(DMStagVecGetArrayRead(s->dm, Zl, (void *)&zero));
    const PetscScalar ***dry_r;
    PCALL(DMStagVecGetArrayRead(s->dm, s->dry_local, (void *)&dry_r));
    (void)compute_properties(s, u, dry_r);
    eval_ctx c = {.u = u, .frozen = dry_r, .s = s};
    c.bottom = end_at(s, 0, t);
    c.top = end_at(s, 1, t);
    PCALL(load_solid_flags(s));
    if (s->hypo)
        lagged_norms(&c);
    PCALL(TSGetTimeStep(ts, &s->dt_step));
    residual_rows(&c, zero, f, mg, t);
    /* the compression limit (the 1D solver's, control.c): with dU/dt = 0
     * the phi rows hold div(phi v) = -dphi/dt; a step should close at most
     * half of phi_step_max of a cell's gap to phi_cp (check_stage rejects
     * beyond phi_step_max) */
    double close_rate = 0.0; /* [1/s] */
    for (PetscInt j = z0; j < z0 + nzl; j++)
        for (PetscInt i = x0; i < x0 + nxl; i++) {
            const double gap = s->sc->material.phi_cp - u[j][i][s->s_phi];
            if (-f[j][i][s->s_phi] > 0.0 && gap > 0.0)
                close_rate = fmax(close_rate, -f[j][i][s->s_phi] / gap);
        }
    PCALL(DMStagVecRestoreArrayRead(s->dm, s->dry_local, (void *)&dry_r));
    PCALL(DMStagVecRestoreArrayRead(s->dm, Zl, (void *)&zero));
    PCALL(DMStagVecRestoreArray(s->dm, Fl, &f));
    PCALL(DMStagVecRestoreArray(s->dm, Ml, &mg));
    {
        /* the wet cells of the step (compute_properties above) set the rows' error tolerances */
        Vec Ag;
        PCALL(DMGetGlobalVector(s->dm, &Ag));
        PCALL(update_lte_tolerances(s, &c, Fl, Ag));
        PCALL(DMRestoreGlobalVector(s->dm, &Ag));
    }
    PCALL(DMStagVecRestoreArrayRead(s->dm, Ul, (void *)&u));
    PCALL(DMLocalToGlobal(s->dm, Ml, INSERT_VALUES, s->row_mag));
    PetscReal dt;
    PCALL(TSGetTimeStep(ts, &dt));
    PCALL(update_row_scale(s, dt));
    PCALL(DMRestoreLocalVector(s->dm, &Fl));
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    PCALL(DMRestoreLocalVector(s->dm, &Ml));
    PCALL(DMRestoreLocalVector(s->dm, &Zl));
    /* the convective limit: what crosses a face in one step at most cfl of a cell */
    double lim[3] = {vmax_x / s->dx, vmax_z / s->dz, close_rate}, glob[3];
    MPI_Allreduce(lim, glob, 3, MPI_DOUBLE, MPI_MAX, s->comm);
    const double rate = fmax(glob[0], glob[1]);
    double dt_lim = rate > 0.0 ? s->sc->numerics.cfl / rate : INFINITY;
    if (glob[2] > 0.0)
        dt_lim = fmin(dt_lim, 0.5 * s->sc->numerics.phi_step_max / glob[2]);
    if (dt > dt_lim)
        PCALL(TSSetTimeStep(ts, dt_lim));
    return 0;
}

/* The mean of the shear stresses at the four corners of cell (i, j) [Pa]
 * (the output's), and (mean_rate non-NULL) the mean of the corners' shear
 * rates where they carry one [1/s]. */
static double cell_mean_shear(const eval_ctx *c, PetscInt i, PetscInt j, double *mean_rate)
{
    double rate, sum = 0.0, rate_sum = 0.0;
    int has, n = 0;
    const PetscInt cn[4][2] = {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}};
    for (int q = 0; q < 4; q++) {
        sum += corner_stress(c, cn[q][0], cn[q][1], &rate, &has);
        if (has) {
            rate_sum += rate;
            n++;
        }
    }
    if (mean_rate)
        *mean_rate = n ? rate_sum / n : 0.0;
    return 0.25 * sum;
}

/* After an accepted step: the switches flow <-> solid of the owned cells
 * by the rules of switching.h (the 1D solver's), with the plane rates.  A
 * cell turning solid takes its flow stress; a corner turning solid the
 * shear stress it had as a flowing corner; a cell turning flow the
 * quasi-static T of its rates (below phi_co: the T of its solid sigma_zz).
 * Writes U only when a cell switched (TS then restarts its history,
 * TSPostStep). */
static PetscErrorCode switch_regimes(ekm2d_solver *s, Vec U, double t)
{
    const ekm_scenario *sc = s->sc;
    const ekm_material *m = &sc->material;
    const ekm_hypo_params *h = &sc->hypo;
    Vec Ul, Fr, Rl;
    PetscScalar ***u, ***fr, ***rg;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(DMGetLocalVector(s->dm, &Fr));
    PCALL(DMGetLocalVector(s->dm, &Rl));
    PCALL(DMGlobalToLocal(s->dm, U, INSERT_VALUES, Ul));
    PCALL(to_physical(s, Ul));
    PCALL(DMGlobalToLocal(s->dm, s->regime, INSERT_VALUES, Rl));
    PCALL(VecSet(Fr, 0.0));
    PCALL(DMStagVecGetArray(s->dm, Ul, &u));
    PCALL(DMStagVecGetArray(s->dm, Fr, &fr));
    PCALL(DMStagVecGetArray(s->dm, Rl, &rg));
    freeze_step_data(s, (const PetscScalar ***)u, fr);
    (void)compute_properties(s, (const PetscScalar ***)u, (const PetscScalar ***)fr);
    eval_ctx c = {.u = (const PetscScalar ***)u, .frozen = (const PetscScalar ***)fr, .s = s};
    c.bottom = end_at(s, 0, t);
    c.top = end_at(s, 1, t);
    PetscInt x0, z0, nxl, nzl, ex, ez;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL));
    /* the corners' stresses before the switch (NAN: solid, kept) */
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++)
            if (has_vertex_row(s, i, j)) {
                double rate;
                int has;
                s->corner_scratch[corner_index(s, i, j)] =
                    corner_is_solid(&c, i, j) ? NAN : corner_stress(&c, i, j, &rate, &has);
            }
    int switched = 0;
    for (PetscInt j = z0; j < z0 + nzl; j++)
        for (PetscInt i = x0; i < x0 + nxl; i++) {
            PetscScalar *v = u[j][i];
            const double phi = v[s->s_phi];
            const int wet = is_wet(s, i, j);
            const ekm_hypo_plane_rate r = cell_plane_rate(&c, i, j);
            const double shear = r.gxz;
            const ekm_switch_rates sr = ekm_switch_rates_of(h, r.exx, r.ezz, shear);
            const double rate_before = rg[j][i][s->s_T];
            rg[j][i][s->s_T] = sr.rate;
            const double PY = ekm_pressure_yield(m, phi);
            const int loose = ekm_switch_loose(m, h, phi);
            const int below_solid = j > 0 && is_solid(s, i, j - 1);
            const double Y = ekm_switch_yield_temperature(m, loose, phi, below_solid,
                                                          below_solid ? u[j - 1][i][s->s_phi] : 0.0);
            if (is_solid(s, i, j)) {
                const ekm_hypo_stress sig = {v[s->s_sxx], v[s->s_syy], v[s->s_szz],
                                             cell_mean_shear(&c, i, j, NULL)};
                const double fY =
                    loose ? NAN : ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &sig);
                double T_qs = sc->numerics.T_floor;
                if (wet) {
                    const ekm_source_coeffs src = ekm_temperature_source_coeffs_plane(
                        m, sc->variant, phi, ekm_g(m, phi), ekm_yield_temperature(m, phi), shear * shear,
                        r.exx, r.ezz);
                    T_qs = fmax(ekm_source_balance(&src), sc->numerics.T_floor);
                }
                const ekm_switch_verdict verdict = ekm_switch_to_flow(h, wet, loose, Y, sig.zz, fY, &sr);
                int go = verdict == EKM_SWITCH_GO;
                if (verdict == EKM_SWITCH_CHECK) {
                    const ekm_cell_properties p = ekm_cell_properties_at(m, sc->variant, phi, T_qs);
                    const ekm_plane_stress e = ekm_stress_plane(&p, sc->variant, r.exx, r.ezz);
                    double mean_rate;
                    (void)cell_mean_shear(&c, i, j, &mean_rate);
                    const double e_xz = p.eta * mean_rate;
                    const double jump =
                        fmax(fmax(fabs(e.szz - sig.zz), fabs(e.sxx - sig.xx)), fabs(e_xz - sig.xz)) /
                        fmax(fabs(sig.zz), fabs(sig.xz));
                    go = ekm_switch_jump_passes(h, jump);
                }
                if (!go)
                    continue;
                if (wet && h->carry_over)
                    v[s->s_T] = ekm_switch_flow_temperature(m, sc->variant, loose, phi, r.ezz, sig.zz, T_qs,
                                                            sc->numerics.T_floor);
                rg[j][i][s->s_phi] = 0.0;
                s->to_flow++;
                switched = 1;
                if (h->log)
                    fprintf(stderr,
                            "ekm: t = %.9g s: cell (%d, %d) solid -> flow: phi %.6f, f_Y %.3e, T := %.3e\n",
                            t, (int)i, (int)j, phi, fY, v[s->s_T]);
            } else {
                const ekm_switch_verdict verdict =
                    ekm_switch_to_solid(h, wet, loose, Y, v[s->s_T], phi, &sr, rate_before);
                if (verdict == EKM_SWITCH_STAY)
                    continue;
                const ekm_plane_stress e = ekm_stress_plane(props(s, i, j), sc->variant, r.exx, r.ezz);
                ekm_hypo_stress sig = {e.sxx, e.syy, e.szz, cell_mean_shear(&c, i, j, NULL)};
                if (verdict == EKM_SWITCH_CHECK &&
                    !ekm_switch_inside_passes(
                        h, ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &sig)))
                    continue;
                if (!h->carry_over) /* tests only (scenario.h) */
                    sig.xx = sig.yy = sig.zz = -PY;
                v[s->s_sxx] = sig.xx;
                v[s->s_syy] = sig.yy;
                v[s->s_szz] = sig.zz;
                rg[j][i][s->s_phi] = 1.0;
                s->to_solid++;
                switched = 1;
                if (h->log)
                    fprintf(
                        stderr,
                        "ekm: t = %.9g s: cell (%d, %d) flow -> solid: phi %.6f, T %.3e, sigma_zz %.6g Pa\n",
                        t, (int)i, (int)j, phi, v[s->s_T], sig.zz);
            }
        }
    PCALL(DMStagVecRestoreArray(s->dm, Rl, &rg));
    PCALL(DMLocalToGlobal(s->dm, Rl, INSERT_VALUES, s->regime)); /* the flags and the rates */
    int any;
    MPI_Allreduce(&switched, &any, 1, MPI_INT, MPI_MAX, s->comm);
    if (any) {
        PCALL(load_solid_flags(s));
        /* a corner that turned solid starts from its flowing stress */
        for (PetscInt j = z0; j < z0 + nzl + ez; j++)
            for (PetscInt i = x0; i < x0 + nxl + ex; i++)
                if (has_vertex_row(s, i, j)) {
                    const double before = s->corner_scratch[corner_index(s, i, j)];
                    if (corner_is_solid(&c, i, j) && !isnan(before))
                        u[j][i][s->s_sxz] = before;
                }
    }
    PCALL(DMStagVecRestoreArray(s->dm, Fr, &fr));
    PCALL(DMStagVecRestoreArray(s->dm, Ul, &u));
    if (any) {
        PCALL(to_unknowns(s, Ul));
        PCALL(DMLocalToGlobal(s->dm, Ul, INSERT_VALUES, U));
    }
    PCALL(DMRestoreLocalVector(s->dm, &Rl));
    PCALL(DMRestoreLocalVector(s->dm, &Fr));
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    return 0;
}

/* After each step: the mass that entered through the boundaries (the flux
 * of the accepted state times the step: the backward-Euler balance). */
static PetscErrorCode poststep(TS ts)
{
    ekm2d_solver *s;
    PCALL(TSGetApplicationContext(ts, &s));
    PetscReal t, dt;
    PCALL(TSGetTime(ts, &t));
    PCALL(TSGetTimeStep(ts, &dt));
    (void)t;
    s->steps++;
    /* the inflow's flux is prescribed: rho_p phi_in |w| over the inlet per unit depth */
    const double dt_step = t - s->t_step;
    const ekm_material *m = &s->sc->material;
    const end_data b = end_at(s, 0, s->t_step);
    const end_data tp = end_at(s, 1, s->t_step);
    if (b.kind == EKM_BC_INFLOW)
        s->mass_in += m->rho_p * b.phi_in * b.w * (double)(b.inlet_hi - b.inlet_lo + 1) * s->dx * dt_step;
    if (tp.kind == EKM_BC_INFLOW)
        s->mass_in +=
            -m->rho_p * tp.phi_in * tp.w * (double)(tp.inlet_hi - tp.inlet_lo + 1) * s->dx * dt_step;
    if (s->hypo) {
        Vec U;
        PCALL(TSGetSolution(ts, &U));
        PCALL(switch_regimes(s, U, t));
    }
    return 0;
}

/* A step's new state is accepted only if no cell closed more than
 * phi_step_max of its gap to phi_cp (the 1D solver's rule, step.h): then
 * phi_cp - phi >= (1 - phi_step_max) (phi_cp - phi_old) > 0 holds. */
static PetscErrorCode check_stage(TS ts, PetscReal t, Vec U, PetscBool *accept)
{
    (void)t;
    ekm2d_solver *s;
    PCALL(TSGetApplicationContext(ts, &s));
    const double phi_cp = s->sc->material.phi_cp, keep = 1.0 - s->sc->numerics.phi_step_max;
    int ok = 1;
    Vec Ul, U0l;
    const PetscScalar ***a, ***b;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(DMGetLocalVector(s->dm, &U0l));
    PCALL(DMGlobalToLocal(s->dm, U, INSERT_VALUES, Ul));
    PCALL(DMGlobalToLocal(s->dm, s->U_start, INSERT_VALUES, U0l));
    PCALL(DMStagVecGetArrayRead(s->dm, Ul, (void *)&a));
    PCALL(DMStagVecGetArrayRead(s->dm, U0l, (void *)&b));
    PetscInt x0, z0, nxl, nzl;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, NULL, NULL, NULL));
    for (PetscInt j = z0; j < z0 + nzl && ok; j++)
        for (PetscInt i = x0; i < x0 + nxl && ok; i++) {
            const double phi = a[j][i][s->s_phi], phi0 = b[j][i][s->s_phi];
            if (!(phi >= -EKM2D_PHI_ROUNDOFF && phi_cp - phi >= keep * (phi_cp - phi0)))
                ok = 0;
        }
    PCALL(DMStagVecRestoreArrayRead(s->dm, Ul, (void *)&a));
    PCALL(DMStagVecRestoreArrayRead(s->dm, U0l, (void *)&b));
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    PCALL(DMRestoreLocalVector(s->dm, &U0l));
    int all;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, s->comm);
    *accept = all ? PETSC_TRUE : PETSC_FALSE;
    return 0;
}

/* Newton's step kept inside the domain the residual is defined on (full
 * steps otherwise: SNESLINESEARCHBASIC): the iterate X - Y has every cell
 * below phi_cp and every wet cell (not frozen empty) at phi > 0 and T > 0;
 * a step that would leave it is shortened to EKM2D_DOMAIN_FRACTION of the
 * way to the boundary (the fraction-to-the-boundary rule of interior-point
 * Newton methods), so that the next iterate is defined instead of a NaN
 * residual that ends the solve (the thesis filling at 1.52 s: nine
 * retries of the step, each DIVERGED_FNORM_NAN at the first iteration). */
#define EKM2D_DOMAIN_FRACTION 0.9

static PetscErrorCode keep_in_domain(SNESLineSearch ls, Vec X, Vec Y, PetscBool *changed, void *vctx)
{
    (void)ls;
    ekm2d_solver *s = vctx;
    const double phi_cp = s->sc->material.phi_cp;
    const PetscScalar ***x, ***y, ***dry;
    Vec Xl, Yl;
    PCALL(DMGetLocalVector(s->dm, &Xl));
    PCALL(DMGetLocalVector(s->dm, &Yl));
    PCALL(DMGlobalToLocal(s->dm, X, INSERT_VALUES, Xl));
    PCALL(DMGlobalToLocal(s->dm, Y, INSERT_VALUES, Yl));
    PCALL(DMStagVecGetArrayRead(s->dm, Xl, (void *)&x));
    PCALL(DMStagVecGetArrayRead(s->dm, Yl, (void *)&y));
    PCALL(DMStagVecGetArrayRead(s->dm, s->dry_local, (void *)&dry));
    PetscInt x0, z0, nxl, nzl;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, NULL, NULL, NULL));
    double alpha = 1.0; /* the iterate is X - alpha Y */
    for (PetscInt j = z0; j < z0 + nzl; j++)
        for (PetscInt i = x0; i < x0 + nxl; i++) {
            const double phi = x[j][i][s->s_phi], dphi = y[j][i][s->s_phi];
            if (phi - dphi >= phi_cp && -dphi > 0.0)
                alpha = fmin(alpha, EKM2D_DOMAIN_FRACTION * (phi_cp - phi) / -dphi);
            if (dry[j][i][s->s_phi] != 0.0)
                continue;
            const double T = x[j][i][s->s_T], dT = y[j][i][s->s_T];
            if (phi - dphi <= 0.0 && dphi > 0.0)
                alpha = fmin(alpha, EKM2D_DOMAIN_FRACTION * phi / dphi);
            if (T - dT <= 0.0 && dT > 0.0)
                alpha = fmin(alpha, EKM2D_DOMAIN_FRACTION * T / dT);
        }
    PCALL(DMStagVecRestoreArrayRead(s->dm, s->dry_local, (void *)&dry));
    PCALL(DMStagVecRestoreArrayRead(s->dm, Yl, (void *)&y));
    PCALL(DMStagVecRestoreArrayRead(s->dm, Xl, (void *)&x));
    PCALL(DMRestoreLocalVector(s->dm, &Yl));
    PCALL(DMRestoreLocalVector(s->dm, &Xl));
    double all;
    MPI_Allreduce(&alpha, &all, 1, MPI_DOUBLE, MPI_MIN, s->comm);
    *changed = PETSC_FALSE;
    if (all < 1.0 && all > 0.0) {
        PCALL(VecScale(Y, all));
        *changed = PETSC_TRUE;
    }
    return 0;
}

/* ---- creation and the run -------------------------------------------------------------------------- */

static ekm_status petsc_fail(ekm_error *err, PetscErrorCode rc, const char *what)
{
    const char *text = NULL;
    PetscErrorMessage(rc, &text, NULL);
    return EKM_FAIL(err, EKM_EINTERNAL, "2D solver: %s failed (PETSc error %d: %s)", what, (int)rc,
                    text ? text : "?");
}

#define TRY(call, what)                            \
    do {                                           \
        PetscErrorCode try_rc_ = (call);           \
        if (try_rc_) {                             \
            ekm2d_solver_destroy(s);               \
            return petsc_fail(err, try_rc_, what); \
        }                                          \
    } while (0)

/* T_unit(_local): T_ref = T_floor at every element's T slot, 1 elsewhere. */
static PetscErrorCode fill_T_unit(ekm2d_solver *s)
{
    PetscScalar ***a;
    PCALL(VecSet(s->T_unit_local, 1.0));
    PCALL(DMStagVecGetArray(s->dm, s->T_unit_local, &a));
    for (PetscInt j = s->gz0; j < s->gz0 + s->gnz; j++)
        for (PetscInt i = s->gx0; i < s->gx0 + s->gnx; i++)
            a[j][i][s->s_T] = s->sc->numerics.T_floor;
    PCALL(DMStagVecRestoreArray(s->dm, s->T_unit_local, &a));
    PCALL(DMLocalToGlobal(s->dm, s->T_unit_local, INSERT_VALUES, s->T_unit));
    return 0;
}

static PetscErrorCode initial_state(ekm2d_solver *s, const ekm_state *init)
{
    const ekm_scenario *sc = s->sc;
    Vec Ul;
    PetscScalar ***u;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(VecSet(Ul, 0.0));
    PCALL(DMStagVecGetArray(s->dm, Ul, &u));
    PetscInt x0, z0, nxl, nzl, ex, ez;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL));
    const double dz = s->dz, phi_dry = sc->numerics.phi_dry;
    const end_data bottom = end_at(s, 0, 0.0), top = end_at(s, 1, 0.0);
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++) {
            if (init) {
                /* every column the 1D state (w on the faces, u at the centres) */
                if (j < s->nz && i < s->nx) {
                    const double phi = init->phi[j];
                    u[j][i][s->s_phi] = phi;
                    u[j][i][s->s_T] =
                        phi >= phi_dry ? fmax(init->T[j], sc->numerics.T_floor) : sc->numerics.T_floor;
                }
                if (j < s->nz)
                    u[j][i][s->s_vx] = side_face(s, i) ? 0.0 : init->u[j];
                u[j][i][s->s_vz] = init->w[j];
                continue;
            }
            if (j < s->nz && i < s->nx) {
                const double lo = j * dz, hi = (j + 1) * dz;
                const double cover = sc->layer_height >= hi   ? 1.0
                                     : sc->layer_height <= lo ? 0.0
                                                              : (sc->layer_height - lo) / dz;
                const double phi = sc->phi_init * cover;
                u[j][i][s->s_phi] = phi;
                u[j][i][s->s_T] = phi > phi_dry ? sc->T_init : sc->numerics.T_floor;
            }
            if (j < s->nz) {
                const int wet = sc->phi_init * (sc->layer_height > j * dz ? 1.0 : 0.0) > phi_dry;
                const double z = (j + 0.5) * dz;
                u[j][i][s->s_vx] = wet && !side_face(s, i) ? sc->u_init + sc->shear_rate_init * z : 0.0;
            }
            /* the ends' prescribed vz from the start (an open inlet: its w) */
            u[j][i][s->s_vz] = j == 0 ? end_w(s, &bottom, i) : j == s->nz ? end_w(s, &top, i) : 0.0;
        }
    PCALL(DMStagVecRestoreArray(s->dm, Ul, &u));
    PCALL(to_unknowns(s, Ul));
    PCALL(DMLocalToGlobal(s->dm, Ul, INSERT_VALUES, s->U));
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    return 0;
}

static PetscErrorCode total_mass(ekm2d_solver *s, Vec U, double *mass, double *phi_max)
{
    Vec Ul;
    const PetscScalar ***u;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(DMGlobalToLocal(s->dm, U, INSERT_VALUES, Ul));
    PCALL(DMStagVecGetArrayRead(s->dm, Ul, (void *)&u));
    PetscInt x0, z0, nxl, nzl;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, NULL, NULL, NULL));
    double loc[2] = {0.0, 0.0}, glob[2];
    for (PetscInt j = z0; j < z0 + nzl; j++)
        for (PetscInt i = x0; i < x0 + nxl; i++) {
            loc[0] += u[j][i][s->s_phi];
            loc[1] = fmax(loc[1], u[j][i][s->s_phi]);
        }
    PCALL(DMStagVecRestoreArrayRead(s->dm, Ul, (void *)&u));
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    MPI_Allreduce(&loc[0], &glob[0], 1, MPI_DOUBLE, MPI_SUM, s->comm);
    MPI_Allreduce(&loc[1], &glob[1], 1, MPI_DOUBLE, MPI_MAX, s->comm);
    *mass = s->sc->material.rho_p * glob[0] * s->dx * s->dz;
    *phi_max = glob[1];
    return 0;
}

/* Newton's convergence test: PETSc's (the scaled rows' 2-norm below
 * atol = 1e-11 sqrt(N), or 1e-12 of the start), or the mass and momentum
 * rows so and every temperature row below EKM2D_T_ROW_TOL. In a dense
 * cell at a wall corner of a settling bed (phi 0.603, T 7e-8 m^2/s^2 in
 * the thesis filling at 0.76 s) Newton converges only linearly in the T
 * row (the residual falls 5x per iteration, at any step down to 4e-6 s;
 * with T slaved to the shear rate the stress hardly depends on the rate
 * there, docs/model.md "The thesis's 2D cases"), and the steps were
 * retried until the run stopped. A temperature row satisfied to 1e-8 of
 * its terms is far inside the step's error tolerance; the mass rows,
 * whose residual is the mass balance's error, keep the full tolerance. */
#define EKM2D_T_ROW_TOL     1e-8
#define EKM2D_NEWTON_MAX_IT 12

static PetscErrorCode converged_test(SNES snes, PetscInt it, PetscReal xnorm, PetscReal snorm,
                                     PetscReal fnorm, SNESConvergedReason *reason, void *vctx)
{
    ekm2d_solver *s = vctx;
    PCALL(SNESConvergedDefault(snes, it, xnorm, snorm, fnorm, reason, NULL));
    /* also at the last iteration: a solve that meets this test there has converged */
    if ((*reason != SNES_CONVERGED_ITERATING && *reason != SNES_DIVERGED_MAX_IT) || it == 0)
        return 0;
    Vec F, Fl;
    PCALL(SNESGetFunction(snes, &F, NULL, NULL));
    PCALL(DMGetLocalVector(s->dm, &Fl));
    PCALL(VecSet(Fl, 0.0));
    PCALL(DMGlobalToLocal(s->dm, F, INSERT_VALUES, Fl));
    const PetscScalar ***f;
    PCALL(DMStagVecGetArrayRead(s->dm, Fl, (void *)&f));
    PetscInt x0, z0, nxl, nzl, ex, ez;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, &ex, &ez, NULL));
    double loc[2] = {0.0, 0.0}; /* sum of squares of the other rows, largest |T row| */
    for (PetscInt j = z0; j < z0 + nzl + ez; j++)
        for (PetscInt i = x0; i < x0 + nxl + ex; i++) {
            if (has_cell_rows(s, i, j)) {
                loc[0] += f[j][i][s->s_phi] * f[j][i][s->s_phi];
                loc[1] = fmax(loc[1], fabs(f[j][i][s->s_T]));
                if (s->hypo)
                    loc[0] += f[j][i][s->s_sxx] * f[j][i][s->s_sxx] + f[j][i][s->s_syy] * f[j][i][s->s_syy] +
                              f[j][i][s->s_szz] * f[j][i][s->s_szz];
            }
            if (has_vertex_row(s, i, j))
                loc[0] += f[j][i][s->s_sxz] * f[j][i][s->s_sxz];
            if (has_xface_row(s, i, j))
                loc[0] += f[j][i][s->s_vx] * f[j][i][s->s_vx];
            if (has_zface_row(s, i, j))
                loc[0] += f[j][i][s->s_vz] * f[j][i][s->s_vz];
        }
    PCALL(DMStagVecRestoreArrayRead(s->dm, Fl, (void *)&f));
    PCALL(DMRestoreLocalVector(s->dm, &Fl));
    double glob[2];
    MPI_Allreduce(&loc[0], &glob[0], 1, MPI_DOUBLE, MPI_SUM, s->comm);
    MPI_Allreduce(&loc[1], &glob[1], 1, MPI_DOUBLE, MPI_MAX, s->comm);
    PetscReal atol;
    PCALL(SNESGetTolerances(snes, &atol, NULL, NULL, NULL, NULL));
    if (sqrt(glob[0]) < atol && glob[1] < EKM2D_T_ROW_TOL)
        *reason = SNES_CONVERGED_FNORM_ABS;
    return 0;
}

static PetscErrorCode count_newton(TS ts, PetscInt step, PetscReal t, Vec U, void *vctx)
{
    (void)step;
    (void)t;
    (void)U;
    ekm2d_solver *s = vctx;
    SNES snes;
    PetscInt its;
    PCALL(TSGetSNES(ts, &snes));
    PCALL(SNESGetIterationNumber(snes, &its));
    s->newton += its;
    return 0;
}

/* The linear solver: LU, PETSc's own; on several ranks every rank factors
 * the whole (small) system so (PCREDUNDANT): MUMPS' parallel LU of the
 * same system was 14x slower than one rank's LU (docs/model.md "2D
 * solver"). */
static PetscErrorCode set_direct_solve(KSP ksp, int ranks)
{
    PC pc;
    PCALL(KSPSetType(ksp, KSPPREONLY));
    PCALL(KSPGetPC(ksp, &pc));
    if (ranks == 1) {
        PCALL(PCSetType(pc, PCLU));
        /* PETSc's LU counts a pivot below 100 eps of its row's sum as
         * zero; the temperature columns are scaled by T_ref = T_floor (the
         * unknowns are T / T_ref), so a warm cell's T pivot is that small
         * beside the row's phi and velocity entries. Elimination without
         * row interchanges does not depend on the scale of a column (every
         * entry of the column scales alike): only an exact zero counts. */
        return PCFactorSetZeroPivot(pc, 1e-300);
    }
    KSP inner;
    PCALL(PCSetType(pc, PCREDUNDANT));
    PCALL(PCRedundantGetKSP(pc, &inner));
    return set_direct_solve(inner, 1);
}

/* The Jacobian by finite differences over a coloring of its nonzeros
 * (PETSc's TSComputeIJacobianDefaultColor, which takes the coloring
 * composed on the matrix, made here as it makes it), each column perturbed relative to its own value (type
 * "ds"; -mat_fd_type still overrides). PETSc's default ("wp") perturbs
 * every column by one h = 1.5e-8 sqrt(1 + ||U||): with stresses of
 * hundreds of Pa in U a T of 1e-10 m^2/s^2 was moved by 1e-6, its column
 * missed the source's derivative, and Newton converged only linearly in
 * the T rows of cold dense cells (docs/model.md "2D solver"). */
static PetscErrorCode ijacobian(TS ts, PetscReal t, Vec U, Vec Udot, PetscReal shift, Mat J, Mat B, void *ctx)
{
    MatFDColoring color;
    PCALL(PetscObjectQuery((PetscObject)B, "TSMatFDColoring", (PetscObject *)&color));
    if (!color) { /* the first call (the matrix is assembled by then) */
        ISColoring iscoloring;
        MatColoring mc; /* of the matrix's nonzeros: DMStag has no coloring of its own */
        PCALL(MatColoringCreate(B, &mc));
        PCALL(MatColoringSetDistance(mc, 2));
        PCALL(MatColoringSetType(mc, MATCOLORINGSL));
        PCALL(MatColoringSetFromOptions(mc));
        PCALL(MatColoringApply(mc, &iscoloring));
        PCALL(MatColoringDestroy(&mc));
        PCALL(MatFDColoringCreate(B, iscoloring, &color));
        PCALL(MatFDColoringSetFunction(color, (PetscErrorCode(*)(void))(void (*)(void))SNESTSFormFunction,
                                       (void *)ts));
        PCALL(MatFDColoringSetType(color, MATMFFD_DS));
        PCALL(MatFDColoringSetFromOptions(color));
        PCALL(MatFDColoringSetUp(B, iscoloring, color));
        PCALL(ISColoringDestroy(&iscoloring));
        PCALL(PetscObjectCompose((PetscObject)B, "TSMatFDColoring", (PetscObject)color));
        PCALL(PetscObjectDereference((PetscObject)color));
    }
    return TSComputeIJacobianDefaultColor(ts, t, U, Udot, shift, J, B, ctx);
}

ekm_status ekm2d_solver_create(const ekm_scenario *sc, MPI_Comm comm, const ekm_state *init,
                               ekm2d_solver **out, ekm_error *err)
{
    *out = NULL;
    ekm_status st = ekm2d_supported(sc, err);
    if (st != EKM_OK)
        return st;
    if (init && (init->n != sc->cells || fabs(init->n * init->dz - sc->length) > 1e-12 * sc->length))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: the 1D initial state has %d cells over %g m, the scenario %d over %g m",
                        sc->source, init->n, init->n * init->dz, sc->cells, sc->length);
    ekm2d_solver *s = calloc(1, sizeof *s);
    if (!s)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D solver)");
    PetscBool fully_implicit = PETSC_FALSE;
    PetscOptionsGetBool(NULL, NULL, "-ekm_fully_implicit", &fully_implicit, NULL);
    if (!fully_implicit) {
        s->sc = sc;
        s->comm = comm;
        st = ekm2d_step_create(sc, comm, init, &s->semi, err);
        if (st != EKM_OK) {
            free(s);
            return st;
        }
        *out = s;
        return EKM_OK;
    }
    s->sc = sc;
    s->comm = comm;
    s->nx = sc->cells_x;
    s->nz = sc->cells;
    s->dx = sc->width / sc->cells_x;
    s->dz = sc->length / sc->cells;
    s->periodic = sc->periodic_x;
    s->hypo = sc->hypo.enabled != 0;
    s->s_sxx = s->s_syy = s->s_szz = s->s_sxz = -1;
    s->g_x = ekm_scenario_gravity_x(sc);
    s->g_z = ekm_scenario_gravity_z(sc);
    s->side_conductance[0] = 1.0 / (0.5 * s->dx + sc->left.slip_length);
    s->side_conductance[1] = 1.0 / (0.5 * s->dx + sc->right.slip_length);
    const ekm_bc *ends[2] = {&sc->bottom, &sc->top};
    for (int k = 0; k < 2; k++) {
        /* the inlet: the faces whose centres lie in it (the reader checked it holds one) */
        s->inlet_lo[k] = 0;
        s->inlet_hi[k] = s->nx - 1;
        if (ends[k]->kind == EKM_BC_INFLOW && isfinite(ends[k]->inlet_width)) {
            const double lo = ends[k]->inlet_x - 0.5 * ends[k]->inlet_width;
            const double hi = ends[k]->inlet_x + 0.5 * ends[k]->inlet_width;
            s->inlet_lo[k] = s->nx;
            s->inlet_hi[k] = -1;
            for (PetscInt i = 0; i < s->nx; i++) {
                const double xc = (i + 0.5) * s->dx;
                if (xc >= lo && xc <= hi) {
                    s->inlet_lo[k] = i < s->inlet_lo[k] ? i : s->inlet_lo[k];
                    s->inlet_hi[k] = i;
                }
            }
            if (s->inlet_hi[k] < s->inlet_lo[k]) {
                ekm2d_solver_destroy(s);
                return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] inlet_width: the inlet holds no face centre",
                                sc->source, k ? "top" : "bottom");
            }
        }
    }
    TRY(DMStagCreate2d(comm, s->periodic ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, s->nx,
                       s->nz, PETSC_DECIDE, PETSC_DECIDE, s->hypo ? 1 : 0, 1, s->hypo ? 5 : 2,
                       DMSTAG_STENCIL_BOX, 2, NULL, NULL, &s->dm),
        "DMStagCreate2d");
    TRY(DMSetFromOptions(s->dm), "DMSetFromOptions");
    TRY(DMSetUp(s->dm), "DMSetUp");
    TRY(DMStagSetUniformCoordinatesProduct(s->dm, 0.0, sc->width, 0.0, sc->length, 0.0, 0.0),
        "DMStagSetUniformCoordinatesProduct");
    TRY(DMStagGetLocationSlot(s->dm, DMSTAG_ELEMENT, 0, &s->s_phi), "DMStagGetLocationSlot");
    TRY(DMStagGetLocationSlot(s->dm, DMSTAG_ELEMENT, 1, &s->s_T), "DMStagGetLocationSlot");
    TRY(DMStagGetLocationSlot(s->dm, DMSTAG_LEFT, 0, &s->s_vx), "DMStagGetLocationSlot");
    TRY(DMStagGetLocationSlot(s->dm, DMSTAG_DOWN, 0, &s->s_vz), "DMStagGetLocationSlot");
    if (s->hypo) {
        TRY(DMStagGetLocationSlot(s->dm, DMSTAG_ELEMENT, 2, &s->s_sxx), "DMStagGetLocationSlot");
        TRY(DMStagGetLocationSlot(s->dm, DMSTAG_ELEMENT, 3, &s->s_syy), "DMStagGetLocationSlot");
        TRY(DMStagGetLocationSlot(s->dm, DMSTAG_ELEMENT, 4, &s->s_szz), "DMStagGetLocationSlot");
        TRY(DMStagGetLocationSlot(s->dm, DMSTAG_DOWN_LEFT, 0, &s->s_sxz), "DMStagGetLocationSlot");
    }
    TRY(DMStagGetGhostCorners(s->dm, &s->gx0, &s->gz0, NULL, &s->gnx, &s->gnz, NULL),
        "DMStagGetGhostCorners");
    s->prop = calloc((size_t)s->gnx * (size_t)s->gnz, sizeof *s->prop);
    s->wet = calloc((size_t)s->gnx * (size_t)s->gnz, 1);
    const size_t ncell = (size_t)s->gnx * (size_t)s->gnz,
                 ncorner = (size_t)(s->gnx + 1) * (size_t)(s->gnz + 1);
    s->solid = calloc(ncell, 1);
    s->knorm = calloc(ncell, sizeof *s->knorm);
    s->ktr = calloc(ncell, sizeof *s->ktr);
    s->knorm_c = calloc(ncorner, sizeof *s->knorm_c);
    s->corner_scratch = calloc(ncorner, sizeof *s->corner_scratch);
    if (!s->prop || !s->wet || !s->solid || !s->knorm || !s->ktr || !s->knorm_c || !s->corner_scratch) {
        ekm2d_solver_destroy(s);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D solver, %d x %d cells)", sc->cells_x, sc->cells);
    }
    TRY(DMCreateGlobalVector(s->dm, &s->U), "DMCreateGlobalVector");
    TRY(VecDuplicate(s->U, &s->U_start), "VecDuplicate");
    TRY(VecDuplicate(s->U, &s->row_scale), "VecDuplicate");
    TRY(VecSet(s->row_scale, 1.0), "VecSet");
    TRY(VecDuplicate(s->U, &s->row_mag), "VecDuplicate");
    TRY(VecSet(s->row_mag, 0.0), "VecSet");
    TRY(VecDuplicate(s->U, &s->row_age), "VecDuplicate");
    TRY(VecSet(s->row_age, 0.0), "VecSet");
    TRY(VecDuplicate(s->U, &s->lte_atol), "VecDuplicate");
    TRY(VecSet(s->lte_atol, EKM2D_LTE_EXCLUDED), "VecSet");
    TRY(VecDuplicate(s->U, &s->regime), "VecDuplicate");
    TRY(VecSet(s->regime, 0.0), "VecSet");
    TRY(DMCreateLocalVector(s->dm, &s->dry_local), "DMCreateLocalVector");
    TRY(VecSet(s->dry_local, 0.0), "VecSet");
    TRY(DMCreateLocalVector(s->dm, &s->T_unit_local), "DMCreateLocalVector");
    TRY(VecDuplicate(s->U, &s->T_unit), "VecDuplicate");
    TRY(fill_T_unit(s), "the temperature scale");
    TRY(initial_state(s, init), "initial state");

    TRY(TSCreate(comm, &s->ts), "TSCreate");
    TRY(TSSetDM(s->ts, s->dm), "TSSetDM");
    TRY(TSSetApplicationContext(s->ts, s), "TSSetApplicationContext");
    TRY(TSSetType(s->ts, TSBDF), "TSSetType");
    TRY(TSBDFSetOrder(s->ts, 1), "TSBDFSetOrder");
    TRY(TSSetIFunction(s->ts, NULL, ifunction, s), "TSSetIFunction");
    TRY(DMSetMatType(s->dm, MATAIJ), "DMSetMatType");
    TRY(DMCreateMatrix(s->dm, &s->J), "DMCreateMatrix");
    TRY(TSSetIJacobian(s->ts, s->J, s->J, ijacobian, NULL), "TSSetIJacobian");
    TRY(TSSetPreStep(s->ts, prestep), "TSSetPreStep");
    TRY(TSSetPostStep(s->ts, poststep), "TSSetPostStep");
    TRY(TSMonitorSet(s->ts, count_newton, s, NULL), "TSMonitorSet");
    TRY(TSSetMaxSNESFailures(s->ts, -1), "TSSetMaxSNESFailures");
    TRY(TSSetMaxStepRejections(s->ts, -1), "TSSetMaxStepRejections");
    TRY(TSSetExactFinalTime(s->ts, TS_EXACTFINALTIME_MATCHSTEP), "TSSetExactFinalTime");
    TRY(TSSetTime(s->ts, 0.0), "TSSetTime");
    const double dt0 = fmin(sc->numerics.dt_max, fmin(1e-4, sc->output_dt));
    TRY(TSSetTimeStep(s->ts, dt0), "TSSetTimeStep");
    TRY(TSSetTolerances(s->ts, EKM2D_LTE_ATOL, s->lte_atol, EKM2D_LTE_RTOL, NULL), "TSSetTolerances");
    TSAdapt adapt;
    TRY(TSGetAdapt(s->ts, &adapt), "TSGetAdapt");
    TRY(TSAdaptSetType(adapt, TSADAPTBASIC), "TSAdaptSetType");
    TRY(TSAdaptSetStepLimits(adapt, sc->numerics.dt_min, sc->numerics.dt_max), "TSAdaptSetStepLimits");
    SNES snes;
    TRY(TSGetSNES(s->ts, &snes), "TSGetSNES");
    TRY(TSSetFunctionDomainError(s->ts, check_stage), "TSSetFunctionDomainError");
    TRY(SNESSetComputeInitialGuess(snes, initial_guess, s), "SNESSetComputeInitialGuess");
    TRY(SNESSetConvergenceTest(snes, converged_test, s, NULL), "SNESSetConvergenceTest");
    /* Converged when the scaled rows' RMS is below 1e-11 (each row is scaled
     * by its terms' magnitude; with 1e-12 the start-up of a tilted layer at
     * rest finds no descent below it at t = 0), or 1e-12 of the start. No step-norm test
     * (stol 0): with PETSc's default a line search that stalled counted as
     * converged, and steps were accepted with residuals of 1e-4. The mass
     * balance of a step is then exact to the phi rows' residual (the fluxes
     * telescope for any iterate): about 1e-14 relative per step. */
    PetscInt n_rows;
    TRY(VecGetSize(s->U, &n_rows), "VecGetSize");
    TRY(SNESSetTolerances(snes, 1e-11 * sqrt((double)n_rows), 1e-12, 0.0, EKM2D_NEWTON_MAX_IT, 100000),
        "SNESSetTolerances");
    /* full Newton steps: a solve that does not converge is caught within
     * EKM2D_NEWTON_MAX_IT iterations and its step retried shorter (the
     * thesis filling's first 0.1 s on 9 x 30 cells: 20 s; with the
     * backtracking line search and 50 iterations, 56 s) */
    SNESLineSearch linesearch;
    TRY(SNESGetLineSearch(snes, &linesearch), "SNESGetLineSearch");
    TRY(SNESLineSearchSetType(linesearch, SNESLINESEARCHBASIC), "SNESLineSearchSetType");
    TRY(SNESLineSearchSetPreCheck(linesearch, keep_in_domain, s), "SNESLineSearchSetPreCheck");
    KSP ksp;
    TRY(SNESGetKSP(snes, &ksp), "SNESGetKSP");
    int size;
    MPI_Comm_size(comm, &size);
    TRY(set_direct_solve(ksp, size), "the linear solver");
    TRY(TSSetFromOptions(s->ts), "TSSetFromOptions");
    *out = s;
    return EKM_OK;
}

void ekm2d_solver_destroy(ekm2d_solver *s)
{
    if (!s)
        return;
    ekm2d_step_destroy(s->semi);
    TSDestroy(&s->ts);
    MatDestroy(&s->J);
    VecDestroy(&s->U);
    VecDestroy(&s->U_start);
    VecDestroy(&s->row_scale);
    VecDestroy(&s->row_mag);
    VecDestroy(&s->row_age);
    VecDestroy(&s->lte_atol);
    VecDestroy(&s->T_unit);
    VecDestroy(&s->T_unit_local);
    VecDestroy(&s->dry_local);
    VecDestroy(&s->regime);
    DMDestroy(&s->dm);
    free(s->prop);
    free(s->wet);
    free(s->solid);
    free(s->knorm);
    free(s->ktr);
    free(s->knorm_c);
    free(s->corner_scratch);
    free(s);
}

ekm_status ekm2d_solver_advance(ekm2d_solver *s, double t_to, ekm_error *err)
{
    if (s->semi)
        return ekm2d_step_advance(s->semi, t_to, err);
    PetscReal t;
    TSGetTime(s->ts, &t);
    if (!(t_to > t))
        return EKM_OK;
    PetscErrorCode rc = TSSetMaxTime(s->ts, t_to);
    if (!rc)
        rc = TSSetMaxSteps(s->ts, PETSC_MAX_INT);
    if (!rc)
        rc = TSSolve(s->ts, s->U);
    if (rc && s->dt_failed > 0.0) {
        TSGetTime(s->ts, &t);
        return EKM_FAIL(
            err, EKM_ENUMERIC,
            "%s: the 2D solver stopped at t = %.9g s: the step fell to %.3g s, below dt_min = %g s "
            "(Newton did not converge, or a step would close more than phi_step_max of the gap to "
            "phi_cp)",
            s->sc->source, t, s->dt_failed, s->sc->numerics.dt_min);
    }
    if (rc)
        return petsc_fail(err, rc, "TSSolve");
    TSConvergedReason reason;
    TSGetConvergedReason(s->ts, &reason);
    PetscInt rej;
    TSGetStepRejections(s->ts, &rej);
    s->rejected = rej; /* TS counts over its lifetime */
    TSGetTime(s->ts, &t);
    if (reason < 0) {
        PetscReal dt;
        TSGetTimeStep(s->ts, &dt);
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "%s: the 2D solver stopped at t = %.9g s (TS: %s, last step %.3g s; dt_min %.3g s)",
                        s->sc->source, t, TSConvergedReasons[reason], dt, s->sc->numerics.dt_min);
    }
    if (fabs(t - t_to) > 1e-9 * fmax(1.0, fabs(t_to)))
        return EKM_FAIL(err, EKM_ENUMERIC, "%s: the 2D solver stopped at t = %.9g s before %.9g s",
                        s->sc->source, t, t_to);
    return EKM_OK;
}

/* Cell-centred output fields of the local cells into the natural-order
 * vector fields (one dof per cell, nfields dofs per cell). */
static PetscErrorCode local_fields(ekm2d_solver *s, DM dmf, Vec nat)
{
    const ekm_scenario *sc = s->sc;
    Vec Ul;
    const PetscScalar ***u, ***dry;
    PCALL(DMGetLocalVector(s->dm, &Ul));
    PCALL(DMGlobalToLocal(s->dm, s->U, INSERT_VALUES, Ul));
    PCALL(to_physical(s, Ul));
    PCALL(DMStagVecGetArrayRead(s->dm, Ul, (void *)&u));
    /* the output classifies cells by the state itself */
    Vec dryl;
    PetscScalar ***dw;
    PCALL(DMGetLocalVector(s->dm, &dryl));
    PCALL(VecSet(dryl, 0.0));
    PCALL(DMStagVecGetArray(s->dm, dryl, &dw));
    freeze_step_data(s, u, dw);
    PCALL(DMStagVecRestoreArray(s->dm, dryl, &dw));
    PCALL(DMStagVecGetArrayRead(s->dm, dryl, (void *)&dry));
    (void)compute_properties(s, u, dry);
    PCALL(load_solid_flags(s)); /* after the last step's switches */
    eval_ctx c = {.u = u, .frozen = dry, .s = s};
    PetscReal t;
    PCALL(TSGetTime(s->ts, &t));
    c.bottom = end_at(s, 0, t);
    c.top = end_at(s, 1, t);
    PetscScalar ***o;
    PCALL(DMStagVecGetArray(dmf, nat, &o));
    PetscInt x0, z0, nxl, nzl;
    PCALL(DMStagGetCorners(s->dm, &x0, &z0, NULL, &nxl, &nzl, NULL, NULL, NULL, NULL));
    for (PetscInt j = z0; j < z0 + nzl; j++)
        for (PetscInt i = x0; i < x0 + nxl; i++) {
            PetscScalar *v = o[j][i];
            const int wet = is_wet(s, i, j);
            v[EKM2D_PHI] = u[j][i][s->s_phi];
            v[EKM2D_VX] = wet ? 0.5 * (u[j][i][s->s_vx] + u[j][i + 1][s->s_vx]) : 0.0;
            v[EKM2D_VZ] = wet ? 0.5 * (u[j][i][s->s_vz] + u[j + 1][i][s->s_vz]) : 0.0;
            v[EKM2D_T] = wet ? u[j][i][s->s_T] : 0.0;
            const ekm_plane_stress st = cell_stress(&c, i, j);
            v[EKM2D_P] = wet ? st.P : 0.0;
            v[EKM2D_SXX] = st.sxx;
            v[EKM2D_SZZ] = st.szz;
            v[EKM2D_SXZ] = wet ? cell_mean_shear(&c, i, j, NULL) : 0.0;
            v[EKM2D_REGIME] = !wet                                       ? EKM_REGIME_EMPTY
                              : is_solid(s, i, j)                        ? EKM_REGIME_SOLID
                              : u[j][i][s->s_phi] <= sc->material.phi_co ? EKM_REGIME_KINETIC
                                                                         : EKM_REGIME_DENSE;
        }
    PCALL(DMStagVecRestoreArray(dmf, nat, &o));
    PCALL(DMStagVecRestoreArrayRead(s->dm, dryl, (void *)&dry));
    PCALL(DMRestoreLocalVector(s->dm, &dryl));
    PCALL(DMStagVecRestoreArrayRead(s->dm, Ul, (void *)&u));
    PCALL(DMRestoreLocalVector(s->dm, &Ul));
    return 0;
}

static PetscErrorCode gather_fields(ekm2d_solver *s, double *const fields[EKM2D_NFIELDS])
{
    /* a cell-only DMStag with the same layout carries the output fields */
    DM dmf;
    PCALL(DMStagCreateCompatibleDMStag(s->dm, 0, 0, EKM2D_NFIELDS, 0, &dmf));
    Vec loc, glob, nat, all;
    PCALL(DMCreateLocalVector(dmf, &loc));
    PCALL(VecSet(loc, 0.0));
    PCALL(local_fields(s, dmf, loc));
    PCALL(DMCreateGlobalVector(dmf, &glob));
    PCALL(DMLocalToGlobal(dmf, loc, INSERT_VALUES, glob));
    /* to the natural (x fastest, then z) order on rank 0 */
    DM da;
    PCALL(DMStagVecSplitToDMDA(dmf, glob, DMSTAG_ELEMENT, -EKM2D_NFIELDS, &da, &nat));
    Vec natural;
    PCALL(DMDACreateNaturalVector(da, &natural));
    PCALL(DMDAGlobalToNaturalBegin(da, nat, INSERT_VALUES, natural));
    PCALL(DMDAGlobalToNaturalEnd(da, nat, INSERT_VALUES, natural));
    VecScatter sc0;
    PCALL(VecScatterCreateToZero(natural, &sc0, &all));
    PCALL(VecScatterBegin(sc0, natural, all, INSERT_VALUES, SCATTER_FORWARD));
    PCALL(VecScatterEnd(sc0, natural, all, INSERT_VALUES, SCATTER_FORWARD));
    int rank;
    MPI_Comm_rank(s->comm, &rank);
    if (rank == 0) {
        const PetscScalar *a;
        PCALL(VecGetArrayRead(all, &a));
        const size_t ncell = (size_t)s->nx * (size_t)s->nz;
        for (size_t k = 0; k < ncell; k++)
            for (int q = 0; q < EKM2D_NFIELDS; q++)
                fields[q][k] = a[k * EKM2D_NFIELDS + (size_t)q];
        PCALL(VecRestoreArrayRead(all, &a));
    }
    PCALL(VecScatterDestroy(&sc0));
    PCALL(VecDestroy(&all));
    PCALL(VecDestroy(&natural));
    PCALL(VecDestroy(&nat));
    PCALL(DMDestroy(&da));
    PCALL(VecDestroy(&glob));
    PCALL(VecDestroy(&loc));
    PCALL(DMDestroy(&dmf));
    return 0;
}

ekm_status ekm2d_solver_fields(ekm2d_solver *s, double *const fields[EKM2D_NFIELDS], ekm_error *err)
{
    if (s->semi)
        return ekm2d_step_fields(s->semi, fields, err);
    PetscErrorCode rc = gather_fields(s, fields);
    return rc ? petsc_fail(err, rc, "gathering the output fields") : EKM_OK;
}

ekm_status ekm2d_solver_stats(ekm2d_solver *s, ekm2d_stats *out, ekm_error *err)
{
    if (s->semi) {
        ekm2d_step_info in;
        ekm_status st = ekm2d_step_stats(s->semi, &in, err);
        if (st != EKM_OK)
            return st;
        *out = (ekm2d_stats){.t = in.t,
                             .steps = in.steps,
                             .rejected = in.rejected,
                             .newton = in.newton_total,
                             .mass = in.mass,
                             .mass_in = in.mass_in,
                             .phi_max = in.phi_max,
                             .cell_updates = (double)in.steps * s->sc->cells_x * s->sc->cells,
                             .to_solid = in.to_solid,
                             .to_flow = in.to_flow};
        return EKM_OK;
    }
    PetscReal t;
    PetscErrorCode rc = TSGetTime(s->ts, &t);
    if (rc)
        return petsc_fail(err, rc, "the solver's time");
    out->t = t;
    out->steps = s->steps;
    out->rejected = s->rejected;
    out->newton = s->newton;
    double mass = NAN, phi_max = NAN;
    rc = total_mass(s, s->U, &mass, &phi_max);
    if (rc)
        return petsc_fail(err, rc, "the total mass");
    out->mass = mass;
    out->mass_in = s->mass_in;
    out->phi_max = phi_max;
    out->cell_updates = (double)s->steps * s->nx * s->nz;
    long sw[2] = {s->to_solid, s->to_flow}, all[2];
    MPI_Allreduce(sw, all, 2, MPI_LONG, MPI_SUM, s->comm);
    out->to_solid = all[0];
    out->to_flow = all[1];
    return EKM_OK;
}
