/* point.c: the EKM state of a campaign point by the steady policy, and the
 * agreement of two states (point.h). */
#include "point.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fields.h"
#include "local_slab.h"
#include "run.h"
#include "state.h"
#include "steady_solve.h"
#include "step.h"

/* max |a - b| / max |b| over the cells where use (NULL: all) is set */
static double relative_difference(const double *a, const double *b, const unsigned char *use, size_t n)
{
    double scale = 0.0, diff = 0.0;
    for (size_t j = 0; j < n; j++) {
        if (use && !use[j])
            continue;
        scale = fmax(scale, fabs(b[j]));
        diff = fmax(diff, fabs(a[j] - b[j]));
    }
    const double rel = scale > 0.0 ? diff / scale : (diff > 0.0 ? INFINITY : 0.0);
    return isnan(rel) ? INFINITY : rel;
}

double ekm_point_agreement(const ekm_point_view *a, const ekm_point_view *b, const char **field)
{
    const size_t n = b->n;
    double phi_max = 0.0;
    for (size_t j = 0; j < n; j++)
        phi_max = fmax(phi_max, b->phi[j]);
    const double support = EKM_POINT_SUPPORT * phi_max;
    unsigned char *use = malloc(n ? n : 1);
    size_t used = 0;
    for (size_t j = 0; use && j < n; j++) {
        use[j] = a->phi[j] >= support && b->phi[j] >= support;
        used += use[j];
    }
    if (!use || !used) {
        free(use);
        if (field)
            *field = "support";
        return INFINITY;
    }
    const char *names[] = {"phi", "vx", "T", "P"};
    const double *fa[] = {a->phi, a->vx, a->T, a->P}, *fb[] = {b->phi, b->vx, b->T, b->P};
    double worst = -1.0;
    const char *where = "phi";
    for (int f = 0; f < 4; f++) {
        const double rel = relative_difference(fa[f], fb[f], f == 0 ? NULL : use, n);
        if (rel > worst) {
            worst = rel;
            where = names[f];
        }
    }
    free(use);
    if (!isnan(a->gap) && !isnan(b->gap)) {
        const double rel = relative_difference(&a->gap, &b->gap, NULL, 1);
        if (rel > worst) {
            worst = rel;
            where = "gap";
        }
    }
    if (field)
        *field = where;
    return worst;
}

void ekm_point_free(ekm_point *p)
{
    free(p->z); /* one block: z and the five profiles */
    *p = (ekm_point){0};
}

/* The profiles of state s as ekm writes them, into p (one block). */
static ekm_status profiles_of(const ekm_scenario *sc, const ekm_state *s, ekm_point *p, ekm_error *err)
{
    const size_t n = (size_t)s->n;
    double *block = malloc(n * 8 * sizeof *block);
    int *regime = malloc(n * sizeof *regime);
    if (!block || !regime) {
        free(block);
        free(regime);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (the point's profiles, %zu cells)", n);
    }
    p->n = n;
    p->z = block;
    p->phi = block + n;
    p->vx = block + 2 * n;
    p->T = block + 3 * n;
    p->P = block + 4 * n;
    p->sxz = block + 5 * n;
    ekm_fields fl = {
        .vx = p->vx, .vz = block + 6 * n, .P = p->P, .sxz = p->sxz, .szz = block + 7 * n, .regime = regime};
    ekm_slab_fields(sc, s, s->t, &fl); /* what ekm writes (h5out.c) */
    memcpy(p->z, s->z, n * sizeof(double));
    memcpy(p->phi, s->phi, n * sizeof(double));
    memcpy(p->T, s->T, n * sizeof(double));
    free(regime);
    return EKM_OK;
}

static double gap_of(const ekm_scenario *sc, const ekm_state *s)
{
    return ekm_boundary_pressure_wall(&sc->top) ? s->dz * s->n : NAN;
}

/* The steady solver of sc's closure takes sc (ekm steady's test): the
 * EKM's (steady_solve.h) or a local rheology's slab solver (local_slab.h). */
static int steady_takes(const ekm_scenario *sc, ekm_error *why)
{
    if (ekm_local_slab_applies(sc))
        return ekm_local_slab_check(sc, why) == EKM_OK;
    return ekm_steady_supported(sc, why) == EKM_OK;
}

/* The steady state from the initial state (`ekm steady`): Newton of the
 * EKM's steady solver or of the local rheology's slab solver. */
static ekm_status steady_from_start(const ekm_scenario *sc, ekm_state *s, ekm_error *err)
{
    if (!ekm_local_slab_applies(sc)) {
        ekm_state_init(s, sc);
        return ekm_steady_solve(sc, s, NULL, err);
    }
    ekm_local_slab *ls = ekm_local_slab_alloc(sc, err);
    if (!ls)
        return err->code;
    ekm_local_slab_steady_report rep;
    ekm_status st = ekm_local_slab_init(ls, s, err);
    if (st == EKM_OK)
        st = ekm_local_slab_steady(ls, s, &rep, err);
    ekm_local_slab_free(ls);
    return st;
}

/* Time stepping from the initial state (`ekm run`: the EKM's stepper or the
 * local rheology's slab solver); *steady: it ended steady. */
static ekm_status run_from_start(const ekm_scenario *sc, ekm_state *s, int *steady, ekm_error *err)
{
    ekm_run_stats stats;
    if (ekm_local_slab_applies(sc)) {
        ekm_local_slab *ls = ekm_local_slab_alloc(sc, err);
        if (!ls)
            return err ? err->code : EKM_ENOMEM;
        ekm_status st = ekm_local_slab_init(ls, s, err);
        if (st == EKM_OK)
            st = ekm_local_slab_run(ls, s, NULL, &stats, err);
        ekm_local_slab_free(ls);
        *steady = st == EKM_OK && stats.steady;
        return st;
    }
    ekm_state_init(s, sc);
    ekm_stepper *stp = ekm_step_alloc(sc, err);
    if (!stp)
        return err ? err->code : EKM_ENOMEM;
    const ekm_status st = ekm_run(sc, s, stp, NULL, &stats, err);
    ekm_step_free(stp);
    *steady = st == EKM_OK && stats.steady;
    return st;
}

ekm_status ekm_point_solve(const ekm_scenario *scenario, const ekm_material *m, int check, ekm_point *p,
                           ekm_error *err)
{
    *p = (ekm_point){0};
    ekm_scenario sc = *scenario; /* shares the entries: read only */
    ekm_status st = ekm_scenario_set_material(&sc, m, err);
    if (st != EKM_OK)
        return st;
    ekm_state *s = ekm_state_alloc(sc.cells, sc.length);
    if (!s)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (a state of %d cells)", sc.cells);
    int steady = 0;
    ekm_error why = {0};
    p->solver = EKM_POINT_RUN;
    if (sc.stop == EKM_STOP_STEADY && steady_takes(&sc, &why)) {
        const ekm_status rc = steady_from_start(&sc, s, &why);
        if (rc == EKM_OK) {
            p->solver = EKM_POINT_NEWTON;
        } else if (rc != EKM_ENOTSTEADY) {
            if (err)
                *err = why;
            ekm_state_free(s);
            return rc;
        }
    }
    if (p->solver == EKM_POINT_NEWTON && !check) {
        st = profiles_of(&sc, s, p, err);
    } else if (p->solver == EKM_POINT_NEWTON) {
        ekm_state *r = ekm_state_alloc(sc.cells, sc.length);
        ekm_point run = {0};
        st = r ? run_from_start(&sc, r, &steady, err) : EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        if (st == EKM_OK)
            st = profiles_of(&sc, s, p, err);
        if (st == EKM_OK)
            st = profiles_of(&sc, r, &run, err);
        if (st == EKM_OK) {
            const ekm_point_view a = {p->n, p->phi, p->vx, p->T, p->P, gap_of(&sc, s)};
            const ekm_point_view b = {run.n, run.phi, run.vx, run.T, run.P, gap_of(&sc, r)};
            p->checked = 1;
            p->run_steady = steady;
            p->agreement = ekm_point_agreement(&a, &b, NULL);
            if (!(steady && p->agreement <= EKM_POINT_AGREE_TOL)) {
                ekm_point keep = *p;
                *p = run;
                run = keep;
                p->solver = EKM_POINT_RUN;
                p->checked = 1;
                p->run_steady = steady;
                p->agreement = keep.agreement;
            }
        }
        ekm_point_free(&run);
        ekm_state_free(r);
    } else {
        st = run_from_start(&sc, s, &steady, err);
        if (st == EKM_OK)
            st = profiles_of(&sc, s, p, err);
    }
    ekm_state_free(s);
    if (st != EKM_OK)
        ekm_point_free(p);
    return st;
}
