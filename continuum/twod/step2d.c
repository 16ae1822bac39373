/* step2d.c: the semi-implicit 2D step (step2d.h): phases 1-4 and 7, the
 * stepper's life cycle.  Units: SI throughout (phi [-], T [m^2/s^2], v
 * [m/s], rho = rho_p phi [kg/m^3], fluxes F = v phi [m/s]). */
#include "step2d_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)

/* The thermal relaxation limit at the end of a step (step.c's factor). */
#define EKM2D_THERMAL_END_FACTOR 1.01

#define PTRY(call, what)                                                               \
    do {                                                                               \
        if ((call) != 0)                                                               \
            return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error in %s", (what)); \
    } while (0)

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
                            sc->source, k ? "top" : "bottom", ekm_bc_kind_name(bc->kind));
        if (bc->kind == EKM_BC_WALL && (isfinite(bc->pressure) || isfinite(bc->shear_rate)))
            return EKM_FAIL(
                err, EKM_EUNAVAILABLE,
                "%s: [%s] pressure: a pressure-controlled wall is not in the 2D step yet (issue 33)",
                sc->source, k ? "top" : "bottom");
    }
    return EKM_OK;
}

/* ---- phase 1: boundaries ------------------------------------------------------------------------ */

/* The ends at the step's start and the face velocities they fix: vz of
 * the end faces (an inlet's w, a wall's 0, a free end the adjacent
 * interior face's), vx of side-wall faces (0); gravity at the end of the
 * step (step.c's rule). */
static void boundaries(ekm2d_step *st, PetscScalar ***u, double dt)
{
    const ekm2d_grid *g = &st->g;
    st->bottom = ekm2d_grid_end(g, 0, st->t);
    st->top = ekm2d_grid_end(g, 1, st->t);
    for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
        if (g->gz0 == 0) {
            const ekm2d_end *e = &st->bottom;
            u[0][i][g->s_vz] = e->kind == EKM_BC_FREE ? (g->nz > 1 ? u[1][i][g->s_vz] : 0.0)
                                                      : (ekm2d_inlet_face(g, e, i) ? e->w : 0.0);
        }
        if (g->gz0 + g->gnz > g->nz) {
            const ekm2d_end *e = &st->top;
            u[g->nz][i][g->s_vz] =
                e->kind == EKM_BC_FREE ? u[g->nz - 1][i][g->s_vz] : (ekm2d_inlet_face(g, e, i) ? e->w : 0.0);
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

/* Which box points phase 2 reaches: an x-face's flux needs both cells
 * beside it (a side-wall face carries none), a z-face's both cells or its
 * end's; a cell's new phi its four faces. */
static inline int fx_ok(const ekm2d_grid *g, PetscInt i)
{
    return i < g->gx0 + g->gnx && (ekm2d_side_face(g, i) || i > g->gx0);
}

static inline int fz_ok(const ekm2d_grid *g, PetscInt j)
{
    return j < g->gz0 + g->gnz && (j == 0 || j == g->nz || j > g->gz0);
}

static inline int cell_ok(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return ekm2d_cell_exists(g, i, j) && i >= g->gx0 && j >= g->gz0 && fx_ok(g, i) && fx_ok(g, i + 1) &&
           fz_ok(g, j) && fz_ok(g, j + 1);
}

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
            if (j < g->nz && fx_ok(g, i))
                fx = ekm2d_flux_x(g, u, i, j);
            if (fz_ok(g, j) && j <= g->nz && ekm2d_cell_exists(g, i, j < g->nz ? j : g->nz - 1))
                fz = ekm2d_flux_z(g, &st->bottom, &st->top, u, i, j);
            BOX(st, Fx, i, j) = fx;
            BOX(st, Fz, i, j) = fz;
        }
    const double rx = dt / g->dx, rz = dt / g->dz;
    int ok = 1;
    for (PetscInt j = Z0; j < Z1; j++)
        for (PetscInt i = X0; i < X1; i++) {
            if (!cell_ok(g, i, j))
                continue;
            const double phi = u[j][i][g->s_phi];
            const double phi_new = phi - rz * (BOX(st, Fz, i, j + 1) - BOX(st, Fz, i, j)) -
                                   rx * (BOX(st, Fx, i + 1, j) - BOX(st, Fx, i, j));
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
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!cell_ok(g, i, j))
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
            BOX(st, rhoT, i, j) =
                rho_p * (u[j][i][g->s_phi] * u[j][i][g->s_T] - rz * (q[1] - q[0]) - rx * (q[3] - q[2]));
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
                BOX(st, rhs_z, i, j) = rho_p * (phi_face * u[j][i][vz] - rz * (ma - mb) - rx * (mr - ml));
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
                BOX(st, rhs_x, i, j) = rho_p * (phi_face * u[j][i][vx] - rz * (ma - mb) - rx * (mr - ml));
            }
        }
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
            if (!cell_ok(g, i, j))
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
            const double x = fmax(phi - m->phi_co, 0.0);
            const double r = m->eps0 * sqrt(T) * m->phi_cp * (phi * T + m->nu * m->T0 * x) /
                             ((m->phi_cp - phi) * (phi * T + m->T0 * x));
            rate = fmax(rate, r);
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
    boundaries(st, u, dt);
    const int n_solid = ekm2d_regime_begin(st, u);
    if (!mass_update(st, u, dt))
        return reject(st, u, accepted, err);
    ekm_status rc = exchange_phi_new(st, err);
    if (rc != EKM_OK) {
        DMStagVecRestoreArray(g->dm, st->Ul, &u);
        return rc;
    }
    convect_temperature(st, u, dt);
    convect_momentum(st, u, dt);
    properties(st);
    if (n_solid)
        ekm2d_regime_properties(st, u, dt);
    int ok = ekm2d_velocity_solve(st, u, dt, err);
    if (ok > 0 && n_solid) {
        /* the second pass: the law's norm lagged on the first pass's
         * rates (step.c: a cell that starts to deform within the step
         * already deforms plastically) */
        if ((rc = refresh_ghosts(st, &u, err)) != EKM_OK)
            return rc;
        ekm2d_regime_lagged_rates(st, u);
        ekm2d_regime_properties(st, u, dt);
        ok = ekm2d_velocity_solve(st, u, dt, err);
    }
    if (ok > 0 && n_solid)
        ekm2d_regime_finish(st, u);
    if (ok > 0)
        ok = ekm2d_temperature_solve(st, u, dt, err);
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
    st->t += dt;
    st->steps++;
    st->newton_total += st->newton;
    return ekm2d_regime_switch(st, err);
}

const char *ekm2d_step_reason(const ekm2d_step *st)
{
    return st->reason;
}

/* ---- life cycle ------------------------------------------------------------------------------------ */

/* The initial state: the scenario's (state.h) or init, in every column;
 * a free or inflow end's face takes its column's 1D value too. */
static ekm_status initial_state(ekm2d_step *st, const ekm_state *init, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    ekm_state *s1 = NULL;
    if (!init) {
        s1 = ekm_state_alloc(g->nz, st->sc->length);
        if (!s1)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D initial state)");
        ekm_state_init(s1, st->sc);
        init = s1;
    }
    PetscScalar ***u;
    PetscErrorCode pe = DMStagVecGetArray(g->dm, st->Ul, &u);
    if (!pe) {
        for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
            for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
                PetscScalar *v = u[j][i];
                if (j < g->nz) {
                    v[g->s_phi] = init->phi[j];
                    v[g->s_T] = init->T[j];
                    v[g->s_vx] = ekm2d_side_face(g, i) ? 0.0 : init->u[j];
                }
                if (j <= g->nz)
                    v[g->s_vz] = init->w[j];
                if (g->s_sxz >= 0 && j <= g->nz) { /* the solid regime's state */
                    v[g->s_sxz] = init->sxz[j];
                    if (j < g->nz) {
                        v[g->s_sxx] = init->sxx[j];
                        v[g->s_syy] = init->syy[j];
                        v[g->s_szz] = init->szz[j];
                        v[g->s_solid] = init->solid[j];
                        v[g->s_rate] = init->rate_prev[j];
                    }
                }
            }
        pe = DMStagVecRestoreArray(g->dm, st->Ul, &u);
    }
    if (!pe)
        pe = DMLocalToGlobal(g->dm, st->Ul, INSERT_VALUES, st->U);
    ekm_state_free(s1);
    if (pe)
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error setting the initial state");
    return EKM_OK;
}

/* A system's linear solver (options prefix ekm_v_ or ekm_t_): on one rank
 * LU (the velocity system: LU as GMRES's preconditioner, kept across steps
 * while it converges in few iterations: velocity2d.c); on several GMRES
 * with block Jacobi (ILU) to 1e-12 (to be chosen by measurement: docs). */
static ekm_status set_up_ksp(KSP ksp, Mat A, const char *prefix, int reuse, MPI_Comm comm, ekm_error *err)
{
    PC pc;
    int size = 1;
    MPI_Comm_size(comm, &size);
    PTRY(KSPSetOperators(ksp, A, A), "KSPSetOperators");
    PTRY(KSPSetOptionsPrefix(ksp, prefix), "KSPSetOptionsPrefix");
    PTRY(KSPGetPC(ksp, &pc), "KSPGetPC");
    if (size == 1 && reuse) {
        PTRY(KSPSetType(ksp, KSPGMRES), "KSPSetType");
        PTRY(PCSetType(pc, PCLU), "PCSetType");
        PTRY(KSPSetTolerances(ksp, 1e-13, 1e-300, PETSC_DEFAULT, 30), "KSPSetTolerances");
    } else if (size == 1) {
        PTRY(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
        PTRY(PCSetType(pc, PCLU), "PCSetType");
    } else {
        PTRY(KSPSetType(ksp, KSPGMRES), "KSPSetType");
        PTRY(PCSetType(pc, PCBJACOBI), "PCSetType");
        PTRY(KSPSetTolerances(ksp, 1e-12, 1e-50, PETSC_DEFAULT, 1000), "KSPSetTolerances");
    }
    PTRY(KSPSetErrorIfNotConverged(ksp, PETSC_FALSE), "KSPSetErrorIfNotConverged");
    PTRY(KSPSetFromOptions(ksp), "KSPSetFromOptions");
    return EKM_OK;
}

ekm_status ekm2d_step_create(const ekm_scenario *sc, MPI_Comm comm, const ekm_state *init, ekm2d_step **out,
                             ekm_error *err)
{
    *out = NULL;
    ekm_status rc = ekm2d_step_supported(sc, err);
    if (rc != EKM_OK)
        return rc;
    ekm2d_step *st = calloc(1, sizeof *st);
    if (!st)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D step)");
    st->sc = sc;
    rc = ekm2d_grid_create(sc, comm, &st->g, err);
    if (rc != EKM_OK) {
        free(st);
        return rc;
    }
    *out = st;
    const ekm2d_grid *g = &st->g;
    const size_t n = ekm2d_grid_box_size(g);
    st->Fx = calloc(n, sizeof(double));
    st->Fz = calloc(n, sizeof(double));
    st->phi_new = calloc(n, sizeof(double));
    st->rhoT = calloc(n, sizeof(double));
    st->T_star = calloc(n, sizeof(double));
    st->prop = calloc(n, sizeof *st->prop);
    st->dry = calloc(n, 1);
    st->K = calloc(n, sizeof(double));
    st->rhs_x = calloc(n, sizeof(double));
    st->rhs_z = calloc(n, sizeof(double));
    st->pu_x = calloc(n, sizeof(double));
    st->pu_z = calloc(n, sizeof(double));
    st->T_it = calloc(n, sizeof(double));
    st->T_lin = calloc(n, sizeof(double));
    st->T_change = calloc(n, sizeof(double));
    st->upd = calloc(n, sizeof(double));
    st->src = calloc(n, sizeof *st->src);
    int solid_ok = 1;
    if (sc->hypo.enabled) {
        st->solid = calloc(n, 1);
        st->solid_c = calloc(n, 1);
        st->rate_old = calloc(n, sizeof *st->rate_old);
        st->rate_c_old = calloc(n, sizeof *st->rate_c_old);
        st->hyp = calloc(n, sizeof *st->hyp);
        st->hyp_c = calloc(n, sizeof *st->hyp_c);
        st->t0_c = calloc(n, sizeof(double));
        st->T_keep = calloc(n, sizeof(double));
        st->eta_new = calloc(n, sizeof(double));
        st->sxz_c = calloc(n, sizeof(double));
        solid_ok = st->solid && st->solid_c && st->rate_old && st->rate_c_old && st->hyp && st->hyp_c &&
                   st->t0_c && st->T_keep && st->eta_new && st->sxz_c;
    }
    if (!solid_ok || !st->Fx || !st->Fz || !st->phi_new || !st->rhoT || !st->T_star || !st->prop ||
        !st->dry || !st->K || !st->rhs_x || !st->rhs_z || !st->pu_x || !st->pu_z || !st->T_it || !st->T_lin ||
        !st->T_change || !st->upd || !st->src) {
        ekm2d_step_destroy(st);
        *out = NULL;
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D step, %d x %d cells)", g->nx, g->nz);
    }
    PetscErrorCode pe = DMCreateGlobalVector(g->dm, &st->U);
    pe = pe ? pe : VecDuplicate(st->U, &st->U_back);
    pe = pe ? pe : DMCreateLocalVector(g->dm, &st->Ul);
    pe = pe ? pe : VecDuplicate(st->U, &st->W);
    pe = pe ? pe : VecDuplicate(st->Ul, &st->Wl);
    pe = pe ? pe : DMCreateMatrix(g->dmv, &st->A);
    pe = pe ? pe : DMCreateGlobalVector(g->dmv, &st->V);
    pe = pe ? pe : VecDuplicate(st->V, &st->Vb);
    pe = pe ? pe : DMCreateLocalVector(g->dmv, &st->Vl);
    pe = pe ? pe : KSPCreate(comm, &st->ksp_v);
    pe = pe ? pe : DMCreateMatrix(g->dmt, &st->J);
    pe = pe ? pe : DMCreateGlobalVector(g->dmt, &st->dT);
    pe = pe ? pe : VecDuplicate(st->dT, &st->R);
    pe = pe ? pe : VecDuplicate(st->dT, &st->Tn);
    pe = pe ? pe : DMCreateLocalVector(g->dmt, &st->Tl);
    pe = pe ? pe : VecDuplicate(st->Tl, &st->Rl);
    pe = pe ? pe : KSPCreate(comm, &st->ksp_t);
    pe = pe ? pe : MatSetOption(st->A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE);
    pe = pe ? pe : MatSetOption(st->J, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE);
    if (pe) {
        ekm2d_step_destroy(st);
        *out = NULL;
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error creating the vectors and matrices");
    }
    rc = set_up_ksp(st->ksp_v, st->A, "ekm_v_", 1, comm, err);
    if (rc == EKM_OK)
        rc = set_up_ksp(st->ksp_t, st->J, "ekm_t_", 0, comm, err);
    if (rc == EKM_OK)
        rc = initial_state(st, init, err);
    if (rc != EKM_OK) {
        ekm2d_step_destroy(st);
        *out = NULL;
    }
    return rc;
}

void ekm2d_step_destroy(ekm2d_step *st)
{
    if (!st)
        return;
    KSPDestroy(&st->ksp_v);
    KSPDestroy(&st->ksp_t);
    MatDestroy(&st->A);
    MatDestroy(&st->J);
    VecDestroy(&st->U);
    VecDestroy(&st->U_back);
    VecDestroy(&st->Ul);
    VecDestroy(&st->W);
    VecDestroy(&st->Wl);
    VecDestroy(&st->V);
    VecDestroy(&st->Vb);
    VecDestroy(&st->Vl);
    VecDestroy(&st->dT);
    VecDestroy(&st->R);
    VecDestroy(&st->Tn);
    VecDestroy(&st->Tl);
    VecDestroy(&st->Rl);
    free(st->Fx);
    free(st->Fz);
    free(st->phi_new);
    free(st->rhoT);
    free(st->T_star);
    free(st->prop);
    free(st->dry);
    free(st->K);
    free(st->rhs_x);
    free(st->rhs_z);
    free(st->pu_x);
    free(st->pu_z);
    free(st->T_it);
    free(st->T_lin);
    free(st->T_change);
    free(st->upd);
    free(st->src);
    free(st->solid);
    free(st->solid_c);
    free(st->rate_old);
    free(st->rate_c_old);
    free(st->hyp);
    free(st->hyp_c);
    free(st->t0_c);
    free(st->T_keep);
    free(st->eta_new);
    free(st->sxz_c);
    ekm2d_grid_destroy(&st->g);
    free(st);
}

ekm_status ekm2d_step_column(ekm2d_step *st, int i, ekm_state *out, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    const int n = g->nz;
    enum { C_PHI, C_T, C_U, C_W, C_SXX, C_SYY, C_SZZ, C_SOLID, C_RATE, C_SXZ, C_N };
    if (out->n != n || i < 0 || i >= g->nx)
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: column %d of %d x %d cells into a state of %d cells", i,
                        g->nx, n, out->n);
    const size_t len = C_N * ((size_t)n + 1);
    double *buf = calloc(len, sizeof(double)), *sum = calloc(len, sizeof(double));
    if (!buf || !sum) {
        free(buf);
        free(sum);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D column)");
    }
#define AT(q, j) ((size_t)(q) * ((size_t)n + 1) + (size_t)(j))
    PetscScalar ***u;
    PetscErrorCode pe = DMGlobalToLocal(g->dm, st->U, INSERT_VALUES, st->Ul);
    pe = pe ? pe : DMStagVecGetArray(g->dm, st->Ul, &u);
    const int solid = g->s_sxz >= 0;
    if (!pe) {
        if (i >= g->x0 && i < g->x0 + g->nxl)
            for (PetscInt j = g->z0; j < g->z0 + g->nzl + 1 && j <= n; j++) {
                const int face = j < g->z0 + g->nzl || j == n; /* this rank's z-face and corner */
                if (j < n && j < g->z0 + g->nzl) {
                    buf[AT(C_PHI, j)] = u[j][i][g->s_phi];
                    buf[AT(C_T, j)] = u[j][i][g->s_T];
                    buf[AT(C_U, j)] = u[j][i][g->s_vx];
                    if (solid) {
                        buf[AT(C_SXX, j)] = u[j][i][g->s_sxx];
                        buf[AT(C_SYY, j)] = u[j][i][g->s_syy];
                        buf[AT(C_SZZ, j)] = u[j][i][g->s_szz];
                        buf[AT(C_SOLID, j)] = u[j][i][g->s_solid];
                        buf[AT(C_RATE, j)] = u[j][i][g->s_rate];
                    }
                }
                if (face) {
                    buf[AT(C_W, j)] = u[j][i][g->s_vz];
                    if (solid)
                        buf[AT(C_SXZ, j)] = u[j][i][g->s_sxz];
                }
            }
        pe = DMStagVecRestoreArray(g->dm, st->Ul, &u);
    }
    if (!pe)
        MPI_Allreduce(buf, sum, (int)len, MPI_DOUBLE, MPI_SUM, g->comm);
    for (int j = 0; j < n; j++) {
        out->phi[j] = sum[AT(C_PHI, j)];
        out->T[j] = sum[AT(C_T, j)];
        out->u[j] = sum[AT(C_U, j)];
        if (solid) {
            out->sxx[j] = sum[AT(C_SXX, j)];
            out->syy[j] = sum[AT(C_SYY, j)];
            out->szz[j] = sum[AT(C_SZZ, j)];
            out->solid[j] = sum[AT(C_SOLID, j)] > 0.5;
            out->rate_prev[j] = sum[AT(C_RATE, j)];
        }
    }
    for (int j = 0; j <= n; j++) {
        out->w[j] = sum[AT(C_W, j)];
        if (solid)
            out->sxz[j] = sum[AT(C_SXZ, j)];
    }
#undef AT
    out->t = st->t;
    free(buf);
    free(sum);
    if (pe)
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error reading a column");
    return EKM_OK;
}

ekm_status ekm2d_step_stats(ekm2d_step *st, ekm2d_step_info *out, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    const PetscScalar ***u;
    PTRY(DMGlobalToLocal(g->dm, st->U, INSERT_VALUES, st->Ul), "DMGlobalToLocal");
    PTRY(DMStagVecGetArrayRead(g->dm, st->Ul, (void *)&u), "DMStagVecGetArrayRead");
    double mass = 0.0, phi_max = 0.0;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            mass += u[j][i][g->s_phi];
            phi_max = fmax(phi_max, u[j][i][g->s_phi]);
        }
    PTRY(DMStagVecRestoreArrayRead(g->dm, st->Ul, (void *)&u), "DMStagVecRestoreArrayRead");
    double all = mass, phi_all = phi_max;
    MPI_Allreduce(&mass, &all, 1, MPI_DOUBLE, MPI_SUM, g->comm);
    MPI_Allreduce(&phi_max, &phi_all, 1, MPI_DOUBLE, MPI_MAX, g->comm);
    out->t = st->t;
    out->steps = st->steps;
    out->rejected = st->rejected;
    out->mass = all * st->sc->material.rho_p * g->dx * g->dz;
    out->mass_in = st->mass_in;
    out->newton = st->newton;
    out->newton_total = st->newton_total;
    out->phi_max = phi_all;
    long sw[2] = {st->to_solid, st->to_flow}, sw_all[2];
    MPI_Allreduce(sw, sw_all, 2, MPI_LONG, MPI_SUM, g->comm);
    out->to_solid = sw_all[0];
    out->to_flow = sw_all[1];
    return EKM_OK;
}
