/* test_step2d.c: the semi-implicit 2D step (continuum/twod/step2d.h) on
 * states uniform in x reproduces the 1D step (continuum/step.h), step by
 * step with the same dt, and conserves mass to round-off.
 *
 * usage: test_step2d SOURCE_DIR CASE  (CASE: a scenario of scenarios/ with
 * wall, free or inflow ends: simple_shear, chute, filling, thesis_filling,
 * shear_cell (a top wall held at a pressure: the grid stretches, and the
 * two gaps must agree as the fields),
 * with the flow regimes only ([hypo] off); NAME+solid with the solid
 * regime on: filling+solid, tilting_layer+solid)
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
 * is conserved to round-off.  With the solid regime the two must also
 * agree in every cell's regime at every step and in the solid stresses
 * (sxx, syy, szz of solid cells, sxz of the faces beside them, relative
 * to the largest |sigma_zz| of the solid cells).  Environment: EKM_STEPS,
 * EKM_SET (one KEY=VALUE), EKM_LOG (the switch log), EKM_VERBOSE,
 * EKM_CELLS / EKM_STRESS (one step's cells).
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
static double case_tolerance(const char *name, int solid)
{
    if (strcmp(name, "filling") == 0)
        return 1e-4;
    /* tilting_layer+solid: at the failure (t = 0.8573 s) the layer starts
     * from rest, its speeds from the round-off of the stress balance
     * (1e-22 m/s) to 1e-2 m/s within a few hundred steps, and the two
     * solvers' round-off grows with them to 3.0e-9 of the largest speed
     * and 1.5e-9 of the largest T (measured 2026-12-06, 1000 steps); the
     * regime flags stay equal and the solid stresses within 6e-12 */
    return solid ? 1e-8 : 1e-9;
}

/* Steps of a case: the solid cases far enough for the regime to act
 * (filling: 12 bed cells solid by step 3000; tilting_layer: the failure
 * at step 31 and 970 steps of flow after it). */
static int case_steps(const char *name, int solid)
{
    if (getenv("EKM_STEPS"))
        return atoi(getenv("EKM_STEPS"));
    if (solid)
        return strcmp(name, "filling") == 0 ? 3000 : 1000;
    /* shear_cell: the top wall, held at 100 Pa, settles from 42 to 38.4 mm
     * in 0.26 s */
    return strcmp(name, "shear_cell") == 0 ? 2000 : STEPS;
}

/* A case's setting beside its scenario (NULL: none), from EKM_SET or:
 * tilting_layer starts at 24.2 deg, close to its failure near 24.28 deg,
 * so that the layer fails (solid -> flow) within the test's steps. */
static const char *case_setting(const char *name)
{
    if (getenv("EKM_SET"))
        return getenv("EKM_SET");
    return strcmp(name, "tilting_layer") == 0 ? "gravity.angle=24.2" : NULL;
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

static int run_case(const char *src, const char *arg)
{
    /* CASE+solid: the solid regime on ([hypo] enabled = 1) */
    char name[256];
    snprintf(name, sizeof name, "%s", arg);
    char *plus = strchr(name, '+');
    const int solid = plus && strcmp(plus, "+solid") == 0;
    if (plus)
        *plus = '\0';
    const char *hypo = solid ? "hypo.enabled=1" : "hypo.enabled=0";
    const char *log = getenv("EKM_LOG") ? "hypo.log=1" : "hypo.log=0";
    const char *extra = case_setting(name);
    const char *sets1[] = {hypo, "run.stop=t_end", log, extra};
    const char *sets2[] = {
        hypo, "run.stop=t_end", log, "domain.cells_x=2", "domain.width=0.01", "domain.periodic_x=1", extra};
    ekm_scenario sc1, sc2;
    int rc = 0;
    if (load(src, name, sets1, extra ? 4 : 3, &sc1))
        return 1;
    if (load(src, name, sets2, extra ? 7 : 6, &sc2)) {
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
    const double TOL = case_tolerance(name, solid);
    double worst[4] = {0, 0, 0, 0}, worst_mass = 0.0, worst_stress = 0.0, worst_gap = 0.0;
    const double gap0 = s->n * s->dz;
    int flag_diff = 0, solid_max = 0;
    double dt_prev = ekm_control_restart_dt(&sc1, s) / 1.5;
    const int steps = case_steps(name, solid);
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
            /* velocities relative to the largest speed of the 1D state, at
             * least 1e-10 sqrt(g L): a solid layer at rest moves at the
             * round-off of its stress balance (about 1e-22 m/s in
             * tilting_layer), which is no scale */
            const double v =
                fmax(fmax(largest(s->u, n), largest(s->w, n + 1)), 1e-10 * sqrt(sc1.gravity * sc1.length));
            const double d[4] = {rel_diff(s->phi, col->phi, n, largest(s->phi, n)),
                                 rel_diff(s->u, col->u, n, v), rel_diff(s->w, col->w, n + 1, v),
                                 rel_diff(s->T, col->T, n, largest(s->T, n))};
            for (int k = 0; k < 4; k++)
                worst[k] = fmax(worst[k], d[k]);
            /* a pressure-controlled top wall (shear_cell): the gap */
            worst_gap = fmax(worst_gap, fabs(col->dz - s->dz) / s->dz);
            if (solid) {
                /* the solid stresses relative to the largest |sigma_zz| of
                 * the solid cells (1D), and the regime flags */
                double scale = 1e-300, ds = 0.0;
                int count = 0;
                for (int j = 0; j < n; j++)
                    if (s->solid[j])
                        scale = fmax(scale, fabs(s->szz[j]));
                for (int j = 0; j < n; j++) {
                    flag_diff += s->solid[j] != col->solid[j];
                    count += s->solid[j];
                    if (s->solid[j] && col->solid[j])
                        ds = fmax(ds, fmax(fmax(fabs(s->sxx[j] - col->sxx[j]), fabs(s->syy[j] - col->syy[j])),
                                           fabs(s->szz[j] - col->szz[j])));
                }
                for (int f = 0; f <= n; f++)
                    if ((f > 0 && s->solid[f - 1]) || (f < n && s->solid[f]))
                        ds = fmax(ds, fabs(s->sxz[f] - col->sxz[f]));
                if (getenv("EKM_STRESS") && i == 0 && step == atoi(getenv("EKM_STRESS")))
                    for (int j = 0; j <= n; j++)
                        printf("  %2d solid %d/%d sxx %.9g/%.9g szz %.9g/%.9g sxz %.9g/%.9g\n", j,
                               j < n ? s->solid[j] : -1, j < n ? col->solid[j] : -1, j < n ? s->sxx[j] : 0.0,
                               j < n ? col->sxx[j] : 0.0, j < n ? s->szz[j] : 0.0, j < n ? col->szz[j] : 0.0,
                               s->sxz[j], col->sxz[j]);
                worst_stress = fmax(worst_stress, count ? ds / scale : 0.0);
                solid_max = count > solid_max ? count : solid_max;
                if (getenv("EKM_VERBOSE") && i == 0)
                    printf("step %d: %d solid cells, stress %.2e, flags differ %d\n", step, count,
                           count ? ds / scale : 0.0, flag_diff);
            }
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
    printf(
        "%s: %d steps to t = %.6g s: 2D columns against 1D: phi %.2e, vx %.2e, vz %.2e, T %.2e, gap %.2e "
        "(tolerance %.0e; the gap %.9g m from %.9g m); mass - initial - entered %.2e of the mass (tolerance "
        "%.0e)\n",
        name, steps, s->t, worst[0], worst[1], worst[2], worst[3], worst_gap, TOL, s->n * s->dz, gap0,
        worst_mass, MASS_TOL);
    if (solid) {
        printf("%s: solid regime: at most %d solid cells per column; regime flags differ in %d cell-steps; "
               "solid stresses %.2e of the largest |sigma_zz| (tolerance %.0e)\n",
               arg, solid_max, flag_diff, worst_stress, TOL);
        if (flag_diff)
            FAIL("%s: the regime flags differ in %d cell-steps\n", arg, flag_diff);
        if (!(worst_stress <= TOL))
            FAIL("%s: the solid stresses differ by %.3g > %.0e\n", arg, worst_stress, TOL);
        if (solid_max == 0)
            FAIL("%s: no cell was solid in %d steps: the case tests nothing of the solid regime\n", arg,
                 steps);
    }
    for (int k = 0; k < 4; k++)
        if (!(worst[k] <= TOL))
            FAIL("%s: field %d differs by %.3g > %.0e\n", name, k, worst[k], TOL);
    if (!(worst_gap <= TOL))
        FAIL("%s: the gap differs by %.3g of itself > %.0e\n", name, worst_gap, TOL);
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
