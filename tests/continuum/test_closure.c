/* The closure styles (law/closure.h): the table, the mu_i style's steady
 * shear against closed forms written out here (docs/model/closures.md),
 * the EKM styles equal to ekm_homog_shear bit for bit, and the scenario
 * reader's `[model] closure` with its [material] keys and refusals. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "closure.h"
#include "homogeneous.h"
#include "mu_i.h"
#include "resolve.h"
#include "scenario.h"

static void assert_rel(const char *what, double got, double want, double tol)
{
    const double r = fabs(got - want) / fabs(want);
    if (!(r < tol))
        fail_msg("%s: got %.17g, want %.17g (relative error %.3g > %.3g)", what, got, want, r, tol);
}

/* Names unique, parameter keys unique over the table and none an EKM
 * [material] key, every slot inside law_p. */
static void test_table(void **state)
{
    (void)state;
    size_t nparams = 0;
    ekm_scenario defaults;
    ekm_scenario_init_defaults(&defaults);
    for (size_t i = 0; i < ekm_closure_count(); i++) {
        const ekm_closure *c = ekm_closure_at(i);
        assert_non_null(c->check);
        assert_non_null(c->homog);
        assert_ptr_equal(ekm_closure_find(c->name, NULL), c);
        for (size_t j = 0; j < i; j++)
            assert_string_not_equal(ekm_closure_at(j)->name, c->name);
        for (size_t k = 0; k < c->nparams; k++) {
            const ekm_closure *owner;
            size_t kk;
            assert_int_equal(ekm_closure_param_find(c->params[k].key, &owner, &kk), 0);
            assert_ptr_equal(owner, c); /* the first with that key is this one: unique */
            assert_int_equal(kk, k);
            assert_int_equal(ekm_closure_slot(c, k), nparams + k);
            for (size_t s = 0; s < ekm_scenario_key_count(); s++) {
                const char *section, *key;
                ekm_scenario_key_name(s, &section, &key);
                if (strcmp(section, "material") == 0)
                    assert_string_not_equal(key, c->params[k].key);
            }
        }
        nparams += c->nparams;
    }
    assert_true(nparams <= EKM_LAW_PARAMS_MAX);
    ekm_scenario_free(&defaults);
    ekm_error err;
    assert_null(ekm_closure_find("mu_of_i", &err));
    assert_non_null(strstr(err.message,
                           "unknown closure 'mu_of_i': expected one of ekm_full, ekm_thesis, mu_i, ekm_jam"));
}

/* The EKM styles are ekm_homog_shear of their variant, to the bit. */
static void test_ekm_styles(void **state)
{
    (void)state;
    const ekm_material m = ekm_material_thesis();
    const ekm_closure *styles[] = {&ekm_closure_ekm_full, &ekm_closure_ekm_thesis};
    const ekm_variant variants[] = {EKM_VARIANT_FULL, EKM_VARIANT_THESIS};
    for (int v = 0; v < 2; v++) {
        assert_ptr_equal(ekm_closure_of_variant(variants[v]), styles[v]);
        for (double phi = 0.3; phi < 0.635; phi += 0.05) {
            ekm_homog_state a, b;
            ekm_error err;
            assert_int_equal(ekm_closure_homog(styles[v], &m, phi, 7.0, &a, &err), EKM_OK);
            assert_int_equal(ekm_homog_shear(&m, variants[v], phi, 7.0, &b, &err), EKM_OK);
            assert_memory_equal(&a, &b, sizeof a);
        }
    }
}

/* The material of a mu_i closure: glass beads (Jop et al. 2006: tan 20.9
 * deg, tan 32.76 deg, I_0 0.279), d = 2 mm, phi(I) = 0.6 - 0.2 I. */
static ekm_material mu_i_material(void)
{
    ekm_material m = ekm_material_thesis();
    m.rho_p = 2500.0;
    const ekm_closure *c = &ekm_closure_mu_i;
    const char *keys[] = {"mu_s", "mu_2", "I_0", "phi_max", "phi_min", "d"};
    const double values[] = {0.382, 0.643, 0.279, 0.6, 0.4, 0.002};
    for (size_t i = 0; i < 6; i++) {
        const ekm_closure *owner;
        size_t k;
        assert_int_equal(ekm_closure_param_find(keys[i], &owner, &k), 0);
        assert_ptr_equal(owner, c);
        *ekm_closure_param_ptr(c, k, &m) = values[i];
    }
    return m;
}

/* Volume control: phi = 0.58 gives I = (0.6 - 0.58)/0.2 = 0.1, at gdot =
 * 10 1/s P = 2500 (0.002 x 10 / 0.1)^2 = 100 Pa, mu = 0.382 + 0.261 x
 * 0.1/0.379, tau = mu P = 45.0865... Pa; T is n/a (NAN). Pressure
 * control gives the same point back: I from P and gdot, phi from I. */
static void test_mu_i_homog(void **state)
{
    (void)state;
    const ekm_material m = mu_i_material();
    const ekm_closure *c = &ekm_closure_mu_i;
    ekm_error err;
    assert_int_equal(ekm_closure_check(c, &m, &err), EKM_OK);
    ekm_homog_state h;
    assert_int_equal(ekm_closure_homog(c, &m, 0.58, 10.0, &h, &err), EKM_OK);
    const double mu = 0.382 + 0.261 * 0.1 / (0.279 + 0.1);
    assert_rel("P", h.P, 100.0, 1e-13);
    assert_rel("mu", h.mu, mu, 1e-14);
    assert_rel("sxz", h.sxz, 100.0 * mu, 1e-13);
    assert_rel("sxz by hand", h.sxz, 45.08654353562005, 1e-12);
    assert_true(isnan(h.T) && isnan(h.P_K) && isnan(h.P_Y) && isnan(h.r));
    const ekm_mu_i_params p = {.rho_p = 2500.0,
                               .mu_s = 0.382,
                               .mu_2 = 0.643,
                               .I_0 = 0.279,
                               .phi_max = 0.6,
                               .phi_min = 0.4,
                               .d = 0.002};
    const double I_back = 10.0 * p.d / sqrt(h.P / p.rho_p);
    assert_rel("I from P", I_back, 0.1, 1e-13);
    assert_rel("phi(I)", ekm_mu_i_phi_of_I(&p, I_back), 0.58, 1e-14);
    assert_rel("I(mu)", ekm_mu_i_inertial_number_of_friction(&p, h.mu), 0.1, 1e-12);
    /* the limits: mu(0) = mu_s, mu -> mu_2; no friction outside (mu_s, mu_2) */
    assert_true(ekm_mu_i_friction(&p, 0.0) == p.mu_s);
    assert_rel("mu(1e12)", ekm_mu_i_friction(&p, 1e12), p.mu_2, 1e-12);
    assert_true(isnan(ekm_mu_i_inertial_number_of_friction(&p, 0.3)));
    assert_true(isnan(ekm_mu_i_inertial_number_of_friction(&p, 0.643)));
    /* P scales as gdot^2 at a fixed phi (Bagnold) */
    ekm_homog_state h2;
    assert_int_equal(ekm_closure_homog(c, &m, 0.58, 30.0, &h2, &err), EKM_OK);
    assert_rel("Bagnold P", h2.P, 900.0, 1e-13);
    assert_rel("mu at fixed phi", h2.mu, h.mu, 1e-15);
    /* no steady shear at or above phi_max */
    assert_int_equal(ekm_closure_homog(c, &m, 0.6, 10.0, &h, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "phi_max = 0.6"));
    assert_int_equal(ekm_closure_homog(c, &m, 0.5, 0.0, &h, &err), EKM_EINPUT);
}

/* An EKM material with the ekm_jam keys phi_J and beta set. */
static ekm_material jam_material(double phi_J, double beta)
{
    ekm_material m = ekm_material_thesis();
    m.rho_p = 2500.0;
    m.phi_co = 0.55;
    const char *keys[] = {"phi_J", "beta"};
    const double values[] = {phi_J, beta};
    for (size_t i = 0; i < 2; i++) {
        const ekm_closure *owner;
        size_t k;
        assert_int_equal(ekm_closure_param_find(keys[i], &owner, &k), 0);
        assert_ptr_equal(owner, &ekm_closure_ekm_jam);
        *ekm_closure_param_ptr(owner, k, &m) = values[i];
    }
    return m;
}

/* ekm_jam: with beta = 1 and phi_J = phi_cp the EKM's state (to
 * round-off); with beta = 2 P and |sxz| carry one more factor g1 =
 * 1/(1 - phi/phi_J), T and mu are the EKM's, and below phi_co the inertial
 * number I = gdot d / sqrt(P / rho_p) = d sqrt(3 eps0 / (2 eta0)) (1 -
 * phi/phi_J) is linear in phi: the linear dilatancy law. */
static void test_ekm_jam(void **state)
{
    (void)state;
    const ekm_material one = jam_material(0.64, 1.0), two = jam_material(0.6, 2.0);
    ekm_error err;
    assert_int_equal(ekm_closure_check(&ekm_closure_ekm_jam, &two, &err), EKM_OK);
    for (double phi = 0.2; phi < 0.595; phi += 0.05) {
        ekm_homog_state a, b, c;
        assert_int_equal(ekm_closure_homog(&ekm_closure_ekm_jam, &one, phi, 8.0, &a, &err), EKM_OK);
        assert_int_equal(ekm_homog_shear(&one, EKM_VARIANT_FULL, phi, 8.0, &b, &err), EKM_OK);
        assert_rel("beta 1: P", a.P, b.P, 1e-14);
        assert_rel("beta 1: sxz", a.sxz, b.sxz, 1e-14);
        assert_true(a.T == b.T);
        ekm_material e = two;
        e.phi_cp = 0.6;
        e.g_beta = 1.0; /* the EKM at phi_cp = phi_J */
        assert_int_equal(ekm_closure_homog(&ekm_closure_ekm_jam, &two, phi, 8.0, &a, &err), EKM_OK);
        assert_int_equal(ekm_homog_shear(&e, EKM_VARIANT_FULL, phi, 8.0, &c, &err), EKM_OK);
        const double g1 = 1.0 / (1.0 - phi / 0.6);
        assert_rel("beta 2: P", a.P, c.P * g1, 1e-13);
        assert_rel("beta 2: sxz", a.sxz, c.sxz * g1, 1e-13);
        assert_rel("beta 2: mu", a.mu, c.mu, 1e-13);
        assert_true(a.T == c.T);
        if (phi < two.phi_co) {
            const double d = 0.002, I = 8.0 * d / sqrt(a.P / two.rho_p);
            assert_rel("linear dilatancy", I, d * sqrt(3.0 * two.eps0 / (2.0 * two.eta0)) * (1.0 - phi / 0.6),
                       1e-13);
        }
    }
    ekm_homog_state h;
    assert_int_equal(ekm_closure_homog(&ekm_closure_ekm_jam, &two, 0.6, 8.0, &h, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "phi_J = 0.6"));
    ekm_material bad = jam_material(0.6, 0.0);
    assert_int_equal(ekm_closure_check(&ekm_closure_ekm_jam, &bad, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "[material] beta: expected a positive number, got 0"));
    bad = jam_material(0.5, 2.0); /* below its phi_co = 0.55 */
    assert_int_equal(ekm_closure_check(&ekm_closure_ekm_jam, &bad, &err), EKM_EINPUT);
    assert_non_null(
        strstr(err.message, "[material] phi_co: expected a number in (0, phi_J = 0.5), got 0.55"));
}

/* Pressure control is the inverse of volume control: at the P of a state
 * found at phi, each closure finds that phi back (the EKM on both sides of
 * phi_co, both variants; mu_i), and refuses a P it cannot reach. */
static void test_at_pressure(void **state)
{
    (void)state;
    ekm_material m = ekm_material_thesis();
    m.rho_p = 2500.0;
    const ekm_material mu = mu_i_material(), jam = jam_material(0.62, 2.5);
    const struct {
        const ekm_closure *c;
        const ekm_material *m;
        double phi_lo, phi_hi;
    } cases[] = {{&ekm_closure_ekm_full, &m, 0.05, 0.635},
                 {&ekm_closure_ekm_thesis, &m, 0.3, 0.63},
                 {&ekm_closure_mu_i, &mu, 0.41, 0.599},
                 {&ekm_closure_ekm_jam, &jam, 0.05, 0.615}};
    for (size_t c = 0; c < 4; c++)
        for (double gdot = 0.5; gdot < 100.0; gdot *= 4.0)
            for (int i = 0; i <= 20; i++) {
                const double phi = cases[c].phi_lo + (cases[c].phi_hi - cases[c].phi_lo) * i / 20.0;
                ekm_homog_state a, b;
                ekm_error err;
                assert_int_equal(ekm_closure_homog(cases[c].c, cases[c].m, phi, gdot, &a, &err), EKM_OK);
                assert_int_equal(ekm_closure_homog_at_pressure(cases[c].c, cases[c].m, a.P, gdot, &b, &err),
                                 EKM_OK);
                if (!(fabs(b.phi - phi) < 1e-12 && fabs(b.P / a.P - 1.0) < 1e-12 &&
                      fabs(b.sxz / a.sxz - 1.0) < 1e-10))
                    fail_msg("%s, phi %.17g, gdot %g: back at phi %.17g, P %.17g (%.17g), sxz %.17g (%.17g)",
                             cases[c].c->name, phi, gdot, b.phi, b.P, a.P, b.sxz, a.sxz);
            }
    /* the EKM's dilute limit rho_p 2 eta0 gdot^2 / (3 eps0) */
    ekm_homog_state h;
    ekm_error err;
    const double limit = m.rho_p * 2.0 * m.eta0 * 100.0 / (3.0 * m.eps0);
    assert_int_equal(ekm_closure_homog_at_pressure(&ekm_closure_ekm_full, &m, 0.999 * limit, 10.0, &h, &err),
                     EKM_EINPUT);
    assert_non_null(strstr(err.message, "expected P above the dilute limit"));
    /* mu_i: a pressure so low that I > phi_max / (phi_max - phi_min) */
    assert_int_equal(ekm_closure_homog_at_pressure(&ekm_closure_mu_i, &mu, 1e-3, 10.0, &h, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "the dilatancy law has no volume fraction there"));
}

static void test_mu_i_ranges(void **state)
{
    (void)state;
    const ekm_closure *c = &ekm_closure_mu_i;
    const struct {
        const char *key;
        double value;
        const char *message;
    } bad[] = {
        {"mu_2", 0.3, "[material] mu_2: expected a number > mu_s = 0.382, got 0.3"},
        {"I_0", 0.0, "[material] I_0: expected a positive number, got 0"},
        {"phi_min", 0.7, "[material] phi_min: expected a number in (0, phi_max = 0.6), got 0.7"},
        {"phi_max", 1.2, "[material] phi_max: expected a number in (0, 1), got 1.2"},
        {"d", NAN, "[material] d: expected a positive number, got nan"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ekm_material m = mu_i_material();
        const ekm_closure *owner;
        size_t k;
        assert_int_equal(ekm_closure_param_find(bad[i].key, &owner, &k), 0);
        *ekm_closure_param_ptr(c, k, &m) = bad[i].value;
        ekm_error err;
        assert_int_equal(ekm_closure_check(c, &m, &err), EKM_EINPUT);
        if (!strstr(err.message, bad[i].message))
            fail_msg("%s: got '%s'", bad[i].key, err.message);
    }
}

static const char MU_I_INI[] = "[scenario]\nname = t\n"
                               "[material]\nrho_p = 2500\nmu_s = 0.382\nmu_2 = 0.643\nI_0 = 0.279\n"
                               "phi_max = 0.6\nphi_min = 0.4\nd = 0.002\n"
                               "[model]\nclosure = mu_i\n"
                               "[domain]\nlength = 0.02\ncells = 10\n[initial]\nphi = 0.5\n"
                               "[bottom]\ntype = wall\n[top]\ntype = wall\n[run]\nt_end = 1\n";

/* Reads MU_I_INI with the --set overrides; the status, and the message in err. */
static ekm_status load(const char *const *sets, size_t nsets, ekm_scenario *sc, ekm_error *err)
{
    ekm_scenario_text t = {.name = "mu_i.ini", .text = MU_I_INI, .size = strlen(MU_I_INI)};
    return ekm_scenario_load_texts(sc, &t, NULL, sets, nsets, err);
}

static void test_reader(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_error err;
    assert_int_equal(load(NULL, 0, &sc, &err), EKM_OK);
    assert_ptr_equal(sc.closure, &ekm_closure_mu_i);
    /* the resolved scenario lists the keys the closure reads, where they came from */
    ekm_resolved r;
    assert_int_equal(ekm_resolve(&sc, NULL, NULL, &r, &err), EKM_OK);
    const ekm_resolve_key *k = ekm_resolve_find(&r, "material.phi_min");
    assert_non_null(k);
    assert_string_equal(k->value, "0.4");
    assert_string_equal(k->from, "mu_i.ini:9");
    assert_non_null(ekm_resolve_find(&r, "material.rho_p"));
    assert_string_equal(ekm_resolve_find(&r, "model.closure")->value, "mu_i");
    assert_null(ekm_resolve_find(&r, "material.eta0"));
    assert_null(ekm_resolve_find(&r, "model.variant"));
    ekm_resolve_free(&r);
    ekm_homog_state a, b;
    const ekm_material m = mu_i_material();
    assert_int_equal(ekm_closure_homog(sc.closure, &sc.material, 0.58, 10.0, &a, &err), EKM_OK);
    assert_int_equal(ekm_closure_homog(&ekm_closure_mu_i, &m, 0.58, 10.0, &b, &err), EKM_OK);
    assert_true(a.P == b.P && a.sxz == b.sxz);
    ekm_scenario_free(&sc);
    const struct {
        const char *set;
        const char *message;
    } bad[] = {
        {"model.closure=ekm_full", "mu_i.ini:5: [material] mu_s: a parameter of closure mu_i, but [model] "
                                   "closure = ekm_full"},
        {"model.closure=mu",
         "[model] closure: unknown closure 'mu': expected one of ekm_full, ekm_thesis, mu_i, ekm_jam"},
        /* a --set of either spelling overrides the file's other one */
        {"model.variant=thesis", "mu_i.ini:5: [material] mu_s: a parameter of closure mu_i, but [model] "
                                 "closure = ekm_thesis"},
        {"material.eta0=1e-4",
         "--set material.eta0: [material] eta0: closure mu_i does not read it (its keys: "
         "rho_p, mu_s, mu_2, I_0, phi_max, phi_min, d)"},
        {"material.phi_min=0.65", "--set material.phi_min: [material] phi_min: expected a number in (0, "
                                  "phi_max = 0.6), got 0.65"},
        {"material.d=abc", "[material] d: expected a number, got 'abc'"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *sets[] = {bad[i].set};
        const ekm_status st = load(sets, 1, &sc, &err);
        ekm_scenario_free(&sc);
        if (st != EKM_EINPUT || !strstr(err.message, bad[i].message))
            fail_msg("--set %s: status %d, message '%s'", bad[i].set, (int)st, err.message);
    }
    /* both spellings in the file must agree */
    {
        char clash[sizeof MU_I_INI + 32];
        snprintf(clash, sizeof clash, "%s", MU_I_INI);
        char *model = strstr(clash, "closure = mu_i\n");
        memmove(model + 15, model, strlen(model) + 1);
        memcpy(model, "variant = full\n", 15);
        ekm_scenario_text ct = {.name = "mu_i.ini", .text = clash, .size = strlen(clash)};
        assert_int_equal(ekm_scenario_load_texts(&sc, &ct, NULL, NULL, 0, &err), EKM_EINPUT);
        ekm_scenario_free(&sc);
        assert_non_null(
            strstr(err.message, "mu_i.ini:12: [model] variant = full disagrees with [model] closure = mu_i"));
    }
    /* a missing key names the closure and the key's meaning */
    char text[sizeof MU_I_INI];
    snprintf(text, sizeof text, "%s", MU_I_INI);
    char *d = strstr(text, "d = 0.002\n");
    memset(d, ' ', strlen("d = 0.002"));
    ekm_scenario_text t = {.name = "mu_i.ini", .text = text, .size = strlen(text)};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, NULL, 0, &err), EKM_EINPUT);
    ekm_scenario_free(&sc);
    assert_non_null(
        strstr(err.message, "mu_i.ini: [material] d: missing (closure mu_i needs it: grain diameter [m])"));
}

/* An EKM scenario: no closure key means ekm_full, variant = thesis means
 * ekm_thesis; both keys given must agree; the stepper refuses mu_i. */
static void test_reader_ekm(void **state)
{
    (void)state;
    static const char ini[] = "[scenario]\nname = t\n[material]\nrho_p = 2500\nphi_co = 0.6\nphi_cp = 0.64\n"
                              "T0 = 1.5\neta0 = 3.55e-4\nzeta0 = 1e-4\nlambda0 = 3.4e-4\neps0 = 500\nnu = 1\n"
                              "A_h = 2e8\nB_h = 2e8\nalpha = 0\n"
                              "[domain]\nlength = 0.02\ncells = 10\n[initial]\nphi = 0.5\n"
                              "[bottom]\ntype = wall\n[top]\ntype = wall\n[run]\nt_end = 1\n";
    ekm_scenario_text t = {.name = "ekm.ini", .text = ini, .size = strlen(ini)};
    ekm_scenario sc;
    ekm_error err;
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, NULL, 0, &err), EKM_OK);
    assert_ptr_equal(sc.closure, &ekm_closure_ekm_full);
    ekm_scenario_free(&sc);
    const char *thesis[] = {"model.variant=thesis"};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, thesis, 1, &err), EKM_OK);
    assert_ptr_equal(sc.closure, &ekm_closure_ekm_thesis);
    assert_int_equal(sc.variant, EKM_VARIANT_THESIS);
    ekm_scenario_free(&sc);
    const char *both[] = {"model.variant=thesis", "model.closure=ekm_thesis"};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, both, 2, &err), EKM_OK);
    assert_ptr_equal(sc.closure, &ekm_closure_ekm_thesis);
    ekm_scenario_free(&sc);
    const char *closure_only[] = {"model.closure=ekm_thesis"};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, closure_only, 1, &err), EKM_OK);
    assert_int_equal(sc.variant, EKM_VARIANT_THESIS);
    ekm_scenario_free(&sc);
    const char *clash[] = {"model.variant=full", "model.closure=ekm_thesis"};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, clash, 2, &err), EKM_EINPUT);
    ekm_scenario_free(&sc);
    assert_non_null(
        strstr(err.message, "[model] variant = full disagrees with [model] closure = ekm_thesis"));
    /* mu_i's keys without its closure, and mu_i with the EKM's keys */
    const char *foreign[] = {"material.I_0=0.3"};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, foreign, 1, &err), EKM_EINPUT);
    ekm_scenario_free(&sc);
    assert_non_null(strstr(err.message,
                           "--set material.I_0: [material] I_0: a parameter of closure mu_i, but "
                           "[model] closure = ekm_full"));
    const char *to_mu_i[] = {"model.closure=mu_i"};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, to_mu_i, 1, &err), EKM_EINPUT);
    ekm_scenario_free(&sc);
    assert_non_null(strstr(err.message, "ekm.ini:5: [material] phi_co: closure mu_i does not read it"));
    /* every solver refuses a closure it cannot run, by name */
    assert_int_equal(ekm_closure_require_ekm(&ekm_closure_ekm_thesis, "ekm run", &err), EKM_OK);
    assert_int_equal(ekm_closure_require_ekm(&ekm_closure_mu_i, "ekm run", &err), EKM_EUNAVAILABLE);
    assert_non_null(
        strstr(err.message, "[model] closure = mu_i: ekm run solves the EKM's transport law only"));
    assert_int_equal(ekm_closure_require_ekm(&ekm_closure_ekm_jam, "ekm run", &err), EKM_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table),       cmocka_unit_test(test_ekm_styles),
        cmocka_unit_test(test_mu_i_homog),  cmocka_unit_test(test_mu_i_ranges),
        cmocka_unit_test(test_at_pressure), cmocka_unit_test(test_ekm_jam),
        cmocka_unit_test(test_reader),      cmocka_unit_test(test_reader_ekm),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
