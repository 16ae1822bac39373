/* Solver runs against the closed forms of docs/model-notes.md section 7. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fields.h"
#include "testutil.h"

#define DEG (3.14159265358979323846 / 180.0)

/* ---- homogeneous cooling: T(t) = T_i / (1 + eps0 g sqrt(T_i) t / 2)^2 ---- */

typedef struct {
    double T_i, rate; /* eps0 g sqrt(T_i) / 2 */
    double max_err, T_last, T_first;
    int frames;
} cooling_ctx;

static ekm_status cooling_frame(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)err;
    cooling_ctx *c = ctx;
    const ekm_material *m = &st->sc->material;
    if (c->frames == 0) {
        c->T_i = s->T[0];
        c->T_first = s->T[0];
        c->rate = m->eps0 * ekm_g(m, s->phi[0]) * sqrt(c->T_i) / 2.0;
    }
    const double exact = c->T_i / pow(1.0 + c->rate * s->t, 2);
    for (int j = 0; j < s->n; j++)
        c->max_err = fmax(c->max_err, fabs(s->T[j] / exact - 1.0));
    c->T_last = s->T[0];
    c->frames++;
    return EKM_OK;
}

static void test_cooling(void **state)
{
    (void)state;
    cooling_ctx c = {0};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/cooling.ini", NULL, 0, cooling_frame, &c), EKM_OK);
    printf("cooling: %d frames, T %.4g -> %.4g, max relative error %.3g\n", c.frames, c.T_first, c.T_last,
           c.max_err);
    assert_true(c.T_last < 0.1 * c.T_first); /* a decade of cooling */
    assert_true(c.max_err < 1e-3);
    test_run_free(&r);
}

/* ---- steady Couette = homogeneous simple shear ---- */

/* scenario: the shear cell (the EKM) or a closure's; g_of: its density
 * factor written out here, independently of the law's code */
static void couette_run(const char *scenario, double (*g_of)(double phi), double phi, const char *t_end,
                        const char *cells)
{
    char set_phi[64], set_rate[64], set_T[64];
    const double L = 0.042, V = 0.42, gdot = V / L;
    snprintf(set_phi, sizeof set_phi, "initial.phi=%.17g", phi);
    snprintf(set_rate, sizeof set_rate, "initial.shear_rate=%.17g", gdot);
    /* start away from the answer: twice the expected T */
    test_run r;
    ekm_material m;
    {
        ekm_scenario tmp;
        ekm_error e;
        assert_int_equal(ekm_scenario_load(&tmp, test_path(scenario), NULL, 0, &e), EKM_OK);
        m = tmp.material;
        ekm_scenario_free(&tmp);
    }
    assert_true(m.nu == 1.0);
    const double T_exact = 2 * m.eta0 * gdot * gdot / (3 * phi * m.eps0);
    const double g = g_of(phi);
    const double P_exact =
        m.rho_p * g * (2 * m.eta0 * gdot * gdot / (3 * m.eps0) + m.T0 * fmax(phi - m.phi_co, 0.0));
    const double mu_exact = sqrt(3 * m.eta0 * m.eps0 / (2 * phi));
    snprintf(set_T, sizeof set_T, "initial.T=%.17g", 2 * T_exact);
    char set_t[64], set_n[64];
    snprintf(set_t, sizeof set_t, "run.t_end=%s", t_end);
    snprintf(set_n, sizeof set_n, "domain.cells=%s", cells);
    /* the fixed-gap cell: the wall stays put, the run goes to t_end */
    const char *sets[] = {
        set_phi, set_rate, set_T, set_t, set_n, "run.output_dt=0.1", "top.pressure=none", "run.stop=t_end"};
    assert_int_equal(test_run_scenario(&r, scenario, sets, 8, NULL, NULL), EKM_OK);
    const int n = r.s->n;
    double *buf = calloc((size_t)n * 5, sizeof(double));
    int *regime = calloc((size_t)n, sizeof(int));
    ekm_fields f = {buf, buf + n, buf + 2 * n, buf + 3 * n, buf + 4 * n, regime};
    ekm_fields_compute(&r.sc, r.s, r.s->t, &f);
    double eT = 0, eP = 0, emu = 0, ephi = 0;
    for (int j = 0; j < n; j++) {
        eT = fmax(eT, fabs(r.s->T[j] / T_exact - 1));
        eP = fmax(eP, fabs(f.P[j] / P_exact - 1));
        emu = fmax(emu, fabs(fabs(f.sxz[j]) / f.P[j] / mu_exact - 1));
        ephi = fmax(ephi, fabs(r.s->phi[j] / phi - 1));
    }
    printf("couette %s phi = %.2f: T %.6g (exact %.6g)  rel errors T %.2e  P %.2e  sxz/P %.2e  phi %.2e\n",
           scenario, phi, r.s->T[n / 2], T_exact, eT, eP, emu, ephi);
    assert_true(eT < 1e-3);
    assert_true(eP < 1e-3);
    assert_true(emu < 1e-3);
    assert_true(ephi < 1e-3);
    free(buf);
    free(regime);
    test_run_free(&r);
}

/* the EKM's g = 1/(1 - phi/phi_cp), phi_cp = 0.64 of shear_cell.ini */
static double g_ekm(double phi)
{
    return 1.0 / (1.0 - phi / 0.64);
}

static void couette_case(double phi, const char *t_end, const char *cells)
{
    couette_run("scenarios/shear_cell.ini", g_ekm, phi, t_end, cells);
}

static void test_couette_dilute(void **state)
{
    (void)state;
    couette_case(0.30, "10", "10");
}
static void test_couette_dense(void **state)
{
    (void)state;
    couette_case(0.62, "0.5", "10");
}

/* ekm_jam's g = (1 - phi/phi_J)^(-beta), phi_J = 0.6, beta = 2 of
 * shear_cell_jam.ini: the time stepper runs the closure, and its steady
 * Couette flow is the homogeneous shear of the closed form, below phi_co
 * = 0.55 and above it */
static double g_jam(double phi)
{
    return 1.0 / ((1.0 - phi / 0.6) * (1.0 - phi / 0.6));
}

static void test_couette_ekm_jam(void **state)
{
    (void)state;
    couette_run("tests/continuum/data/shear_cell_jam.ini", g_jam, 0.40, "10", "10");
    couette_run("tests/continuum/data/shear_cell_jam.ini", g_jam, 0.58, "2", "10");
}

/* ---- chute flow, lambda0 = 0, Bagnold profile ---- */

typedef struct {
    double e_phi, e_T, e_u; /* max relative errors in the bulk */
    double l2_T, l2_u;      /* relative L2 errors in the bulk */
} chute_err;

static void chute_case(const char *cells, const char *t_end, chute_err *out)
{
    char set_n[64], set_t[64];
    snprintf(set_n, sizeof set_n, "domain.cells=%s", cells);
    snprintf(set_t, sizeof set_t, "run.t_end=%s", t_end);
    const char *sets[] = {set_n, set_t, "run.output_dt=1"};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "tests/continuum/data/chute_bagnold.ini", sets, 3, NULL, NULL),
                     EKM_OK);
    const ekm_material *m = &r.sc.material;
    const double th = r.sc.angle_deg * DEG, G = r.sc.gravity;
    const double phi_eq = 3 * m->eta0 * m->eps0 / (2 * tan(th) * tan(th));
    assert_true(phi_eq < m->phi_co);
    const double h = ekm_state_mass(r.s, m->rho_p) / (m->rho_p * phi_eq);
    const double a = sqrt(3 * phi_eq * m->eps0 * G * cos(th) * (1 - phi_eq / m->phi_cp) / (2 * m->eta0));
    memset(out, 0, sizeof *out);
    double nT = 0, nu_ = 0;
    for (int j = 0; j < r.s->n; j++) {
        const double z = r.s->z[j];
        if (z < 0.2 * h || z > 0.6 * h)
            continue;
        const double T = G * cos(th) * (h - z) * (1 - phi_eq / m->phi_cp);
        const double u = 2.0 / 3.0 * a * (pow(h, 1.5) - pow(h - z, 1.5));
        out->e_phi = fmax(out->e_phi, fabs(r.s->phi[j] / phi_eq - 1));
        out->e_T = fmax(out->e_T, fabs(r.s->T[j] / T - 1));
        out->e_u = fmax(out->e_u, fabs(r.s->u[j] / u - 1));
        out->l2_T += pow(r.s->T[j] - T, 2);
        nT += T * T;
        out->l2_u += pow(r.s->u[j] - u, 2);
        nu_ += u * u;
    }
    out->l2_T = sqrt(out->l2_T / nT);
    out->l2_u = sqrt(out->l2_u / nu_);
    printf("chute %s cells: phi_eq %.4f h %.5f m; bulk max errors phi %.2e T %.2e u %.2e; L2 T %.2e u %.2e\n",
           cells, phi_eq, h, out->e_phi, out->e_T, out->e_u, out->l2_T, out->l2_u);
    test_run_free(&r);
}

static void test_chute_bagnold(void **state)
{
    (void)state;
    chute_err coarse, fine;
    chute_case("60", "14", &coarse);
    chute_case("120", "14", &fine);
    assert_true(fine.e_phi < 0.02);
    assert_true(fine.e_T < 0.02);
    assert_true(fine.e_u < 0.02);
    /* first-order scheme: the error halves when dz halves (ratio 2; accept > 1.6) */
    printf("chute convergence: L2(T) ratio %.2f, L2(u) ratio %.2f\n", coarse.l2_T / fine.l2_T,
           coarse.l2_u / fine.l2_u);
    assert_true(coarse.l2_T / fine.l2_T > 1.6);
    assert_true(coarse.l2_u / fine.l2_u > 1.6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cooling),       cmocka_unit_test(test_couette_dilute),
        cmocka_unit_test(test_couette_dense), cmocka_unit_test(test_couette_ekm_jam),
        cmocka_unit_test(test_chute_bagnold),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
