/* fields2d.c: what the semi-implicit 2D stepper's state reads out
 * (step2d.h): one column as a 1D state (ekm2d_step_column), the run's
 * statistics (ekm2d_step_stats), and the output fields
 * (ekm2d_step_fields) at the cell centres, out2d.h's layout:
 *
 *   phi [-]; vx, vz [m/s] the means of the cell's two faces; T [m^2/s^2];
 *   P = P_K + P_Y - zeta div v [Pa] and sxx, szz [Pa] (model.h's
 *   ekm_stress_plane at the state); sxz [Pa] a quarter of the sum of the
 *   four corners' shear stresses (velocity2d.c's corner rule);
 *   regime: empty (phi < phi_dry), kinetic (phi <= phi_co) or dense;
 *   solid cells ([hypo]): sxx, szz the state's, P = -tr(sigma)/3, regime
 *   solid; with [hypo] sxz is the mean of the corners' state sxz.
 * Empty cells: phi, and zeros.  Gathered to rank 0 in the natural order
 * (x fastest) through a cell-only DMStag of the same decomposition.
 */
#include "step2d_impl.h"

#include <math.h>
#include <petscdmda.h>

#include <stdlib.h>

#include "fields.h"
#include "out2d.h"

/* The properties of every cell of the box at the state u (the output's
 * classification: empty below phi_dry), into the step's work arrays. */
static void state_properties(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    const ekm_cell_properties none = {0};
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j < g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!ekm2d_cell_exists(g, i, j))
                continue;
            const size_t k = ekm2d_box_index(g, i, j);
            const double phi = u[j][i][g->s_phi], T = u[j][i][g->s_T];
            const int dry = !(phi >= sc->numerics.phi_dry) || !(T > 0.0);
            st->dry[k] = (unsigned char)dry;
            st->prop[k] = dry ? none : ekm_cell_properties_at(&sc->material, sc->variant, phi, T);
        }
}

static PetscErrorCode local_fields(ekm2d_step *st, DM dmf, Vec loc)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    PetscScalar ***u, ***o;
    PetscCall(DMGlobalToLocal(g->dm, st->U, INSERT_VALUES, st->Ul));
    PetscCall(DMStagVecGetArray(g->dm, st->Ul, &u));
    st->bottom = ekm2d_grid_end(g, 0, st->t);
    st->top = ekm2d_grid_end(g, 1, st->t);
    state_properties(st, u);
    PetscCall(DMStagVecGetArray(dmf, loc, &o));
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            PetscScalar *v = o[j][i];
            const int wet = !BOX(st, dry, i, j);
            const double phi = u[j][i][g->s_phi];
            for (int q = 0; q < EKM2D_NFIELDS; q++)
                v[q] = 0.0;
            v[EKM2D_PHI] = phi;
            v[EKM2D_REGIME] = EKM_REGIME_EMPTY;
            if (!wet)
                continue;
            v[EKM2D_VX] = 0.5 * (u[j][i][g->s_vx] + u[j][i + 1][g->s_vx]);
            v[EKM2D_VZ] = 0.5 * (u[j][i][g->s_vz] + u[j + 1][i][g->s_vz]);
            v[EKM2D_T] = u[j][i][g->s_T];
            const double exx = (u[j][i + 1][g->s_vx] - u[j][i][g->s_vx]) / g->dx;
            const double ezz = (u[j + 1][i][g->s_vz] - u[j][i][g->s_vz]) / g->dz;
            /* the state's own properties (state_properties above: no surface
             * rule, every coefficient of the cell's own phi) */
            const ekm_plane_stress ps = ekm_stress_plane(&BOX(st, prop, i, j), sc->variant, exx, ezz);
            v[EKM2D_P] = ps.P;
            v[EKM2D_SXX] = ps.sxx;
            v[EKM2D_SZZ] = ps.szz;
            double sum = 0.0, eta;
            int has;
            const PetscInt cn[4][2] = {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}};
            for (int q = 0; q < 4; q++) {
                const double rate = ekm2d_corner_rate(st, u, cn[q][0], cn[q][1], &eta, &has);
                sum += has ? eta * rate : 0.0;
            }
            v[EKM2D_SXZ] = 0.25 * sum;
            v[EKM2D_REGIME] = phi <= sc->material.phi_co ? EKM_REGIME_KINETIC : EKM_REGIME_DENSE;
            if (g->s_sxz >= 0) {
                /* the solid regime: every corner's sxz is the state's (the
                 * solid's, or the flow's of the last step: regime2d.c) */
                v[EKM2D_SXZ] = 0.25 * (u[j][i][g->s_sxz] + u[j][i + 1][g->s_sxz] + u[j + 1][i][g->s_sxz] +
                                       u[j + 1][i + 1][g->s_sxz]);
                if (u[j][i][g->s_solid] > 0.5) {
                    v[EKM2D_SXX] = u[j][i][g->s_sxx];
                    v[EKM2D_SZZ] = u[j][i][g->s_szz];
                    v[EKM2D_P] = -(u[j][i][g->s_sxx] + u[j][i][g->s_syy] + u[j][i][g->s_szz]) / 3.0;
                    v[EKM2D_REGIME] = EKM_REGIME_SOLID;
                }
            }
        }
    PetscCall(DMStagVecRestoreArray(dmf, loc, &o));
    PetscCall(DMStagVecRestoreArray(g->dm, st->Ul, &u));
    return 0;
}

static PetscErrorCode gather(ekm2d_step *st, double *const fields[])
{
    const ekm2d_grid *g = &st->g;
    DM dmf, da;
    Vec loc, glob, split, natural, all;
    VecScatter to_zero;
    PetscCall(DMStagCreateCompatibleDMStag(g->dm, 0, 0, EKM2D_NFIELDS, 0, &dmf));
    PetscCall(DMCreateLocalVector(dmf, &loc));
    PetscCall(VecSet(loc, 0.0));
    PetscCall(local_fields(st, dmf, loc));
    PetscCall(DMCreateGlobalVector(dmf, &glob));
    PetscCall(DMLocalToGlobal(dmf, loc, INSERT_VALUES, glob));
    PetscCall(DMStagVecSplitToDMDA(dmf, glob, DMSTAG_ELEMENT, -EKM2D_NFIELDS, &da, &split));
    PetscCall(DMDACreateNaturalVector(da, &natural));
    PetscCall(DMDAGlobalToNaturalBegin(da, split, INSERT_VALUES, natural));
    PetscCall(DMDAGlobalToNaturalEnd(da, split, INSERT_VALUES, natural));
    PetscCall(VecScatterCreateToZero(natural, &to_zero, &all));
    PetscCall(VecScatterBegin(to_zero, natural, all, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(to_zero, natural, all, INSERT_VALUES, SCATTER_FORWARD));
    int rank;
    MPI_Comm_rank(g->comm, &rank);
    if (rank == 0) {
        const PetscScalar *a;
        PetscCall(VecGetArrayRead(all, &a));
        const size_t ncell = (size_t)g->nx * (size_t)g->nz;
        for (size_t k = 0; k < ncell; k++)
            for (int q = 0; q < EKM2D_NFIELDS; q++)
                fields[q][k] = a[k * EKM2D_NFIELDS + (size_t)q];
        PetscCall(VecRestoreArrayRead(all, &a));
    }
    PetscCall(VecScatterDestroy(&to_zero));
    PetscCall(VecDestroy(&all));
    PetscCall(VecDestroy(&natural));
    PetscCall(VecDestroy(&split));
    PetscCall(DMDestroy(&da));
    PetscCall(VecDestroy(&glob));
    PetscCall(VecDestroy(&loc));
    PetscCall(DMDestroy(&dmf));
    return 0;
}

ekm_status ekm2d_step_fields(ekm2d_step *st, double *const fields[], ekm_error *err)
{
    if (gather(st, fields))
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error gathering the output fields");
    return EKM_OK;
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
    out->dz = g->dz;
    for (int j = 0; j < n; j++)
        out->z[j] = (j + 0.5) * g->dz;
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
    out->dz = g->dz;
    out->mass_in = st->mass_in;
    out->newton = st->newton;
    out->newton_total = st->newton_total;
    out->phi_max = phi_all;
    out->solid_lag_max = st->solid_lag_max;
    out->solid_floor_steps = st->solid_floor_steps;
    long sw[2] = {st->to_solid, st->to_flow}, sw_all[2];
    MPI_Allreduce(sw, sw_all, 2, MPI_LONG, MPI_SUM, g->comm);
    out->to_solid = sw_all[0];
    out->to_flow = sw_all[1];
    return EKM_OK;
}
