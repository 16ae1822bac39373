/* step2d.c: the semi-implicit 2D step (step2d.h): phases 1-4 and 7 and
 * the order of all phases (ekm2d_step_apply); the velocity system is
 * velocity2d.c's, the temperature temperature2d.c's, the solid regime
 * regime2d.c's, the stepper's life cycle setup2d.c's.  Units: SI
 * throughout (phi [-], T [m^2/s^2], v [m/s], rho = rho_p phi [kg/m^3],
 * fluxes F = v phi [m/s]). */
#include "step2d_impl.h"

#include "bc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)

/* The thermal relaxation limit at the end of a step (step.c's factor). */
#define EKM2D_THERMAL_END_FACTOR 1.01

ekm_status ekm2d_step_supported(const ekm_scenario *sc, ekm_error *err)
{
    if (sc->numerics.normal_coupling != EKM_COUPLING_IMPLICIT)
        return EKM_FAIL(
            err, EKM_EUNAVAILABLE,
            "%s: [numerics] normal_coupling = explicit: the 2D step couples the pressure implicitly",
            sc->source);
    if (sc->numerics.convection == EKM_CONVECTION_TVD)
        return EKM_FAIL(err, EKM_EUNAVAILABLE,
                        "%s: [numerics] convection = tvd: the 2D step is first-order upwind (issue 33)",
                        sc->source);
    const ekm_bc *ends[2] = {&sc->bottom, &sc->top};
    for (int k = 0; k < 2; k++) {
        const ekm_bc *bc = ends[k];
        if (bc->kind != EKM_BC_WALL && bc->kind != EKM_BC_FREE && bc->kind != EKM_BC_INFLOW)
            return EKM_FAIL(err, EKM_EUNAVAILABLE,
                            "%s: [%s] type = %s: the 2D step has wall, free and inflow ends (issue 33)",
                            sc->source, k ? "top" : "bottom", ekm_boundary_kind_name(bc->kind));
        if (bc->kind == EKM_BC_WALL && isfinite(bc->shear_rate))
            return EKM_FAIL(err, EKM_EUNAVAILABLE,
                            "%s: [%s] shear_rate: a wall whose speed follows the gap is not in the 2D step",
                            sc->source, k ? "top" : "bottom");
        if (bc->kind == EKM_BC_WALL && isfinite(bc->pressure) && !k)
            return EKM_FAIL(err, EKM_EUNAVAILABLE,
                            "%s: [bottom] pressure: only the top wall may be held at a pressure", sc->source);
    }
    return EKM_OK;
}

/* ---- phase 1: boundaries ------------------------------------------------------------------------ */

/* A moving top wall's speed dL/dt for a step of dt [m/s] (bc.h): the
 * wall moves as one body under the mean load of the top cells at the
 * step's start (collective). */
static double gap_rate(const ekm2d_step *st, PetscScalar ***u, double dt)
{
    const ekm2d_grid *g = &st->g;
    double sum[2] = {0.0, 0.0}, all[2];
    if (g->z0 + g->nzl == g->nz) {
        const PetscInt j = g->nz - 1;
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            const int solid = g->s_solid >= 0 && u[j][i][g->s_solid] > 0.5;
            const ekm_bc_top_cell c =
                ekm_bc_top_cell_load(st->sc, u[j][i][g->s_phi], u[j][i][g->s_T], solid,
                                     solid ? u[j][i][g->s_szz] : 0.0, u[j][i][g->s_vz], g->dz, dt);
            sum[0] += c.load;
            sum[1] += c.stiffness;
        }
    }
    MPI_Allreduce(sum, all, 2, MPI_DOUBLE, MPI_SUM, g->comm);
    const ekm_bc_top_cell mean = {.load = all[0] / g->nx, .stiffness = all[1] / g->nx};
    return ekm_bc_gap_rate_of(st->sc, mean, g->nz, g->dz);
}

/* The ends at the step's start and the face velocities they fix: vz of
 * the end faces (an inlet's w, a wall's speed, a free end the adjacent
 * interior face's), vx of side-wall faces (0); gravity at the end of the
 * step (step.c's rule).  A moving top wall: its speed of the step. */
static void boundaries(ekm2d_step *st, PetscScalar ***u, double dt)
{
    ekm2d_grid *g = &st->g;
    st->bottom = ekm2d_grid_end(g, 0, st->t);
    st->top = ekm2d_grid_end(g, 1, st->t);
    st->dz_start = st->dz_new = g->dz;
    if (g->top_moving) {
        st->gap_rate = gap_rate(st, u, dt);
        st->top.w_wall = st->gap_rate;
        g->w_grid = st->gap_rate / g->nz;
        st->dz_new = g->dz + dt * st->gap_rate / g->nz;
    }
    for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
        if (g->gz0 == 0) {
            const ekm2d_end *e = &st->bottom;
            u[0][i][g->s_vz] =
                ekm2d_open_face(g, e, i) ? (g->nz > 1 ? u[1][i][g->s_vz] : 0.0) : ekm2d_end_face_w(g, e, i);
        }
        if (g->gz0 + g->gnz > g->nz) {
            const ekm2d_end *e = &st->top;
            u[g->nz][i][g->s_vz] =
                ekm2d_open_face(g, e, i) ? u[g->nz - 1][i][g->s_vz] : ekm2d_end_face_w(g, e, i);
        }
    }
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++)
            if (ekm2d_side_face(g, i))
                u[j][i][g->s_vx] = 0.0;
    const double angle = ekm_scenario_angle_at(st->sc, st->t + dt) * DEG;
    st->g_x = st->sc->gravity * sin(angle);
    st->g_z = -st->sc->gravity * cos(angle);
}

/* ---- phase 2: mass --------------------------------------------------------------------------------- */

/* The face fluxes F = v phi_up (upwind by the sign of v, 0 at v = 0,
 * flux.h) wherever both sides are in the box, then phi* of every cell
 * whose four faces are; 0 = reject (an owned cell left [0, phi_cp)). */
static int mass_update(ekm2d_step *st, PetscScalar ***u, double dt)
{
    const ekm2d_grid *g = &st->g;
    const ekm_material *m = &st->sc->material;
    const PetscInt X0 = g->gx0, X1 = g->gx0 + g->gnx, Z0 = g->gz0, Z1 = g->gz0 + g->gnz;
    for (PetscInt j = Z0; j < Z1; j++)
        for (PetscInt i = X0; i < X1; i++) {
            double fx = 0.0, fz = 0.0;
            if (j < g->nz && ekm2d_fx_ok(g, i))
                fx = ekm2d_flux_x(g, u, i, j);
            if (ekm2d_fz_ok(g, j) && j <= g->nz && ekm2d_cell_exists(g, i, j < g->nz ? j : g->nz - 1))
                fz = ekm2d_flux_z(g, &st->bottom, &st->top, u, i, j);
            BOX(st, Fx, i, j) = fx;
            BOX(st, Fz, i, j) = fz;
        }
    const double rx = dt / g->dx, rz = dt / g->dz;
    /* a moving top wall: the cell's content over its new height */
    const double inv_dz_new = 1.0 / st->dz_new;
    int ok = 1;
    for (PetscInt j = Z0; j < Z1; j++)
        for (PetscInt i = X0; i < X1; i++) {
            if (!ekm2d_cell_ok(g, i, j))
                continue;
            const double phi = u[j][i][g->s_phi];
            const double dFz = BOX(st, Fz, i, j + 1) - BOX(st, Fz, i, j),
                         dFx = BOX(st, Fx, i + 1, j) - BOX(st, Fx, i, j);
            const double phi_new = g->top_moving ? (phi * g->dz - dt * dFz - g->dz * rx * dFx) * inv_dz_new
                                                 : phi - rz * dFz - rx * dFx;
            BOX(st, phi_new, i, j) = phi_new;
            const int owned = i >= g->x0 && i < g->x0 + g->nxl && j >= g->z0 && j < g->z0 + g->nzl;
            if (owned && ok &&
                (!(phi_new >= 0.0) ||
                 !(phi_new - phi <= st->sc->numerics.phi_step_max * (m->phi_cp - phi)))) {
                snprintf(st->reason, sizeof st->reason,
                         "t = %.9g s, dt = %.3g s, cell (%d, %d) (x = %.6g m, z = %.6g m): phi %.9g -> %.9g "
                         "(allowed [0, %.9g)), T = %.3g m^2/s^2",
                         st->t, dt, (int)i, (int)j, (i + 0.5) * g->dx, (j + 0.5) * g->dz, phi, phi_new,
                         phi + st->sc->numerics.phi_step_max * (m->phi_cp - phi), u[j][i][g->s_T]);
                ok = 0;
            }
        }
    int all = ok;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_LAND, g->comm);
    if (!all && ok)
        snprintf(st->reason, sizeof st->reason,
                 "t = %.9g s, dt = %.3g s: a cell of another rank left [0, phi_cp)", st->t, dt);
    return all;
}

/* phi* of the owned cells to the whole ghosted box: the velocity rows
 * reach the upwind phi* of a face two cells away, whose own fluxes lie
 * beyond the state's ghosts. */
static ekm_status exchange_phi_new(ekm2d_step *st, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    PetscScalar ***w;
    PTRY(DMStagVecGetArray(g->dm, st->Wl, &w), "DMStagVecGetArray");
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++)
            w[j][i][g->s_phi] = BOX(st, phi_new, i, j);
    PTRY(DMStagVecRestoreArray(g->dm, st->Wl, &w), "DMStagVecRestoreArray");
    PTRY(DMLocalToGlobal(g->dm, st->Wl, INSERT_VALUES, st->W), "DMLocalToGlobal");
    PTRY(DMGlobalToLocal(g->dm, st->W, INSERT_VALUES, st->Wl), "DMGlobalToLocal");
    PTRY(DMStagVecGetArray(g->dm, st->Wl, &w), "DMStagVecGetArray");
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j < g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++)
            if (ekm2d_cell_exists(g, i, j))
                BOX(st, phi_new, i, j) = w[j][i][g->s_phi];
    PTRY(DMStagVecRestoreArray(g->dm, st->Wl, &w), "DMStagVecRestoreArray");
    return EKM_OK;
}

/* ---- phase 3: convection --------------------------------------------------------------------------- */

/* (rho T)* of every cell with phi*, by the fluxes of phase 2 carrying the
 * upwind T (an entering end face: the inflow's T_in). */
static void convect_temperature(ekm2d_step *st, PetscScalar ***u, double dt)
{
    const ekm2d_grid *g = &st->g;
    const double rho_p = st->sc->material.rho_p, rx = dt / g->dx, rz = dt / g->dz;
    const double dz_new = st->dz_new; /* a moving top wall: the cells' new height */
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!ekm2d_cell_ok(g, i, j))
                continue;
            double q[4]; /* T carried through the faces below, above, left, right */
            const PetscInt fi[4] = {i, i, i, i + 1}, fj[4] = {j, j + 1, j, j};
            for (int k = 0; k < 4; k++) {
                const double F = k < 2 ? BOX(st, Fz, fi[k], fj[k]) : BOX(st, Fx, fi[k], fj[k]);
                double Tq = 0.0;
                if (k < 2) {
                    const PetscInt jf = fj[k];
                    if (jf == 0)
                        Tq = F > 0.0 ? st->bottom.T_in : u[0][i][g->s_T];
                    else if (jf == g->nz)
                        Tq = F < 0.0 ? st->top.T_in : u[jf - 1][i][g->s_T];
                    else if (F != 0.0)
                        Tq = F > 0.0 ? u[jf - 1][i][g->s_T] : u[jf][i][g->s_T];
                } else if (F != 0.0) { /* a side wall's face carries none */
                    const PetscInt ifc = fi[k];
                    Tq = F > 0.0 ? u[j][ifc - 1][g->s_T] : u[j][ifc][g->s_T];
                }
                q[k] = F * Tq;
            }
            const double phiT = u[j][i][g->s_phi] * u[j][i][g->s_T];
            BOX(st, rhoT, i, j) =
                g->top_moving
                    ? rho_p / dz_new * (phiT * g->dz - dt * (q[1] - q[0]) - g->dz * rx * (q[3] - q[2]))
                    : rho_p * (phiT - rz * (q[1] - q[0]) - rx * (q[3] - q[2]));
        }
}

/* The momentum of the face velocity v[] (vx or vz) through a side of its
 * control volume with volume flux Fc: Fc times the upwind velocity. */
static inline double carried(double Fc, double v_behind, double v_ahead)
{
    return Fc * (Fc > 0.0 ? v_behind : v_ahead);
}

/* The face momenta after convection, rho_f v - dt div(F v) [kg/(m^2 s)],
 * the control volume of a face spanning half of each cell beside it: its
 * sides through the two cell centres carry the mean of the cells' two
 * face fluxes along the face's direction (flux.h's centre fluxes), its
 * sides through the two corners the mean of the fluxes across them. */
static void convect_momentum(ekm2d_step *st, PetscScalar ***u, double dt)
{
    const ekm2d_grid *g = &st->g;
    const double rho_p = st->sc->material.rho_p, rx = dt / g->dx, rz = dt / g->dz;
    const double dz_new = st->dz_new; /* a moving top wall: the cells' new height */
    const PetscInt vx = g->s_vx, vz = g->s_vz;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl + 1 && j <= g->nz; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl + 1; i++) {
            /* vz at z-face (i, j), interior */
            if (j > 0 && j < g->nz && i < g->x0 + g->nxl && ekm2d_cell_exists(g, i, j)) {
                const double phi_face = 0.5 * (u[j - 1][i][g->s_phi] + u[j][i][g->s_phi]);
                const double Fb = 0.5 * (BOX(st, Fz, i, j - 1) + BOX(st, Fz, i, j)),
                             Fa = 0.5 * (BOX(st, Fz, i, j) + BOX(st, Fz, i, j + 1));
                const double mb = carried(Fb, u[j - 1][i][vz], u[j][i][vz]),
                             ma = carried(Fa, u[j][i][vz], u[j + 1][i][vz]);
                double ml = 0.0, mr = 0.0; /* through the corners (i, j) and (i + 1, j) */
                if (!ekm2d_side_face(g, i))
                    ml = carried(0.5 * (BOX(st, Fx, i, j - 1) + BOX(st, Fx, i, j)), u[j][i - 1][vz],
                                 u[j][i][vz]);
                if (!ekm2d_side_face(g, i + 1))
                    mr = carried(0.5 * (BOX(st, Fx, i + 1, j - 1) + BOX(st, Fx, i + 1, j)), u[j][i][vz],
                                 u[j][i + 1][vz]);
                BOX(st, rhs_z, i, j) =
                    g->top_moving
                        ? rho_p / dz_new *
                              (phi_face * u[j][i][vz] * g->dz - dt * (ma - mb) - g->dz * rx * (mr - ml))
                        : rho_p * (phi_face * u[j][i][vz] - rz * (ma - mb) - rx * (mr - ml));
            }
            /* vx at x-face (i, j), not on a side wall */
            if (j < g->z0 + g->nzl && j < g->nz && !ekm2d_side_face(g, i) && (g->periodic || i < g->nx)) {
                const double phi_face = 0.5 * (u[j][i - 1][g->s_phi] + u[j][i][g->s_phi]);
                const double Fl = 0.5 * (BOX(st, Fx, i - 1, j) + BOX(st, Fx, i, j)),
                             Fr = 0.5 * (BOX(st, Fx, i, j) + BOX(st, Fx, i + 1, j));
                const double ml = carried(Fl, u[j][i - 1][vx], u[j][i][vx]),
                             mr = carried(Fr, u[j][i][vx], u[j][i + 1][vx]);
                /* through the corners (i, j) and (i, j + 1): an end face's
                 * entering flow brings the inflow's u_in */
                const double Fb = 0.5 * (BOX(st, Fz, i - 1, j) + BOX(st, Fz, i, j)),
                             Fa = 0.5 * (BOX(st, Fz, i - 1, j + 1) + BOX(st, Fz, i, j + 1));
                const double mb = j == 0 ? Fb * (Fb > 0.0 ? st->bottom.u_in : u[0][i][vx])
                                         : carried(Fb, u[j - 1][i][vx], u[j][i][vx]);
                const double ma = j == g->nz - 1 ? Fa * (Fa < 0.0 ? st->top.u_in : u[j][i][vx])
                                                 : carried(Fa, u[j][i][vx], u[j + 1][i][vx]);
                BOX(st, rhs_x, i, j) =
                    g->top_moving
                        ? rho_p / dz_new *
                              (phi_face * u[j][i][vx] * g->dz - dt * (ma - mb) - g->dz * rx * (mr - ml))
                        : rho_p * (phi_face * u[j][i][vx] - rz * (ma - mb) - rx * (mr - ml));
            }
        }
}

/* A moving top wall: the grid takes its new height after the transport
 * (phases 2-3), and the ends' data follow it (step.c's order). */
static void stretch_grid(ekm2d_step *st)
{
    ekm2d_grid *g = &st->g;
    g->dz = st->dz_new;
    st->bottom = ekm2d_grid_end(g, 0, st->t);
    st->top = ekm2d_grid_end(g, 1, st->t);
    st->top.w_wall = st->gap_rate;
}

/* ---- phase 4: properties ------------------------------------------------------------------------- */

/* T*, the empty cells and the transport coefficients at (phi*, T*) of
 * every cell phase 2 and 3 reached (empty cells: zeros). */
static void properties(ekm2d_step *st)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const double phi_dry = sc->numerics.phi_dry, T_floor = sc->numerics.T_floor;
    const ekm_cell_properties none = {0};
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!ekm2d_cell_ok(g, i, j))
                continue;
            const size_t k = ekm2d_box_index(g, i, j);
            const int dry = st->phi_new[k] < phi_dry;
            const double phi = dry ? phi_dry : st->phi_new[k];
            const double T = fmax(st->rhoT[k] / (m->rho_p * phi), T_floor);
            st->dry[k] = (unsigned char)dry;
            st->T_star[k] = dry ? 0.0 : T;
            st->prop[k] = dry ? none : ekm_cell_properties_at(m, sc->variant, phi, T);
            st->K[k] = dry ? 0.0 : ekm_pressure_dphi(m, st->phi_new[k], T);
        }
    ekm2d_surface_properties(st);
}

/* ---- phase 7: accept ----------------------------------------------------------------------------- */

/* The largest relaxation rate of the kinetic pressure over this rank's
 * wet cells, eps P_K/(P_K + P_Y) [1/s] (control.c's formula). */
static double thermal_rate(const ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    const ekm_material *m = &st->sc->material;
    double rate = 0.0;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            const double phi = u[j][i][g->s_phi], T = u[j][i][g->s_T];
            if (!(phi >= st->sc->numerics.phi_dry && T > 0.0) ||
                (g->s_solid >= 0 && u[j][i][g->s_solid] > 0.5))
                continue;
            rate = fmax(rate, ekm_thermal_relaxation_rate(m, phi, T));
        }
    return rate;
}

/* The net mass that entered through the ends in the step [kg/m]. */
static double mass_entered(const ekm2d_step *st, double dt)
{
    const ekm2d_grid *g = &st->g;
    double in = 0.0;
    for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
        if (g->z0 == 0)
            in += BOX(st, Fz, i, 0);
        if (g->z0 + g->nzl == g->nz)
            in -= BOX(st, Fz, i, g->nz);
    }
    return dt * st->sc->material.rho_p * g->dx * in;
}

static int state_finite(const ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    int ok = 1;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl + 1 && j <= g->nz; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl + 1; i++) {
            const PetscScalar *v = u[j][i];
            if (i < g->x0 + g->nxl && j < g->nz)
                ok &= isfinite(v[g->s_phi]) && isfinite(v[g->s_T]);
            ok &= isfinite(v[g->s_vx]) && isfinite(v[g->s_vz]);
            if (g->s_sxz >= 0) {
                ok &= isfinite(v[g->s_sxz]);
                if (i < g->x0 + g->nxl && j < g->nz)
                    ok &= isfinite(v[g->s_sxx]) && isfinite(v[g->s_syy]) && isfinite(v[g->s_szz]);
            }
        }
    int all = ok;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_LAND, g->comm);
    return all;
}

/* ---- the step -------------------------------------------------------------------------------------- */

/* The ghosts of the state being stepped (Ul, its array *u) from the
 * owned values of every rank, through the scratch vector W. */
static ekm_status refresh_ghosts(ekm2d_step *st, PetscScalar ****u, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    PTRY(DMStagVecRestoreArray(g->dm, st->Ul, u), "DMStagVecRestoreArray");
    PTRY(DMLocalToGlobal(g->dm, st->Ul, INSERT_VALUES, st->W), "DMLocalToGlobal");
    PTRY(DMGlobalToLocal(g->dm, st->W, INSERT_VALUES, st->Ul), "DMGlobalToLocal");
    PTRY(DMStagVecGetArray(g->dm, st->Ul, u), "DMStagVecGetArray");
    return EKM_OK;
}

static ekm_status reject(ekm2d_step *st, PetscScalar ***u, int *accepted, ekm_error *err)
{
    st->g.dz = st->dz_start;
    PTRY(DMStagVecRestoreArray(st->g.dm, st->Ul, &u), "DMStagVecRestoreArray");
    PTRY(VecCopy(st->U_back, st->U), "VecCopy");
    st->rejected++;
    *accepted = 0;
    return EKM_OK;
}

ekm_status ekm2d_step_apply(ekm2d_step *st, double dt, int *accepted, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    if (!(dt > 0.0) || !isfinite(dt))
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "%s: t = %.9g s: time step dt = %g s is not a positive finite number", st->sc->source,
                        st->t, dt);
    *accepted = 1;
    st->reason[0] = '\0';
    PTRY(VecCopy(st->U, st->U_back), "VecCopy");
    PTRY(DMGlobalToLocal(g->dm, st->U, INSERT_VALUES, st->Ul), "DMGlobalToLocal");
    PetscScalar ***u;
    PTRY(DMStagVecGetArray(g->dm, st->Ul, &u), "DMStagVecGetArray");
    PetscLogEventBegin(st->ev_explicit, 0, 0, 0, 0);
    boundaries(st, u, dt);
    PetscLogEventBegin(st->ev_regime, 0, 0, 0, 0);
    const int n_solid = ekm2d_regime_begin(st, u);
    PetscLogEventEnd(st->ev_regime, 0, 0, 0, 0);
    const int mass_ok = mass_update(st, u, dt);
    ekm_status rc = mass_ok ? exchange_phi_new(st, err) : EKM_OK;
    if (mass_ok && rc == EKM_OK) {
        convect_temperature(st, u, dt);
        convect_momentum(st, u, dt);
        if (g->top_moving)
            stretch_grid(st);
        properties(st);
    }
    PetscLogEventEnd(st->ev_explicit, 0, 0, 0, 0);
    if (!mass_ok)
        return reject(st, u, accepted, err);
    if (rc != EKM_OK) {
        DMStagVecRestoreArray(g->dm, st->Ul, &u);
        return rc;
    }
    if (n_solid) {
        PetscLogEventBegin(st->ev_regime, 0, 0, 0, 0);
        ekm2d_regime_properties(st, u, dt);
        PetscLogEventEnd(st->ev_regime, 0, 0, 0, 0);
    }
    int ok = ekm2d_velocity_solve(st, u, dt, err);
    if (ok > 0 && n_solid) {
        /* the second pass: the law's norm lagged on the first pass's
         * rates (step.c: a cell that starts to deform within the step
         * already deforms plastically) */
        if ((rc = refresh_ghosts(st, &u, err)) != EKM_OK)
            return rc;
        PetscLogEventBegin(st->ev_regime, 0, 0, 0, 0);
        ekm2d_regime_lagged_rates(st, u);
        ekm2d_regime_properties(st, u, dt);
        PetscLogEventEnd(st->ev_regime, 0, 0, 0, 0);
        ok = ekm2d_velocity_solve(st, u, dt, err);
    }
    double lag_err = 0.0;
    /* at or below the solid cells' acoustic step the step stands
     * whatever the lag error (control2d.c) */
    const int above_floor = dt > st->dt_solid_floor * (1.0 + 1e-12);
    if (ok > 0 && n_solid) {
        PetscLogEventBegin(st->ev_regime, 0, 0, 0, 0);
        const double mine = ekm2d_regime_lag_error(st, u, dt);
        MPI_Allreduce(&mine, &lag_err, 1, MPI_DOUBLE, MPI_MAX, g->comm);
        if (lag_err > st->sc->numerics.solid_lag_tol && above_floor) {
            snprintf(st->reason, sizeof st->reason,
                     "t = %.9g s, dt = %.3g s: a solid cell's stress moves by %.3g of itself when the law's "
                     "norm is taken at the step's rates (solid_lag_tol = %g)",
                     st->t, dt, lag_err, st->sc->numerics.solid_lag_tol);
            ok = 0;
        } else {
            ekm2d_regime_finish(st, u);
        }
        PetscLogEventEnd(st->ev_regime, 0, 0, 0, 0);
    }
    if (ok > 0) {
        PetscLogEventBegin(st->ev_temp, 0, 0, 0, 0);
        ok = ekm2d_temperature_solve(st, u, dt, err);
        PetscLogEventEnd(st->ev_temp, 0, 0, 0, 0);
    }
    if (ok < 0) {
        DMStagVecRestoreArray(g->dm, st->Ul, &u);
        return err->code;
    }
    if (ok == 0)
        return reject(st, u, accepted, err);
    /* the new phi of owned cells (T and v are written by phases 5 and 6) */
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++)
            u[j][i][g->s_phi] = BOX(st, phi_new, i, j);
    if (!state_finite(st, u)) {
        snprintf(st->reason, sizeof st->reason, "t = %.9g s, dt = %.3g s: non-finite state", st->t, dt);
        return reject(st, u, accepted, err);
    }
    double rate = thermal_rate(st, u), rate_all = rate;
    MPI_Allreduce(&rate, &rate_all, 1, MPI_DOUBLE, MPI_MAX, g->comm);
    if (dt * rate_all > EKM2D_THERMAL_END_FACTOR * st->sc->numerics.thermal_relax_step) {
        snprintf(
            st->reason, sizeof st->reason,
            "t = %.9g s, dt = %.3g s: the thermal relaxation rate at the end of the step, %.3g 1/s, exceeds "
            "%g x thermal_relax_step / dt",
            st->t, dt, rate_all, EKM2D_THERMAL_END_FACTOR);
        return reject(st, u, accepted, err);
    }
    double in = mass_entered(st, dt), in_all = in;
    MPI_Allreduce(&in, &in_all, 1, MPI_DOUBLE, MPI_SUM, g->comm);
    PTRY(DMStagVecRestoreArray(g->dm, st->Ul, &u), "DMStagVecRestoreArray");
    PTRY(DMLocalToGlobal(g->dm, st->Ul, INSERT_VALUES, st->U), "DMLocalToGlobal");
    st->mass_in += in_all;
    /* the solid regime's next step: the lag error grows as dt (a cell
     * relaxing fast sits on its fixed point, where the error is the
     * relative change of its rates within the step) to dt^2 (a cell
     * relaxing slowly); sized for the first */
    if (above_floor)
        st->solid_lag_max = fmax(st->solid_lag_max, lag_err);
    else if (lag_err > st->sc->numerics.solid_lag_tol)
        st->solid_floor_steps++;
    st->dt_solid =
        lag_err > 0.0 ? dt * fmin(EKM2D_GROWTH, 0.9 * st->sc->numerics.solid_lag_tol / lag_err) : INFINITY;
    st->t += dt;
    st->steps++;
    st->newton_total += st->newton;
    PetscLogEventBegin(st->ev_regime, 0, 0, 0, 0);
    const ekm_status sw = ekm2d_regime_switch(st, err);
    PetscLogEventEnd(st->ev_regime, 0, 0, 0, 0);
    return sw;
}

const char *ekm2d_step_reason(const ekm2d_step *st)
{
    return st->reason;
}
