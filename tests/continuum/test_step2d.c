/* test_step2d.c: the semi-implicit 2D step (continuum/twod/step2d.h) on
 * states uniform in x reproduces the 1D step (continuum/step.h), step by
 * step with the same dt, and conserves mass to round-off.
 *
 * usage: test_step2d SOURCE_DIR CASE  (CASE: a scenario of scenarios/ with
 * wall, free or inflow ends: simple_shear, chute, filling, thesis_filling;
 * the flow regimes, hypo off)
 *
 * Each case loads the scenario twice, as the 1D slab and as a box of 2
 * columns periodic in x, starts both from the scenario's initial state
 * and takes STEPS steps, dt chosen by the 1D solver's control (control.h,
 * growing at most 1.5x per step as run.c does); after every step each
 * column of the 2D state must equal the 1D state: phi and T within the
 * case's tolerance (case_tolerance) of their largest value, u (vx) and w
 * (vz) of the largest speed.  The two solve the same equations with
 * different linear solvers (PETSc's LU of the 2D systems, LAPACK's
 * tridiagonal solves in 1D): the difference is their round-off, and mass
 * is conserved to round-off.
 */
#include <math.h>
#include <petscsys.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "control.h"
#include "scenario.h"
#include "state.h"
#include "step.h"
#include "step2d.h"

#define STEPS    200
#define MASS_TOL 1e-13

/* The tolerance of a case: round-off (1e-9), except filling: there the 1D
 * normal solve (LAPACK dgtsv, partial pivoting) leaves w ~ 1e-15 m/s at
 * the empty faces above the falling stream's front where the 2D LU leaves
 * exactly 0; at the step the front's cell joins, that face's upwind phi
 * of the pressure coupling is then the cell above (1D, w < 0) or the mean
 * of the two (2D, w = 0: implicit.h's rule at rest), and the two runs
 * differ by 2.2e-5 of the largest speed at t = 0.0148 s, 2.3e-7 of the
 * largest T, falling to 7e-9 within 4 steps (measured 2026-12-06). */
static double case_tolerance(const char *name)
{
    return strcmp(name, "filling") == 0 ? 1e-4 : 1e-9;
}

#define FAIL(...)                              \
    do {                                       \
        fprintf(stderr, "FAIL: " __VA_ARGS__); \
        rc = 1;                                \
        goto done;                             \
    } while (0)

static int load(const char *src, const char *name, const char *const *sets, size_t n, ekm_scenario *sc)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenarios/%s.ini", src, name);
    ekm_error err = {0};
    if (ekm_scenario_load(sc, path, sets, n, &err) != EKM_OK) {
        fprintf(stderr, "FAIL: %s\n", err.message);
        return 1;
    }
    return 0;
}

/* The largest |a - b| over n values relative to scale. */
static double rel_diff(const double *a, const double *b, int n, double scale)
{
    double d = 0.0;
    for (int k = 0; k < n; k++)
        d = fmax(d, fabs(a[k] - b[k]));
    return d / scale;
}

/* The largest |a| over n values (at least 1e-300). */
static double largest(const double *a, int n)
{
    double m = 1e-300;
    for (int k = 0; k < n; k++)
        m = fmax(m, fabs(a[k]));
    return m;
}

static int run_case(const char *src, const char *name)
{
    const char *sets1[] = {"hypo.enabled=0", "run.stop=t_end"};
    const char *sets2[] = {"hypo.enabled=0", "run.stop=t_end", "domain.cells_x=2", "domain.width=0.01",
                           "domain.periodic_x=1"};
    ekm_scenario sc1, sc2;
    int rc = 0;
    if (load(src, name, sets1, 2, &sc1))
        return 1;
    if (load(src, name, sets2, 5, &sc2)) {
        ekm_scenario_free(&sc1);
        return 1;
    }
    ekm_error err = {0};
    ekm_state *s = ekm_state_alloc(sc1.cells, sc1.length), *col = ekm_state_alloc(sc1.cells, sc1.length);
    ekm_stepper *st = NULL;
    ekm2d_step *st2 = NULL;
    if (!s || !col)
        FAIL("out of memory\n");
    ekm_state_init(s, &sc1);
    if (!(st = ekm_step_alloc(&sc1, &err)))
        FAIL("%s\n", err.message);
    if (ekm2d_step_create(&sc2, PETSC_COMM_WORLD, s, &st2, &err) != EKM_OK)
        FAIL("%s\n", err.message);
    ekm2d_step_info info0;
    if (ekm2d_step_stats(st2, &info0, &err) != EKM_OK)
        FAIL("%s\n", err.message);
    const int n = sc1.cells;
    const double TOL = case_tolerance(name);
    double worst[4] = {0, 0, 0, 0}, worst_mass = 0.0;
    double dt_prev = ekm_control_restart_dt(&sc1, s) / 1.5;
    const int steps = getenv("EKM_STEPS") ? atoi(getenv("EKM_STEPS")) : STEPS;
    for (int step = 0; step < steps; step++) {
        double dt = fmin(ekm_control_max_dt(&sc1, s, NULL), 1.5 * dt_prev);
        int ok1 = 0, ok2 = 0;
        for (int tries = 0; tries < 30 && !ok1; tries++) {
            if (ekm_step_apply(st, s, dt, &ok1, &err) != EKM_OK)
                FAIL("%s: 1D step: %s\n", name, err.message);
            if (ok1) {
                if (ekm2d_step_apply(st2, dt, &ok2, &err) != EKM_OK)
                    FAIL("%s: 2D step: %s\n", name, err.message);
                if (!ok2)
                    FAIL("%s: step %d, dt %.3g s: the 1D step was accepted, the 2D step rejected: %s\n", name,
                         step, dt, ekm2d_step_reason(st2));
            } else {
                if (ekm2d_step_apply(st2, dt, &ok2, &err) != EKM_OK)
                    FAIL("%s: 2D step: %s\n", name, err.message);
                if (ok2)
                    FAIL("%s: step %d, dt %.3g s: the 1D step was rejected (%s), the 2D step accepted\n",
                         name, step, dt, st->reject_reason);
                dt *= 0.5;
            }
        }
        if (!ok1)
            FAIL("%s: step %d: no accepted step\n", name, step);
        dt_prev = dt;
        for (int i = 0; i < 2; i++) {
            if (ekm2d_step_column(st2, i, col, &err) != EKM_OK)
                FAIL("%s\n", err.message);
            /* velocities relative to the largest speed of the 1D state */
            const double v = fmax(largest(s->u, n), largest(s->w, n + 1));
            const double d[4] = {rel_diff(s->phi, col->phi, n, largest(s->phi, n)),
                                 rel_diff(s->u, col->u, n, v), rel_diff(s->w, col->w, n + 1, v),
                                 rel_diff(s->T, col->T, n, largest(s->T, n))};
            for (int k = 0; k < 4; k++)
                worst[k] = fmax(worst[k], d[k]);
            if (getenv("EKM_CELLS") && i == 0 && step == atoi(getenv("EKM_CELLS")))
                for (int j = 0; j < n; j++)
                    printf("  %2d phi %.6g/%.6g u %.9g/%.9g w %.9g/%.9g T %.6g/%.6g\n", j, s->phi[j],
                           col->phi[j], s->u[j], col->u[j], s->w[j], col->w[j], s->T[j], col->T[j]);
            if (getenv("EKM_VERBOSE") && i == 0)
                printf("step %d t %.6g dt %.3g: phi %.2e vx %.2e vz %.2e T %.2e\n", step, s->t, dt, d[0],
                       d[1], d[2], d[3]);
        }
        ekm2d_step_info info;
        if (ekm2d_step_stats(st2, &info, &err) != EKM_OK)
            FAIL("%s\n", err.message);
        const double scale = fmax(info.mass, info0.mass);
        worst_mass = fmax(worst_mass, fabs(info.mass - info0.mass - info.mass_in) / scale);
    }
    printf("%s: %d steps to t = %.6g s: 2D columns against 1D: phi %.2e, vx %.2e, vz %.2e, T %.2e (tolerance "
           "%.0e); mass - initial - entered %.2e of the mass (tolerance %.0e)\n",
           name, steps, s->t, worst[0], worst[1], worst[2], worst[3], TOL, worst_mass, MASS_TOL);
    for (int k = 0; k < 4; k++)
        if (!(worst[k] <= TOL))
            FAIL("%s: field %d differs by %.3g > %.0e\n", name, k, worst[k], TOL);
    if (!(worst_mass <= MASS_TOL))
        FAIL("%s: mass balance %.3g > %.0e\n", name, worst_mass, MASS_TOL);
done:
    ekm2d_step_destroy(st2);
    ekm_step_free(st);
    ekm_state_free(s);
    ekm_state_free(col);
    ekm_scenario_free(&sc1);
    ekm_scenario_free(&sc2);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_step2d SOURCE_DIR CASE\n");
        return 2;
    }
    char *pargv[] = {argv[0], (char *)"-no_signal_handler", NULL};
    int pargc = 2;
    char **pa = pargv;
    if (PetscInitialize(&pargc, &pa, NULL, NULL))
        return 3;
    if (!getenv("EKM_PETSC_TRACE"))
        PetscPushErrorHandler(PetscReturnErrorHandler, NULL);
    const int rc = run_case(argv[1], argv[2]);
    PetscFinalize();
    return rc;
}
