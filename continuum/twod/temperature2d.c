/* temperature2d.c: phase 6 of the 2D step (step2d.h), the temperature.
 *
 * Each wet cell solves (implicit.h's equation with conduction along x too)
 *
 *   f(T) = rho T - (rho T)* - a_z [l_a (T_a - T) - l_b (T - T_b)]
 *                           - a_x [l_r (T_r - T) - l_l (T - T_l)] - dt S(T) = 0,
 *   a_z = 2/3 dt/dz^2,  a_x = 2/3 dt/dx^2,
 *   S(T) = k_a sqrt(T) + k_y / sqrt(T) - k_d sqrt(T) (T + nu Y)   [W/m^3]
 *
 * with the face conductances l [kg/(m s)] lagged (the harmonic mean of the
 * two cells' lambda at (phi*, T*); none at the ends, the side walls, next
 * to an empty cell and, with [numerics] phi_vacuum > 0, between a cell
 * below phi_vacuum and a cell above it) and the source's coefficients from the new
 * velocities (model.h's ekm_temperature_source_coeffs_plane: the shear
 * rate the mean square of the cell's corners that carry one, the normal
 * rates its own; a surface cell's heating its fill fraction's, a cell below
 * phi_vacuum's phi/phi_vacuum's: implicit.h).  Newton's method on the 5-point system, with the 1D
 * solver's rules (docs/model/slab.md "Temperature step"): the first iterate T*
 * plus the last step's change scaled to dt; the local balance S = 0 at the
 * first iteration where the source is stiff and it fits the cell's
 * equation better; a cell whose diagonal is not positive restarts at the
 * top of its bracket; an update never below a tenth of T nor T_floor; a
 * cell has converged when |dT| < sqrt(tol) T or, the updates contracting,
 * |dT_k|^3/|dT_(k-1)|^2 < tol T.  Decisions that change a cell's iterate
 * use its neighbours' iterates of the iteration's start (the same on any
 * number of ranks); the system is then assembled at the decided iterate
 * (the 1D solver assembles as it decides, cell after cell).
 */
#include "step2d_impl.h"

#include "implicit.h"

#include <math.h>
#include <stdio.h>

static inline double harmonic(double a, double b)
{
    return a > 0.0 && b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
}

static inline int owned(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return i >= g->x0 && i < g->x0 + g->nxl && j >= g->z0 && j < g->z0 + g->nzl;
}

/* Cell k takes no part in the solve: empty, or solid (its T is kept:
 * regime2d.c). */
static inline int frozen(const ekm2d_step *st, size_t k)
{
    return st->dry[k] || (st->n_solid && st->solid[k]);
}

/* lambda of cell (i, j) if it exists and is wet, else 0 (solid cells: 0). */
static inline double lam(const ekm2d_step *st, PetscInt i, PetscInt j)
{
    return ekm2d_cell_exists(&st->g, i, j) && !BOX(st, dry, i, j) ? BOX(st, prop, i, j).lambda : 0.0;
}

/* The source coefficients of every owned wet cell from the new velocities. */
static void sources(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    const ekm_material *m = &st->sc->material;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            if (BOX(st, dry, i, j))
                continue;
            const double shear2 = ekm2d_cell_shear2(st, u, i, j);
            const double exx = (u[j][i + 1][g->s_vx] - u[j][i][g->s_vx]) / g->dx;
            const double ezz = (u[j + 1][i][g->s_vz] - u[j][i][g->s_vz]) / g->dz;
            const ekm_cell_properties *p = &BOX(st, prop, i, j);
            ekm_source_coeffs c = ekm_temperature_source_coeffs_plane(
                m, st->sc->variant, BOX(st, phi_new, i, j), p->g, p->Y, shear2, exx, ezz);
            /* a surface cell's heating is its fill fraction of the material's
             * (surface2d.c); k_diss holds its own phi already */
            c.k_heat_a *= BOX(st, fill, i, j);
            c.k_heat_y *= BOX(st, fill, i, j);
            ekm_implicit_vapour_heating(&c, BOX(st, phi_new, i, j), st->sc->numerics.phi_vacuum);
            BOX(st, src, i, j) = c;
        }
}

/* The iterate of the owned cells to every rank's ghosts: T_it over the
 * box (the ghost ring of dmt). */
static PetscErrorCode exchange(ekm2d_step *st)
{
    const ekm2d_grid *g = &st->g;
    PetscScalar ***t;
    PetscCall(DMStagVecGetArray(g->dmt, st->Tl, &t));
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++)
            t[j][i][g->t_T] = BOX(st, T_it, i, j);
    PetscCall(DMStagVecRestoreArray(g->dmt, st->Tl, &t));
    PetscCall(DMLocalToGlobal(g->dmt, st->Tl, INSERT_VALUES, st->Tn));
    PetscCall(DMGlobalToLocal(g->dmt, st->Tn, INSERT_VALUES, st->Tl));
    PetscInt x0, z0, nx, nz;
    PetscCall(DMStagGetGhostCorners(g->dmt, &x0, &z0, NULL, &nx, &nz, NULL));
    const PetscScalar ***tl;
    PetscCall(DMStagVecGetArrayRead(g->dmt, st->Tl, (void *)&tl));
    for (PetscInt j = z0; j < z0 + nz; j++)
        for (PetscInt i = x0; i < x0 + nx; i++)
            if (ekm2d_cell_exists(g, i, j))
                BOX(st, T_it, i, j) = tl[j][i][g->t_T];
    PetscCall(DMStagVecRestoreArrayRead(g->dmt, st->Tl, (void *)&tl));
    return 0;
}

/* One cell's row at the iterate: the residual f and the conduction's share
 * of the diagonal (sum of a l) and of the right-hand side (sum of a l T_nb). */
typedef struct {
    double a[4]; /* a l of the faces below, above, left, right [kg/m^3] */
    PetscInt nb[4][2];
    double sum_al, sum_alT;
} conduction;

static conduction cell_conduction(const ekm2d_step *st, PetscInt i, PetscInt j, double dt)
{
    const ekm2d_grid *g = &st->g;
    const double az = 2.0 / 3.0 * dt / (g->dz * g->dz), ax = 2.0 / 3.0 * dt / (g->dx * g->dx);
    conduction c = {.nb = {{i, j - 1}, {i, j + 1}, {i - 1, j}, {i + 1, j}}};
    const double here = lam(st, i, j);
    const double vac = st->sc->numerics.phi_vacuum;
    const int vapour = BOX(st, phi_new, i, j) < vac;
    for (int k = 0; k < 4; k++) {
        const PetscInt ni = c.nb[k][0], nj = c.nb[k][1];
        const int across_side = k >= 2 && ekm2d_side_face(g, k == 2 ? i : i + 1);
        double l = nj < 0 || nj >= g->nz || across_side ? 0.0 : harmonic(here, lam(st, ni, nj));
        /* the vacuum rule ([numerics] phi_vacuum > 0): a face between a
         * cell below phi_vacuum and a cell above conducts nothing (implicit.h) */
        if (vac > 0.0 && l > 0.0 && vapour != (BOX(st, phi_new, ni, nj) < vac))
            l = 0.0;
        c.a[k] = (k < 2 ? az : ax) * l;
        c.sum_al += c.a[k];
        if (c.a[k] != 0.0)
            c.sum_alT += c.a[k] * BOX(st, T_it, ni, nj);
    }
    return c;
}

static inline double residual(double rho, double T, double rhoT_star, const conduction *c, double dt,
                              double S)
{
    return rho * T - rhoT_star - (c->sum_alT - c->sum_al * T) - dt * S;
}

/* The iteration's linearisation points, decided from the iterate T_it
 * (every cell from its neighbours' values at the iteration's start, so
 * that the decisions do not depend on the rank layout): at the first
 * iteration the local balance S = 0 where the source is stiff and it fits
 * the cell's equation better; a cell left of its row's minimum (diagonal
 * <= 0, which depends on the cell's own T only) restarts at the top of its
 * bracket.  Into T_lin; *restarted = 1 if a cell restarted. */
static void decide(ekm2d_step *st, double dt, int it, int *restarted)
{
    const ekm2d_grid *g = &st->g;
    const double rho_p = st->sc->material.rho_p, T_floor = st->sc->numerics.T_floor;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            const size_t k = ekm2d_box_index(g, i, j);
            st->T_lin[k] = st->T_it[k];
            if (frozen(st, k))
                continue;
            const ekm_source_coeffs *src = &st->src[k];
            const double rho = rho_p * st->phi_new[k], rhoT_star = st->rhoT[k];
            const conduction c = cell_conduction(st, i, j, dt);
            double T = st->T_it[k], dS;
            const double S = ekm_source_eval(src, T, &dS);
            if (it == 1 && dt * fabs(dS) > 10.0 * rho) {
                const double Tb = fmax(ekm_source_balance(src), T_floor);
                double dSb;
                const double Sb = ekm_source_eval(src, Tb, &dSb);
                if (fabs(residual(rho, Tb, rhoT_star, &c, dt, Sb)) <
                    fabs(residual(rho, T, rhoT_star, &c, dt, S))) {
                    T = Tb;
                    dS = dSb;
                }
            }
            if (!(rho + c.sum_al - dt * dS > 0.0)) {
                const double T_cond = (rhoT_star + c.sum_alT) / (rho + c.sum_al);
                T = fmax(fmax(ekm_source_balance(src), T_cond), T_floor);
                *restarted = 1;
            }
            st->T_lin[k] = T;
        }
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++)
            BOX(st, T_it, i, j) = BOX(st, T_lin, i, j);
}

/* One Newton iteration's system at the iterate T_it (ghosts current). */
static PetscErrorCode assemble(ekm2d_step *st, double dt)
{
    const ekm2d_grid *g = &st->g;
    const double rho_p = st->sc->material.rho_p;
    PetscCall(MatZeroEntries(st->J));
    PetscScalar ***r;
    PetscCall(DMStagVecGetArray(g->dmt, st->Rl, &r));
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            DMStagStencil cols[5];
            double vals[5];
            cols[0] = (DMStagStencil){.loc = DMSTAG_ELEMENT, .i = i, .j = j, .c = 0};
            if (frozen(st, ekm2d_box_index(g, i, j))) {
                vals[0] = 1.0;
                PetscCall(DMStagMatSetValuesStencil(g->dmt, st->J, 1, cols, 1, cols, vals, ADD_VALUES));
                r[j][i][g->t_T] = 0.0;
                continue;
            }
            const ekm_source_coeffs *src = &BOX(st, src, i, j);
            const double rho = rho_p * BOX(st, phi_new, i, j), rhoT_star = BOX(st, rhoT, i, j);
            const conduction c = cell_conduction(st, i, j, dt);
            const double T = BOX(st, T_it, i, j);
            double dS;
            const double S = ekm_source_eval(src, T, &dS);
            int n = 1;
            vals[0] = rho + c.sum_al - dt * dS;
            for (int k = 0; k < 4; k++)
                if (c.a[k] != 0.0) {
                    cols[n] =
                        (DMStagStencil){.loc = DMSTAG_ELEMENT, .i = c.nb[k][0], .j = c.nb[k][1], .c = 0};
                    vals[n] = -c.a[k];
                    n++;
                }
            PetscCall(DMStagMatSetValuesStencil(g->dmt, st->J, 1, cols, n, cols, vals, ADD_VALUES));
            r[j][i][g->t_T] = -residual(rho, T, rhoT_star, &c, dt, S);
        }
    PetscCall(DMStagVecRestoreArray(g->dmt, st->Rl, &r));
    PetscCall(DMLocalToGlobal(g->dmt, st->Rl, INSERT_VALUES, st->R));
    PetscCall(MatAssemblyBegin(st->J, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(st->J, MAT_FINAL_ASSEMBLY));
    return 0;
}

int ekm2d_temperature_solve(ekm2d_step *st, PetscScalar ***u, double dt, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    const double T_floor = sc->numerics.T_floor, tol = sc->numerics.newton_tol;
    sources(st, u);
    /* the first iterate */
    const double change_scale = st->dt_change > 0.0 ? dt / st->dt_change : 0.0;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            const size_t k = ekm2d_box_index(g, i, j);
            const double guess = st->T_star[k] + change_scale * st->T_change[k];
            st->T_it[k] = st->dry[k] ? 0.0 : fmax(fmax(guess, 0.1 * st->T_star[k]), T_floor);
        }
    const double limit = fmax(tol, sqrt(tol));
    for (int it = 1; it <= sc->numerics.newton_max; it++) {
        int restarted = 0;
        PetscErrorCode pe = exchange(st);
        if (!pe) {
            decide(st, dt, it, &restarted);
            pe = exchange(st);
        }
        if (pe || assemble(st, dt)) {
            EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error assembling the temperature system");
            return -1;
        }
        KSPConvergedReason why;
        if (ekm2d_kept_solve(st->ksp_t, &st->t_keep_factor, &st->t_refactors, st->R, st->dT, &why)) {
            EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error solving the temperature system");
            return -1;
        }
        if (why < 0) {
            snprintf(st->reason, sizeof st->reason,
                     "t = %.9g s, dt = %.3g s: the temperature solve failed (%s)", st->t, dt,
                     KSPConvergedReasons[why]);
            return 0;
        }
        const PetscScalar ***d;
        if (DMGlobalToLocal(g->dmt, st->dT, INSERT_VALUES, st->Rl) ||
            DMStagVecGetArrayRead(g->dmt, st->Rl, (void *)&d)) {
            EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error reading the temperature update");
            return -1;
        }
        int converged = !restarted, finite = 1;
        for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
            for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
                const size_t k = ekm2d_box_index(g, i, j);
                if (frozen(st, k)) {
                    st->T_it[k] = st->dry[k] ? 0.0 : st->T_keep[k];
                    continue;
                }
                const double Tj = st->T_it[k];
                double Tn = Tj + d[j][i][g->t_T];
                Tn = Tn > 0.1 * Tj ? Tn : 0.1 * Tj;
                Tn = Tn < T_floor ? T_floor : Tn;
                const double dd = fabs(Tn - Tj);
                const double d_prev = it > 1 ? st->upd[k] : 0.0;
                st->upd[k] = dd;
                converged &= dd < limit * Tn || (dd <= d_prev && dd * dd * dd < tol * Tn * d_prev * d_prev);
                finite &= isfinite(dd);
                st->T_it[k] = Tn;
            }
        DMStagVecRestoreArrayRead(g->dmt, st->Rl, (void *)&d);
        int flags[2] = {converged, finite}, all[2];
        MPI_Allreduce(flags, all, 2, MPI_INT, MPI_LAND, g->comm);
        if (!all[1]) {
            snprintf(st->reason, sizeof st->reason,
                     "t = %.9g s, dt = %.3g s: temperature: non-finite Newton update", st->t, dt);
            return 0;
        }
        if (all[0]) {
            st->newton = it;
            for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
                for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
                    const size_t k = ekm2d_box_index(g, i, j);
                    u[j][i][g->s_T] = st->T_it[k];
                    st->T_change[k] = frozen(st, k) ? 0.0 : st->T_it[k] - st->T_star[k];
                }
            st->dt_change = dt;
            return 1;
        }
    }
    snprintf(st->reason, sizeof st->reason,
             "t = %.9g s, dt = %.3g s: temperature: Newton did not converge in %d iterations", st->t, dt,
             sc->numerics.newton_max);
    return 0;
}
