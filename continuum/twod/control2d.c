/* control2d.c: the step size of the semi-implicit 2D step and its time
 * loop (step2d.h: ekm2d_step_advance), the 1D solver's control.h and
 * run.c in two dimensions.
 *
 *   convective   dt (|vx|/dx + |vz|/dz) <= cfl in every cell, the face
 *                speeds of its four faces (the explicit upwind transport
 *                of phase 2-3; the pressure coupling is implicit, so the
 *                sound speed does not limit the step); an open inlet's
 *                speed counts at its faces
 *   compression  the mass update's net inflow -div(phi_up v) closes at most
 *                half of phi_step_max of the gap phi_cp - phi per step (a
 *                step beyond phi_step_max is rejected: step2d.c); the 1D
 *                control takes -phi div v, which counts a dilute stream
 *                landing on a bed at the bed's phi
 *   thermal      dt eps P_K/(P_K + P_Y) <= thermal_relax_step (control.h)
 *                in flowing cells
 *   solid        the last step's lag error of the solid cells' law
 *                (regime2d.c: ekm2d_regime_lag_error, at most
 *                solid_lag_tol; step2d.c): dt_solid = dt 0.9
 *                solid_lag_tol / error, at most 1.5 dt, but never below
 *                the acoustic step of the solid cells (control.h), where
 *                the linearly implicit law is accurate enough (control.c)
 *   dt_max
 * The step grows at most 1.5x per step; after a change of the driving (an
 * inflow opens or closes) it restarts from the acoustic step cfl h /
 * max(|v| + c) over the wet cells (h = min(dx, dz)); a rejected step is
 * retried with half of it, and below dt_min the run stops (EKM_ENUMERIC,
 * with the reason of the last rejection).  The PETSc option
 * -ekm_step_monitor prints each rejection's reason.
 */
#include "step2d_impl.h"

#include <math.h>
#include <stdio.h>

#include "control.h"

/* Which limit set the step (for -ekm_step_monitor). */
enum { LIM_NONE, LIM_CONVECTIVE, LIM_COMPRESSION, LIM_THERMAL, LIM_ACOUSTIC, LIM_SOLID };
static const char *const LIMIT_NAMES[] = {"dt_max",   "convective",     "compression", "thermal relaxation",
                                          "acoustic", "solid lag error"};

typedef struct {
    int which;     /* LIM_* */
    PetscInt i, j; /* the cell that set it */
} limit_at;

static inline void take(double *dt, limit_at *why, double limit, int which, PetscInt i, PetscInt j)
{
    if (limit < *dt) {
        *dt = limit;
        *why = (limit_at){which, i, j};
    }
}

/* The limits of the state in u (dm's local array, ghosts current); *why
 * the limit that set it. */
static double max_dt_local(const ekm2d_step *st, PetscScalar ***u, int acoustic, limit_at *why,
                           double *dt_solid_floor)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const double cfl = sc->numerics.cfl, h = fmin(g->dx, g->dz);
    const ekm2d_end ends[2] = {ekm2d_grid_end(g, 0, st->t), ekm2d_grid_end(g, 1, st->t)};
    double dt = INFINITY;
    *dt_solid_floor = INFINITY;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            const double vx = fmax(fabs(u[j][i][g->s_vx]), fabs(u[j][i + 1][g->s_vx]));
            double vz = fmax(fabs(u[j][i][g->s_vz]), fabs(u[j + 1][i][g->s_vz]));
            if (j == 0 && ekm2d_inlet_face(g, &ends[0], i))
                vz = fmax(vz, fabs(ends[0].w));
            if (j == g->nz - 1 && ekm2d_inlet_face(g, &ends[1], i))
                vz = fmax(vz, fabs(ends[1].w));
            const double phi = u[j][i][g->s_phi], T = u[j][i][g->s_T];
            const int wet = phi >= sc->numerics.phi_dry && T > 0.0;
            if (acoustic) {
                const double c = wet ? ekm_sound_speed(m, phi, T) : 0.0;
                const double speed = fmax(vx, vz) + c;
                if (speed > 0.0)
                    take(&dt, why, cfl * h / speed, LIM_ACOUSTIC, i, j);
                continue;
            }
            const double rate = vx / g->dx + vz / g->dz;
            if (rate > 0.0)
                take(&dt, why, cfl / rate, LIM_CONVECTIVE, i, j);
            if (!wet)
                continue;
            /* what the mass update will do with these velocities: the
             * upwind fluxes' net inflow (not -phi div v, which counts a
             * dilute stream landing on a bed at the bed's phi) */
            const double inflow = -(ekm2d_flux_x(g, u, i + 1, j) - ekm2d_flux_x(g, u, i, j)) / g->dx -
                                  (ekm2d_flux_z(g, &ends[0], &ends[1], u, i, j + 1) -
                                   ekm2d_flux_z(g, &ends[0], &ends[1], u, i, j)) /
                                      g->dz;
            const double compression = inflow / (m->phi_cp - phi);
            if (compression > 0.0)
                take(&dt, why, 0.5 * sc->numerics.phi_step_max / compression, LIM_COMPRESSION, i, j);
            if (g->s_solid >= 0 && u[j][i][g->s_solid] > 0.5) {
                /* a solid cell: its stress is implicit; the lag error
                 * (dt_solid) limits it, never below its acoustic step */
                *dt_solid_floor =
                    fmin(*dt_solid_floor, cfl * h / (fmax(vx, vz) + ekm_sound_speed(m, phi, T)));
                continue;
            }
            const double relax = ekm_thermal_relaxation_rate(m, phi, T);
            if (relax > 0.0)
                take(&dt, why, sc->numerics.thermal_relax_step / relax, LIM_THERMAL, i, j);
        }
    return dt;
}

/* The largest step of the state (acoustic = 1: the restart step), at most
 * dt_max; collective. */
static ekm_status max_dt(ekm2d_step *st, int acoustic, double *dt, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    PetscScalar ***u;
    if (DMGlobalToLocal(g->dm, st->U, INSERT_VALUES, st->Ul) || DMStagVecGetArray(g->dm, st->Ul, &u))
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error reading the state");
    limit_at why = {LIM_NONE, -1, -1};
    double floor_local;
    double local = max_dt_local(st, u, acoustic, &why, &floor_local), all = local;
    DMStagVecRestoreArray(g->dm, st->Ul, &u);
    MPI_Allreduce(&floor_local, &st->dt_solid_floor, 1, MPI_DOUBLE, MPI_MIN, g->comm);
    const double dt_solid = fmax(st->dt_solid, st->dt_solid_floor);
    if (!acoustic && dt_solid < local) {
        local = dt_solid;
        why = (limit_at){LIM_SOLID, -1, -1};
    }
    MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_MIN, g->comm);
    *dt = fmin(all, st->sc->numerics.dt_max);
    if (st->monitor && !acoustic)
        PetscPrintf(g->comm, "ekm 2D: t = %.9g s: step limit %.3g s (%s, cell %d %d)\n", st->t, *dt,
                    local == all && local < st->sc->numerics.dt_max ? LIMIT_NAMES[why.which]
                                                                    : "dt_max or another rank",
                    (int)why.i, (int)why.j);
    return EKM_OK;
}

ekm_status ekm2d_step_advance(ekm2d_step *st, double t_to, ekm_error *err)
{
    const ekm_scenario *sc = st->sc;
    ekm_status rc = EKM_OK;
    /* fresh factorisations at each advance (each output frame): a run
     * resumed here from a checkpoint (restart2d.c) takes the same steps */
    st->v_keep_factor = st->t_keep_factor = 0;
    if (!(st->dt_prev > 0.0)) { /* the start: from the acoustic step */
        double dt0;
        if ((rc = max_dt(st, 1, &dt0, err)) != EKM_OK)
            return rc;
        st->dt_prev = dt0 / EKM2D_GROWTH;
    }
    while (st->t < t_to * (1.0 - 1e-12)) {
        double dt;
        if ((rc = max_dt(st, 0, &dt, err)) != EKM_OK)
            return rc;
        dt = fmin(dt, EKM2D_GROWTH * st->dt_prev);
        if (dt < sc->numerics.dt_min)
            return EKM_FAIL(err, EKM_ENUMERIC,
                            "%s: t = %.9g s: the step limit %.3g s is below dt_min = %g s (2D)", sc->source,
                            st->t, dt, sc->numerics.dt_min);
        int at_event = 0;
        const double target = fmin(ekm_control_target(sc, st->t, t_to, &at_event), t_to);
        if (st->t + dt >= target * (1.0 - 1e-12))
            dt = target - st->t;
        else
            at_event = 0;
        int accepted = 0;
        while (!accepted) {
            if ((rc = ekm2d_step_apply(st, dt, &accepted, err)) != EKM_OK)
                return rc;
            if (!accepted && st->monitor)
                PetscPrintf(st->g.comm, "ekm 2D: step rejected: %s\n", st->reason);
            if (!accepted) {
                dt *= 0.5;
                at_event = 0;
                if (dt < sc->numerics.dt_min)
                    return EKM_FAIL(err, EKM_ENUMERIC, "%s: step rejected down to dt = %.3g s < dt_min: %s",
                                    sc->source, dt, st->reason);
            }
        }
        if (at_event) { /* the driving changed: restart from the acoustic step */
            double dt0;
            if ((rc = max_dt(st, 1, &dt0, err)) != EKM_OK)
                return rc;
            st->dt_prev = dt0 / EKM2D_GROWTH;
        } else {
            st->dt_prev = dt;
        }
    }
    return EKM_OK;
}
