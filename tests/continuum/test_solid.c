/* The solid (hypoplastic) regime inside the solver: filling ends at rest,
 * switches are continuous, the driven cycle, the tilting layer and the
 * thesis column (docs/model/solid.md, "Solid regime"). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "fields.h"
#include "hypo.h"
#include "testutil.h"

/* ---- continuity: every switch, measured from the states ----
 * A per-step hook compares each cell's regime flag with the previous
 * step's.  At a switch it evaluates the cell's normal and shear stress in
 * both regimes on the same state, with the definitions of the output
 * (fields.h, what ekm writes): the flow law at the cell's phi, T and
 * velocity gradients (face shear stresses with ekm_face_viscosity) and
 * the solid's stress state (its sigma_xz the mean of its
 * face stresses).  The solid -> flow jump is the flow stress after (T as
 * set by the switch) minus the solid stress before; flow -> solid the
 * solid stress after minus the flow stress before.  Nothing here uses the
 * stepper's own jump measure or its jump_tol gate. */
#define WATCH_MAX 256
typedef struct {
    unsigned char prev[WATCH_MAX];
    int have_prev;
    ekm_state *copy;
    double vx[WATCH_MAX], vz[WATCH_MAX], P[WATCH_MAX], sxz[WATCH_MAX], szz[WATCH_MAX];
    int regime[WATCH_MAX];
    const ekm_scenario *sc;
    long to_solid, to_flow, dense_switches;
    double jump_max, jump_max_t; /* largest relative jump and when */
    int jump_max_cell, jump_max_dir;
    int verbose;
} switch_watch;

static void cell_stress(switch_watch *w, const ekm_state *s, int j, int solid, double *zz, double *xz)
{
    ekm_state_copy(w->copy, s);
    w->copy->solid[j] = (unsigned char)solid;
    ekm_fields f = {w->vx, w->vz, w->P, w->sxz, w->szz, w->regime};
    ekm_fields_compute(w->sc, w->copy, s->t, &f);
    *zz = w->szz[j];
    *xz = w->sxz[j];
}

/* At t = 0 (the frame hook): the initial regimes. */
static ekm_status watch_start(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    switch_watch *w = ctx;
    if (s->n > WATCH_MAX)
        return EKM_FAIL(err, EKM_EINPUT, "switch_watch: %d cells, at most %d", s->n, WATCH_MAX);
    w->sc = st->sc;
    if (!w->copy && !(w->copy = ekm_state_alloc(s->n, st->sc->length)))
        return EKM_FAIL(err, EKM_ENOMEM, "switch_watch: out of memory");
    if (!w->have_prev) {
        memcpy(w->prev, s->solid, (size_t)s->n);
        w->have_prev = 1;
    }
    return EKM_OK;
}

static ekm_status watch_step(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)err;
    switch_watch *w = ctx;
    const ekm_material *m = &st->sc->material;
    if (w->have_prev) {
        for (int j = 0; j < s->n; j++) {
            if (s->solid[j] == w->prev[j] || s->phi[j] < st->sc->numerics.phi_dry)
                continue;
            const int to_solid = s->solid[j];
            double zz_solid, xz_solid, zz_flow, xz_flow;
            cell_stress(w, s, j, 1, &zz_solid, &xz_solid);
            cell_stress(w, s, j, 0, &zz_flow, &xz_flow);
            const double zz_before = to_solid ? zz_flow : zz_solid, xz_before = to_solid ? xz_flow : xz_solid;
            /* relative to the stress before, but at least the weight of the
             * cell itself (per area: the smallest stress the grid resolves;
             * near a free surface both stresses are of that size or less) */
            const double g = sqrt(st->g_x * st->g_x + st->g_z * st->g_z);
            const double scale =
                fmax(fmax(fabs(zz_before), fabs(xz_before)), m->rho_p * s->phi[j] * g * s->dz);
            const double jump = fmax(fabs(zz_solid - zz_flow), fabs(xz_solid - xz_flow)) / scale;
            if (to_solid)
                w->to_solid++;
            else
                w->to_flow++;
            if (s->phi[j] > m->phi_co + st->sc->hypo.phi_margin)
                w->dense_switches++;
            if (w->verbose)
                printf("    switch t %.9g cell %d %s phi %.6f: sigma_zz %.8g -> %.8g, sigma_xz %.8g -> %.8g "
                       "Pa, jump %.2e\n",
                       s->t, j, to_solid ? "flow->solid" : "solid->flow", s->phi[j], zz_before,
                       to_solid ? zz_solid : zz_flow, xz_before, to_solid ? xz_solid : xz_flow, jump);
            if (!(jump <= w->jump_max)) {
                w->jump_max = jump;
                w->jump_max_t = s->t;
                w->jump_max_cell = j;
                w->jump_max_dir = to_solid;
            }
        }
    }
    memcpy(w->prev, s->solid, (size_t)s->n);
    w->have_prev = 1;
    return EKM_OK;
}

static void watch_free(switch_watch *w)
{
    ekm_state_free(w->copy);
    w->copy = NULL;
}

static void no_carry_over(ekm_scenario *sc, void *ctx)
{
    (void)ctx;
    sc->hypo.carry_over = 0;
}

static void run_watched(const char *scenario, const char *const *sets, size_t n_sets, int carry_over,
                        switch_watch *w, test_run *r)
{
    memset(w, 0, sizeof *w);
    w->verbose = getenv("EKM_TEST_VERBOSE") != NULL;
    const ekm_run_hooks hooks = {.frame = watch_start, .step = watch_step, .ctx = w};
    assert_int_equal(
        test_run_scenario_hooks(r, scenario, sets, n_sets, &hooks, carry_over ? NULL : no_carry_over, NULL),
        EKM_OK);
    printf("%s%s%s%s: %ld switches flow -> solid, %ld solid -> flow (%ld of dense cells); largest jump %.2e "
           "(t = %.6g s, "
           "cell %d, %s)\n",
           scenario, n_sets ? " " : "", n_sets ? sets[0] : "", carry_over ? "" : " without carry-over",
           w->to_solid, w->to_flow, w->dense_switches, w->jump_max, w->jump_max_t, w->jump_max_cell,
           w->jump_max_dir ? "flow -> solid" : "solid -> flow");
    assert_true(w->have_prev);
}

/* Every switch of the shipped scenarios (filling also run on to rest, 3 s)
 * jumps by < 3e-3; with the carry-over disabled (hypo.carry_over = 0: the
 * solid starts at -P_Y, T stays frozen, no jump_tol gate) the same check
 * finds jumps of order 1 and above: it can fail.  The largest jump of
 * thesis_column_incline is chaotic in its start-up (an independent measure,
 * not the stepper's jump_tol = 5e-4 gate): 4.7e-4 at initial T = 1e-10,
 * 1.59e-3 at 1e-10 x (1 + 1e-4), before the temperature restart
 * (docs/model/slab.md "Temperature step"); 1.02e-3 with it. */
static void test_switches_continuous(void **state)
{
    (void)state;
    const char *scen[] = {"scenarios/filling.ini", "scenarios/filling.ini",
                          "scenarios/thesis_column_incline.ini", "scenarios/tilting_layer.ini",
                          "scenarios/hypoplastic_cycle.ini"};
    const char *rest[] = {"run.t_end=3"};
    const long min_dense[] = {19, 20, 40, 1, 0}; /* switches of dense cells, at least */
    for (int k = 0; k < 5; k++) {
        switch_watch w;
        test_run r;
        run_watched(scen[k], rest, k == 1, 1, &w, &r);
        assert_true(w.dense_switches >= min_dense[k]);
        assert_true(w.jump_max < 3e-3);
        watch_free(&w);
        test_run_free(&r);
    }
    for (int k = 0; k < 4; k++) {
        if (k == 1)
            continue;
        switch_watch w;
        test_run r;
        run_watched(scen[k], NULL, 0, 0, &w, &r);
        assert_true(w.jump_max > 1e-2);
        watch_free(&w);
        test_run_free(&r);
    }
}

/* Filling: the inflow stops at 0.5 s; the shipped scenario, run to t = 3 s
 * (the bed is at rest from 2.5 s; [run] t_end = 1 s is also the DEM's run
 * time, see docs/model/solid.md "Known limitations"), ends with every cell of the
 * bed (from the floor up to the first cell with phi < 0.01) solid, |w| <
 * 1e-9 m/s on every face of the bed, and the bottom normal stress carrying
 * the bed's weight to 1e-6.  The dilute tail of the stream (phi < 1e-4,
 * empty cells by the scenario's phi_dry) stays where it was when its cells
 * became empty: reported, and bounded. */
static void test_filling_ends_at_rest(void **state)
{
    (void)state;
    const char *sets[] = {"run.t_end=3"};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/filling.ini", sets, 1, NULL, NULL), EKM_OK);
    const ekm_state *s = r.s;
    const ekm_material *m = &r.sc.material;
    int top = 0; /* cells 0..top-1 form the bed */
    while (top < s->n && s->phi[top] >= 0.01)
        top++;
    double w_max = 0.0, weight = 0.0, gas = 0.0, w_gas = 0.0;
    int solid = 0, dense = 0;
    for (int f = 0; f <= top; f++)
        w_max = fmax(w_max, fabs(s->w[f]));
    for (int f = top + 1; f <= s->n; f++)
        w_gas = fmax(w_gas, fabs(s->w[f]));
    for (int j = 0; j < s->n; j++) {
        const double wj = m->rho_p * s->phi[j] * r.sc.gravity * s->dz;
        if (j < top) {
            weight += wj;
            solid += s->solid[j];
            dense += s->phi[j] > m->phi_co;
        } else {
            gas += wj;
        }
    }
    /* the empty cell on the surface: its lower half rests on the bed (the
     * momentum control volume of the surface face) */
    if (top < s->n)
        weight += 0.5 * m->rho_p * s->phi[top] * r.sc.gravity * s->dz;
    /* bottom normal stress: cell 0's stress extrapolated to the floor */
    const double bottom = -s->szz[0] + m->rho_p * s->phi[0] * r.sc.gravity * s->dz / 2;
    printf("filling: bed of %d cells (%d with phi > phi_co, surface cell phi %.4f), %d solid; max |w| in the "
           "bed "
           "%.2e m/s; bed weight %.10g Pa, bottom stress %.10g Pa (rel %.2e); remnant above: %.2e of the "
           "weight, "
           "max |w| %.2e m/s; switches %ld/%ld, jump max %.2e\n",
           top, dense, s->phi[top - 1], solid, w_max, weight, bottom, bottom / weight - 1, gas / weight,
           w_gas, r.stats.to_solid, r.stats.to_flow, r.stats.jump_max);
    if (solid != top || w_max >= 1e-9)
        for (int j = 0; j <= top && j < s->n; j++)
            printf("  %3d phi %.6f solid %d T %.3e w %.3e szz %.6g\n", j, s->phi[j], s->solid[j], s->T[j],
                   s->w[j], s->szz[j]);
    assert_true(dense > 10);
    assert_int_equal(solid, top);
    assert_true(w_max < 1e-9);
    assert_true(fabs(bottom / weight - 1.0) < 1e-6);
    assert_true(gas / weight < 5e-4); /* measured 2.3e-4 */
    assert_true(r.stats.jump_max < 1e-3);
    test_run_free(&r);
}

/* ---- hypoplastic_cycle: the driven homogeneous sample (thesis 6.2.2) ---- */

#define CYCLE_MAX 2048
typedef struct {
    int n;
    double t[CYCLE_MAX], szz[CYCLE_MAX], PY[CYCLE_MAX], R[CYCLE_MAX], strain[CYCLE_MAX];
    int solid_frames;
} cycle_ctx;

/* Per frame: the stress, the law's P_Y and R (at the law's phi: [hypo]
 * phi_fixed when set) and ln(phi). */
static ekm_status cycle_frame(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)err;
    cycle_ctx *c = ctx;
    const ekm_material *m = &st->sc->material;
    if (c->n >= CYCLE_MAX)
        return EKM_OK;
    const double phi_law = ekm_scenario_law_phi(st->sc, s->phi[0]);
    c->t[c->n] = s->t;
    c->szz[c->n] = s->szz[0];
    c->PY[c->n] = ekm_pressure_yield(m, phi_law);
    c->R[c->n] = ekm_hypo_R(m, st->sc->variant, phi_law);
    c->strain[c->n] = log(s->phi[0]); /* volumetric strain up to a constant: -ln(phi) grows in extension */
    c->solid_frames += s->solid[0];
    c->n++;
    return EKM_OK;
}

/* The driven sample as an ODE (GSL rk8pd, tight tolerances), independent
 * of the stepper: y = (sigma, ln phi), w' = w_piston(t)/L, the thesis law
 * d(sigma)/dt = f A_h (w' - (sigma + P_Y)/(R P_Y) |w'|) with P_Y, R and f
 * at the current phi (docs/model-notes.md section 4) or at phi_fixed, d(ln phi)/dt = -w'. */
typedef struct {
    const ekm_material *m;
    double dw, phi_fixed;
} cycle_ode;

static double thesis_R(const ekm_material *m, double phi)
{
    return sqrt(3.0 * m->eps0 * m->zeta0 / (2.0 * phi));
}

static double limit_stress(const ekm_material *m, double phi)
{
    return -ekm_pressure_yield(m, phi) * (1.0 + thesis_R(m, phi));
}

static int cycle_rhs(double t, const double y[], double dydt[], void *p)
{
    (void)t;
    const cycle_ode *o = p;
    const ekm_material *m = o->m;
    const double phi = o->phi_fixed > 0.0 ? o->phi_fixed : exp(y[1]);
    const double PY = ekm_pressure_yield(m, phi);
    const double f = m->alpha == 0.0 ? 1.0 : pow((phi - m->phi_co) / (m->phi_cp - phi), m->alpha);
    dydt[0] = f * m->A_h * (o->dw - (y[0] + PY) / (thesis_R(m, phi) * PY) * fabs(o->dw));
    dydt[1] = -o->dw;
    return GSL_SUCCESS;
}

/* Runs the cycle scenario with the overrides and checks the end of every
 * compression half period (4 of them) and the whole run; returns the
 * largest relative error against the plain limit stress -P_Y (1 + R). */
static double check_cycle(const char *const *sets, size_t n_sets, int compacting)
{
    cycle_ctx *c = calloc(1, sizeof *c);
    assert_non_null(c);
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/hypoplastic_cycle.ini", sets, n_sets, cycle_frame, c),
                     EKM_OK);
    const ekm_material *m = &r.sc.material;
    assert_int_equal(r.sc.variant, EKM_VARIANT_THESIS);
    assert_int_equal(r.sc.cells, 1);
    assert_true(compacting ? r.sc.hypo.phi_fixed == 0.0 : r.sc.hypo.phi_fixed == r.sc.phi_init);
    assert_int_equal(c->solid_frames, c->n);
    assert_int_equal(r.stats.to_flow + r.stats.to_solid, 0);
    const double half = 0.5 * r.sc.top.period;
    /* the reference ODE from the same start */
    gsl_set_error_handler_off();
    cycle_ode o = {.m = m, .phi_fixed = r.sc.hypo.phi_fixed};
    gsl_odeiv2_system sys = {cycle_rhs, NULL, 2, &o};
    double y[2] = {c->szz[0], log(r.sc.phi_init)}, t_ode = 0.0;
    const double PY0 = ekm_pressure_yield(m, r.sc.phi_init);
    int checked = 0;
    double err_max = 0.0;
    for (int i = 2; i < c->n - 1; i++) {
        /* frame i ends a compression half period (t = (2k+1) half) */
        const double k = c->t[i] / half;
        if (fabs(k - floor(k + 0.5)) > 1e-9 || ((long)floor(k + 0.5)) % 2 != 1)
            continue;
        /* advance the ODE to t_i, half period by half period */
        while (t_ode < c->t[i] - 1e-9) {
            const long h = lround(floor(t_ode / half + 1e-9));
            o.dw = (h % 2 == 0                 ? r.sc.top.w
                    : isnan(r.sc.top.w_return) ? -r.sc.top.w
                                               : r.sc.top.w_return) /
                   r.sc.length;
            gsl_odeiv2_driver *d =
                gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-6, 1e-13 * PY0, 1e-13);
            assert_non_null(d);
            const double t1 = (h + 1) * half;
            assert_int_equal(gsl_odeiv2_driver_apply(d, &t_ode, t1, y), GSL_SUCCESS);
            gsl_odeiv2_driver_free(d);
        }
        const double phi = compacting ? exp(c->strain[i]) : r.sc.hypo.phi_fixed; /* the law's phi */
        const double limit = -c->PY[i] * (1.0 + c->R[i]);
        assert_true(fabs(limit / limit_stress(m, phi) - 1.0) < 1e-14);
        const double err = fabs(c->szz[i] / limit - 1.0);
        const double err_ode = fabs(c->szz[i] / y[0] - 1.0);
        const double phi_ode = exp(y[1]), phi_cell = exp(c->strain[i]);
        /* the lag: ds = d(s*)/d(ln phi) (central difference; 0 at a fixed
         * phi), k = f A_h/(R P_Y) */
        const double hphi = 1e-6 * phi;
        const double ds =
            compacting ? phi * (limit_stress(m, phi + hphi) - limit_stress(m, phi - hphi)) / (2.0 * hphi)
                       : 0.0;
        const double kk = m->A_h / (thesis_R(m, phi) * c->PY[i]) *
                          (m->alpha == 0.0 ? 1.0 : pow((phi - m->phi_co) / (m->phi_cp - phi), m->alpha));
        const double lagged = limit - ds / kk;
        const double err_lag = fabs(c->szz[i] / lagged - 1.0);
        /* stiffness d(sigma)/d(strain), strain rate = -d ln(phi)/dt: loading
         * over the last frame before the reversal, unloading over the first after */
        const double k_load = (c->szz[i] - c->szz[i - 1]) / -(c->strain[i] - c->strain[i - 1]);
        const double k_unload = (c->szz[i + 1] - c->szz[i]) / -(c->strain[i + 1] - c->strain[i]);
        printf(
            "cycle (%s): t = %.3f s: sigma_zz = %.10g Pa; exact law (ODE) %.10g Pa, rel %.2e (phi %.2e rel); "
            "-P_Y(1+R) = %.10g Pa, rel %.2e; with the compaction lag %.10g Pa, rel %.2e (lag %.2e); "
            "stiffness loading %.4g Pa, unloading %.4g Pa\n",
            compacting ? "compacting" : "phi_fixed", c->t[i], c->szz[i], y[0], err_ode,
            fabs(phi_cell / phi_ode - 1.0), limit, err, lagged, err_lag, -ds / kk / limit, k_load, k_unload);
        assert_true(err_ode < 1e-6);
        assert_true(err_lag < 1e-6);
        assert_true(err < 1e-3);
        assert_true(k_unload > 10.0 * k_load);
        assert_true(k_unload > 1.5 * m->A_h); /* A_h (1 - q/R) -> 2 A_h at q = -R */
        err_max = fmax(err_max, err);
        checked++;
    }
    assert_int_equal(checked, 4);
    /* inside the limit surface all the time (f_Y < 0 on the unloading side too) */
    double fy_max = -INFINITY;
    for (int i = 0; i < c->n; i++) {
        const double q = (c->szz[i] + c->PY[i]) / (c->R[i] * c->PY[i]);
        fy_max = fmax(fy_max, q * q - 1.0);
    }
    printf("cycle (%s): largest f_Y of any frame %.2e\n", compacting ? "compacting" : "phi_fixed", fy_max);
    assert_true(fy_max < 0.0);
    test_run_free(&r);
    free(c);
    return err_max;
}

/* Compression saturates at the limit stress -P_Y (1 + R): the scenario
 * drives each compression half period through 20 relaxation strains
 * R P_Y/A_h, so the start is forgotten to e^-20.
 *  - The shipped scenario is thesis 6.2.2's element test: the law's
 *    constants at a fixed phi ([hypo] phi_fixed = the initial phi; the
 *    thesis: "the materials constant are assumed to be independent of the
 *    density").  Saturation: -P_Y (1 + R) to < 1e-6 at the end of every
 *    compression half, and the stress equals the exact law (ODE) to < 1e-6.
 *  - With the constants at the current phi (hypo.phi_fixed = 0) the sample
 *    compacts while compressed and P_Y (1 + R) grows with phi (d ln P_Y /
 *    d ln phi ~ 65 at phi = 0.62): the saturated stress trails the limit of
 *    the current phi by the law's own lag x = -(d(s*)/d(eps)) / k (s* =
 *    -P_Y(1+R), eps = ln phi, k = f A_h/(R P_Y)), 1.7e-4 of it, for any
 *    rate and any integrator: the stress equals the exact law to < 1e-6
 *    and the lag-corrected limit to < 1e-6, the plain one to < 1e-3.
 * In both, the unloading stiffness exceeds the loading one at the same
 * stress, and the sample stays inside the limit surface (and solid). */
static void test_hypoplastic_cycle(void **state)
{
    (void)state;
    const double err_fixed = check_cycle(NULL, 0, 0);
    assert_true(err_fixed < 1e-6);
    const char *compacting[] = {"hypo.phi_fixed=0"};
    const double err_compacting = check_cycle(compacting, 1, 1);
    printf("cycle: saturation vs -P_Y(1+R): %.2e at fixed phi, %.2e compacting (the law's lag)\n", err_fixed,
           err_compacting);
    assert_true(err_compacting > 1e-5); /* the lag is there, and the check would see it */
}

/* ---- thesis_column_incline (thesis 6.5.3) ----
 * The column leaves its solid state (every cell flows at some output
 * time), flows out through the outflow (all of it by t = 0.6 s), and the
 * outflow equals the mass lost to round-off. */

typedef struct {
    double w_max;
    int solid_first, solid_min;
    int ever_flow[64]; /* cell j was not solid in some frame */
} column_ctx;

static ekm_status column_frame(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)st;
    (void)err;
    column_ctx *c = ctx;
    int solid = 0;
    for (int j = 0; j < s->n; j++) {
        solid += s->solid[j];
        if (j < 64 && !s->solid[j])
            c->ever_flow[j] = 1;
    }
    for (int f = 0; f <= s->n; f++)
        c->w_max = fmax(c->w_max, fabs(s->w[f]));
    if (s->t == 0.0)
        c->solid_first = c->solid_min = solid;
    c->solid_min = solid < c->solid_min ? solid : c->solid_min;
    return EKM_OK;
}

static void test_column_incline(void **state)
{
    (void)state;
    column_ctx c = {0};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/thesis_column_incline.ini", NULL, 0, column_frame, &c),
                     EKM_OK);
    const double m0 = r.stats.mass_initial, m1 = r.stats.mass_final, out = -r.stats.mass_in;
    const double balance = (m0 - m1 - out) / m0;
    printf("column: %d solid cells at t = 0, fewest solid in a frame %d; max |w| %.3g m/s; mass %.6g -> %.6g "
           "kg/m^2, out through the outflow %.6g kg/m^2 (%.1f%%), balance %.1e; switches %ld -> flow, %ld -> "
           "solid, "
           "jump max %.2e\n",
           c.solid_first, c.solid_min, c.w_max, m0, m1, out, 100 * out / m0, balance, r.stats.to_flow,
           r.stats.to_solid, r.stats.jump_max);
    int left = 0, remain = 0;
    for (int j = 0; j < 40; j++)
        left += c.ever_flow[j];
    for (int j = 0; j < r.s->n; j++)
        remain += r.s->solid[j];
    printf(
        "column: %d of the 40 initially solid cells flowed at some output time; %d cells solid at the end\n",
        left, remain);
    assert_true(c.solid_first == 40);
    assert_int_equal(left, 40); /* every cell left the solid state */
    assert_true(c.solid_min == 0);
    assert_true(c.w_max > 0.5);         /* it flows */
    assert_true(out > 0.99 * m0);       /* it leaves (measured 99.998%) */
    assert_true(fabs(balance) < 1e-13); /* outflow = mass lost, to round-off */
    assert_true(r.stats.jump_max < 1e-3);
    test_run_free(&r);
}

/* ---- tilting_layer ----
 * The settled layer starts at rest and solid.  While the base angle grows
 * (0.01 deg/s) it stays solid, and its velocity is the rate law's
 * quasi-static response to the growing load: an elastic solid (stiffness
 * B_h = 200 MPa) would move by ~1.5e-13 m/s at the surface of the 5 mm
 * layer; the hypoplastic law's tangent stiffness is lower and falls to
 * zero at the limit surface, so the law's response grows from 6e-13 m/s
 * at 18 deg to a few 1e-10 m/s just before failure (it scales with the
 * tilt rate and the square of the thickness: the 2 cm layer tilted at 0.5
 * deg/s of earlier versions reached 6.5e-8 m/s).  The test computes that
 * response independently from the stress state of every frame
 * (tilt_response: the law of docs/model-notes.md section 4 solved for the strain rates that
 * give the stress rates of the growing load) and asserts
 *  - velocities below 1e-9 m/s in every step while the whole layer is
 *    solid, up to the failure (a step hook), the law's response below
 *    1e-9 m/s in every such frame, and exactly at rest before the tilting
 *    starts;
 *  - the velocity equals the law's response to 1 % while the layer is
 *    inside the limit surface (f_Y < -0.01 in every cell), and never
 *    exceeds it by more than 1 % (near the surface the solid lags behind
 *    the diverging quasi-static response);
 *  - it fails (first solid -> flow switch) at an angle where the failing
 *    cell's recorded stress satisfies f_Y = 0 to 1e-3 (f_Y recomputed here
 *    from that stress), after the tilting started; the failure is in the
 *    run statistics, the output's hypo.fail_* attributes (test_output.c)
 *    and the regime field; after it the layer flows. */
typedef struct {
    int frames, all_solid_frames, verbose, compared, below_1e9;
    double v_solid_max, v_rest_max, t_all_solid, v_end;
    double dev_inside_max; /* largest |v/v_law - 1| with f_Y < -0.01 */
    double ratio_max;      /* largest v/v_law while solid and loaded */
    double v_1e9_max;      /* largest v where v_law < 1e-9 */
    double angle_1e9;      /* largest angle where v_law < 1e-9 */
    double v_el;           /* elastic estimate at the start of the tilting */
    long solid_steps;      /* steps with every material cell solid, before the failure */
    double v_step_max;     /* largest |u|, |w| of the material over those steps */
} tilt_ctx;

/* Largest |u| (cells) and |w| (faces) of the material; *solid, *wet:
 * solid and material cells. */
static double layer_velocity(const ekm_state *s, const ekm_stepper *st, int *solid, int *wet)
{
    double v = 0.0;
    *solid = *wet = 0;
    for (int j = 0; j < s->n; j++) {
        if (s->phi[j] < st->sc->numerics.phi_dry)
            continue;
        (*wet)++;
        *solid += s->solid[j];
        v = fmax(v, fabs(s->u[j]));
    }
    for (int f = 0; f <= s->n; f++)
        v = fmax(v, fabs(s->w[f]));
    return v;
}

/* Every step while the whole layer is solid, up to the failure. */
static ekm_status tilt_step(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)err;
    tilt_ctx *c = ctx;
    int solid, wet;
    const double v = layer_velocity(s, st, &solid, &wet);
    if (solid == wet && st->regime.fail_time < 0.0) {
        c->solid_steps++;
        c->v_step_max = fmax(c->v_step_max, v);
    }
    return EKM_OK;
}

/* docs/model-notes.md section 4 (full variant) limit function of a cell's stress. */
static double tilt_fY(const ekm_material *m, double phi, const ekm_hypo_stress *sg)
{
    const double PY = ekm_pressure_yield(m, phi);
    const double tr = sg->xx + sg->yy + sg->zz;
    const double dx = sg->xx - tr / 3, dy = sg->yy - tr / 3, dz = sg->zz - tr / 3;
    const double s2 = dx * dx + dy * dy + dz * dz + 2 * sg->xz * sg->xz;
    return (pow(tr + 3 * PY, 2) + 9 * m->zeta0 / (2 * m->eta0) * s2) /
               (27 * m->zeta0 * m->eps0 / (2 * phi) * PY * PY) -
           1;
}

/* The full rate law's quasi-static response of the layer to the growing
 * tilt at the state s: per cell the stress rates the load asks for,
 * d(sigma_xz)/dt = rho_p G cos(theta) theta' M and d(sigma_zz)/dt =
 * rho_p G sin(theta) theta' M (M: phi integrated from the cell centre to
 * the surface), and the strain rates u', w' that give them:
 *   f (B u' - c1 K) = d(sigma_xz)/dt,  f ((A + 2B) w' - c2 K) = d(sigma_zz)/dt,
 *   c1 = 2 B a2 sigma_xz/P_Y,  c2 = (3A + 2B) a1 (tr + 3 P_Y)/P_Y + 2 B a2 (sigma_zz - tr/3)/P_Y,
 *   K = sqrt(u'^2/2 + (2/3 + zeta0/(2 eta0)) w'^2)  (a quadratic in K).
 * Returns the largest |u| at cell centres (no slip at the base) and |w| at
 * faces; *elastic: the same with the elastic part only (c1 = c2 = 0). */
static double tilt_response(const ekm_state *s, const ekm_stepper *st, double *elastic)
{
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const double deg = 3.14159265358979323846 / 180;
    const double th = ekm_scenario_angle_at(sc, s->t) * deg;
    const double thdot = s->t > sc->angle_start ? sc->angle_rate * deg : 0.0;
    const double A = m->A_h, B = m->B_h, c3 = 2.0 / 3.0 + m->zeta0 / (2 * m->eta0);
    double M = 0.0, u = 0.0, w = 0.0, v = 0.0, u_el = 0.0, v_el = 0.0;
    double du_prev = 0.0, du_el_prev = 0.0;
    double Mc[256];
    for (int j = s->n - 1; j >= 0; j--) {
        Mc[j] = M + 0.5 * s->phi[j] * s->dz;
        M += s->phi[j] * s->dz;
    }
    for (int j = 0; j < s->n && s->phi[j] >= sc->numerics.phi_dry; j++) {
        const double phi = s->phi[j], PY = ekm_pressure_yield(m, phi);
        const double f = m->alpha == 0.0 ? 1.0 : pow((phi - m->phi_co) / (m->phi_cp - phi), m->alpha);
        const double a1 = 2.0 / (9.0 * m->zeta0) * sqrt(phi * m->eta0 / (3.0 * m->eps0));
        const double a2 = sqrt(phi / (3.0 * m->eta0 * m->eps0));
        const double sxz = 0.5 * (s->sxz[j] + s->sxz[j + 1]), tr = s->sxx[j] + s->syy[j] + s->szz[j];
        const double c1 = 2 * B * a2 * sxz / PY;
        const double c2 = (3 * A + 2 * B) * a1 * (tr + 3 * PY) / PY + 2 * B * a2 / PY * (s->szz[j] - tr / 3);
        const double rx = m->rho_p * sc->gravity * cos(th) * thdot * Mc[j] / f;
        const double rz = m->rho_p * sc->gravity * sin(th) * thdot * Mc[j] / f;
        const double al = 1 / (2 * B * B), be = c3 / ((A + 2 * B) * (A + 2 * B));
        const double qa = 1 - al * c1 * c1 - be * c2 * c2, qb = -2 * (al * c1 * rx + be * c2 * rz);
        const double qc = -(al * rx * rx + be * rz * rz);
        const double K = qa > 0.0 ? (-qb + sqrt(qb * qb - 4 * qa * qc)) / (2 * qa) : INFINITY;
        const double du = (rx + c1 * K) / B, dw = (rz + c2 * K) / (A + 2 * B), du_el = rx / B;
        u += j == 0 ? 0.5 * du * s->dz : 0.5 * (du_prev + du) * s->dz;
        u_el += j == 0 ? 0.5 * du_el * s->dz : 0.5 * (du_el_prev + du_el) * s->dz;
        w += dw * s->dz;
        v = fmax(v, fmax(fabs(u), fabs(w)));
        v_el = fmax(v_el, fabs(u_el));
        du_prev = du;
        du_el_prev = du_el;
    }
    *elastic = v_el;
    return v;
}

static ekm_status tilt_frame(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)err;
    tilt_ctx *c = ctx;
    const ekm_material *m = &st->sc->material;
    int solid, wet;
    const double v = layer_velocity(s, st, &solid, &wet);
    double fy_max = -INFINITY;
    for (int j = 0; j < s->n; j++) {
        if (s->phi[j] < st->sc->numerics.phi_dry)
            continue;
        const ekm_hypo_stress sg = {s->sxx[j], s->syy[j], s->szz[j], 0.5 * (s->sxz[j] + s->sxz[j + 1])};
        fy_max = fmax(fy_max, tilt_fY(m, s->phi[j], &sg));
    }
    const double angle = ekm_scenario_angle_at(st->sc, s->t);
    if (solid == wet && st->regime.fail_time < 0.0) {
        if (!c->all_solid_frames)
            c->t_all_solid = s->t;
        c->all_solid_frames++;
        c->v_solid_max = fmax(c->v_solid_max, v);
        double v_el;
        const double v_law = tilt_response(s, st, &v_el);
        if (s->t <= st->sc->angle_start) {
            c->v_rest_max = fmax(c->v_rest_max, v);
        } else {
            if (c->v_el == 0.0)
                c->v_el = v_el;
            c->compared++;
            c->ratio_max = fmax(c->ratio_max, v / v_law);
            if (fy_max < -0.01)
                c->dev_inside_max = fmax(c->dev_inside_max, fabs(v / v_law - 1.0));
            if (v_law < 1e-9) {
                c->below_1e9++;
                c->v_1e9_max = fmax(c->v_1e9_max, v);
                c->angle_1e9 = fmax(c->angle_1e9, angle);
            }
        }
        if (c->verbose)
            printf("  t %.2f angle %.3f all solid: max|v| %.4e m/s, law %.4e m/s (ratio %.5f), elastic %.3e "
                   "m/s, "
                   "max f_Y %.3e\n",
                   s->t, angle, v, v_law, v / v_law, v_el, fy_max);
    } else if (c->verbose) {
        printf("  t %.2f angle %.3f solid %d/%d max|v| %.3e\n", s->t, angle, solid, wet, v);
    }
    c->v_end = v;
    c->frames++;
    return EKM_OK;
}

static void test_tilting_layer(void **state)
{
    (void)state;
    tilt_ctx c = {.verbose = getenv("EKM_TEST_VERBOSE") != NULL};
    test_run r;
    const ekm_run_hooks hooks = {.frame = tilt_frame, .step = tilt_step, .ctx = &c};
    assert_int_equal(test_run_scenario_hooks(&r, "scenarios/tilting_layer.ini", NULL, 0, &hooks, NULL, NULL),
                     EKM_OK);
    const ekm_material *m = &r.sc.material;
    const double fy = r.stats.fail_cell >= 0 ? tilt_fY(m, r.stats.fail_phi, &r.stats.fail_stress) : NAN;
    printf(
        "tilting: all solid in %d frames from t = %.2f s; at rest before the tilting: max |v| %.1e m/s; "
        "elastic (B_h) estimate at the start %.2e m/s; the law's response < 1e-9 m/s in %d frames (up to "
        "%.2f "
        "deg), max |v| there %.3e m/s; |v/v_law - 1| <= %.2e inside (f_Y < -0.01), v/v_law <= %.4f in all %d "
        "loaded solid frames; max |v| while solid %.2e m/s in frames, %.3e m/s in all %ld steps up to the "
        "failure\n",
        c.all_solid_frames, c.t_all_solid, c.v_rest_max, c.v_el, c.below_1e9, c.angle_1e9, c.v_1e9_max,
        c.dev_inside_max, c.ratio_max, c.compared, c.v_solid_max, c.v_step_max, c.solid_steps);
    printf("tilting: failure at t = %.4f s, angle %.4f deg, cell %d: f_Y = %.3e (recomputed from its stress "
           "%.3e; stepper %.3e); max |v| at the end %.3g m/s; switches %ld/%ld, jump max %.2e\n",
           r.stats.fail_time, r.stats.fail_angle, r.stats.fail_cell, fy, fy, r.stats.fail_fY, c.v_end,
           r.stats.to_solid, r.stats.to_flow, r.stats.jump_max);
    assert_true(c.all_solid_frames >= 20);
    assert_true(c.t_all_solid == 0.0);
    assert_true(c.v_rest_max < 1e-15);
    assert_true(c.below_1e9 >= 20);
    assert_true(c.v_1e9_max < 1e-9);
    assert_int_equal(c.below_1e9, c.compared); /* the law's response < 1e-9 m/s up to the failure */
    assert_true(c.solid_steps > 1000);
    assert_true(c.v_step_max < 1e-9); /* in every step while solid, up to the failure */
    assert_true(c.dev_inside_max < 1e-2);
    assert_true(c.ratio_max < 1.01);
    assert_true(r.stats.fail_time > r.sc.angle_start);
    assert_true(r.stats.fail_cell >= 0);
    assert_true(fabs(fy) < 1e-3);
    assert_true(fabs(fy - r.stats.fail_fY) < 1e-12);
    assert_true(c.v_end > 1e-3);
    assert_true(r.stats.jump_max < 1e-3);
    test_run_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_switches_continuous), cmocka_unit_test(test_filling_ends_at_rest),
        cmocka_unit_test(test_hypoplastic_cycle),   cmocka_unit_test(test_column_incline),
        cmocka_unit_test(test_tilting_layer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
