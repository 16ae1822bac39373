/* solver2d.c: the run API of the 2D EKM (solver2d.h) over the
 * semi-implicit step (step2d.h). */
#include "solver2d.h"

#include "closure.h"

#include <math.h>
#include <stdlib.h>

struct ekm2d_solver {
    const ekm_scenario *sc;
    ekm2d_step *step;
};

ekm_status ekm2d_supported(const ekm_scenario *sc, ekm_error *err)
{
    const char *src = sc->source;
    ekm_error cerr;
    if (ekm_closure_require_ekm(sc->closure, "the 2D solver", &cerr) != EKM_OK)
        return EKM_FAIL(err, cerr.code, "%s: %s", src, cerr.message);
    if (!(sc->cells_x >= 2))
        return EKM_FAIL(err, EKM_EINPUT, "%s: [domain] cells_x = %d: the 2D solver needs cells_x >= 2", src,
                        sc->cells_x);
    if (sc->cells < 2)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [domain] cells = %d: the 2D solver needs at least 2 cells along z", src,
                        sc->cells);
    if (sc->stop == EKM_STOP_STEADY)
        return EKM_FAIL(err, EKM_EUNAVAILABLE,
                        "%s: [run] stop = steady: the 2D solver stops at t_end only (issue 33)", src);
    if (sc->bottom.kind == EKM_BC_INFLOW && sc->bottom.w < 0.0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [bottom] w = %g: an inflow through the bottom needs w > 0 [m/s]", src,
                        sc->bottom.w);
    if (sc->top.kind == EKM_BC_INFLOW && sc->top.w > 0.0)
        return EKM_FAIL(err, EKM_EINPUT, "%s: [top] w = %g: an inflow through the top needs w < 0 [m/s]", src,
                        sc->top.w);
    return ekm2d_step_supported(sc, err);
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
    s->sc = sc;
    st = ekm2d_step_create(sc, comm, init, &s->step, err);
    if (st != EKM_OK) {
        free(s);
        return st;
    }
    *out = s;
    return EKM_OK;
}

void ekm2d_solver_destroy(ekm2d_solver *s)
{
    if (!s)
        return;
    ekm2d_step_destroy(s->step);
    free(s);
}

ekm_status ekm2d_solver_advance(ekm2d_solver *s, double t_to, ekm_error *err)
{
    return ekm2d_step_advance(s->step, t_to, err);
}

ekm_status ekm2d_solver_save(ekm2d_solver *s, ekm2d_restart *out, ekm_error *err)
{
    return ekm2d_step_save(s->step, out, err);
}

ekm_status ekm2d_solver_load(ekm2d_solver *s, const ekm2d_restart *in, ekm_error *err)
{
    return ekm2d_step_load(s->step, in, err);
}

ekm_status ekm2d_solver_fields(ekm2d_solver *s, double *const fields[EKM2D_NFIELDS], ekm_error *err)
{
    return ekm2d_step_fields(s->step, fields, err);
}

ekm_status ekm2d_solver_stats(ekm2d_solver *s, ekm2d_stats *out, ekm_error *err)
{
    ekm2d_step_info in;
    const ekm_status st = ekm2d_step_stats(s->step, &in, err);
    if (st != EKM_OK)
        return st;
    *out = (ekm2d_stats){.t = in.t,
                         .steps = in.steps,
                         .rejected = in.rejected,
                         .newton = in.newton_total,
                         .mass = in.mass,
                         .dz = in.dz,
                         .mass_in = in.mass_in,
                         .phi_max = in.phi_max,
                         .cell_updates = (double)in.steps * s->sc->cells_x * s->sc->cells,
                         .to_solid = in.to_solid,
                         .to_flow = in.to_flow,
                         .solid_lag_max = in.solid_lag_max,
                         .solid_floor_steps = in.solid_floor_steps};
    return EKM_OK;
}
