/* homog_cli.c: `ekm homog FILE.ini [--material FIT.ini] [--set S.K=V ...]
 * --phi LO:HI:N --rate R[,R,...] --json` (homog_cli.h, docs/model/law.md
 * "ekm homog").  The values are ekm_homog_shear's, printed with 17
 * significant digits (they read back exactly). */
#include "homog_cli.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "closure.h"
#include "homogeneous.h"
#include "json_out.h"
#include "scenario.h"

#define HOMOG_MAX_PHI    100000  /* points of --phi LO:HI:N */
#define HOMOG_MAX_RATES  1000    /* values of --rate */
#define HOMOG_MAX_POINTS 1000000 /* phi x rate points of one call */

typedef struct {
    double phi_lo, phi_hi; /* --phi LO:HI [-] */
    long n_phi;            /* --phi N, >= 1 */
    double *rates;         /* --rate values [1/s] */
    size_t n_rates;
} homog_grid;

static int homog_usage_error(const char *what)
{
    fprintf(stderr, "ekm homog: %s (see ekm --help)\n", what);
    return ekm_status_exit_code(EKM_EUSAGE);
}

/* A whole-string finite number: 0 and *out, else -1. */
static int homog_number(const char *text, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* --phi LO:HI:N: 0 < LO <= HI < 1, N >= 1 (N = 1: LO only, LO = HI). */
static ekm_status homog_parse_phi(const char *arg, homog_grid *g, ekm_error *err)
{
    char buf[256];
    if (strlen(arg) >= sizeof buf)
        return EKM_FAIL(err, EKM_EINPUT, "--phi: value too long");
    snprintf(buf, sizeof buf, "%s", arg);
    char *c1 = strchr(buf, ':');
    char *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c1 || !c2 || strchr(c2 + 1, ':'))
        return EKM_FAIL(err, EKM_EINPUT, "--phi '%s': expected LO:HI:N", arg);
    *c1 = *c2 = '\0';
    double n = 0.0;
    if (homog_number(buf, &g->phi_lo) || homog_number(c1 + 1, &g->phi_hi) || homog_number(c2 + 1, &n))
        return EKM_FAIL(err, EKM_EINPUT, "--phi '%s': expected LO:HI:N with numbers LO, HI and an integer N",
                        arg);
    if (!(n >= 1.0 && n <= HOMOG_MAX_PHI && n == floor(n)))
        return EKM_FAIL(err, EKM_EINPUT, "--phi '%s': N = %g: expected an integer from 1 to %d", arg, n,
                        HOMOG_MAX_PHI);
    g->n_phi = (long)n;
    if (!(g->phi_lo > 0.0 && g->phi_hi < 1.0 && g->phi_lo <= g->phi_hi))
        return EKM_FAIL(err, EKM_EINPUT, "--phi '%s': expected volume fractions 0 < LO <= HI < 1", arg);
    if (g->n_phi == 1 && g->phi_lo != g->phi_hi)
        return EKM_FAIL(err, EKM_EINPUT, "--phi '%s': N = 1 needs LO = HI", arg);
    return EKM_OK;
}

/* --rate R[,R,...]: finite rates > 0 [1/s]. */
static ekm_status homog_parse_rates(const char *arg, homog_grid *g, ekm_error *err)
{
    size_t n = 1;
    for (const char *p = arg; *p; p++)
        n += *p == ',';
    if (n > HOMOG_MAX_RATES)
        return EKM_FAIL(err, EKM_EINPUT, "--rate: %zu values, at most %d", n, HOMOG_MAX_RATES);
    g->rates = calloc(n, sizeof *g->rates);
    char *copy = strdup(arg);
    if (!g->rates || !copy) {
        free(copy);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (--rate)");
    }
    ekm_status st = EKM_OK;
    char *item = copy;
    for (size_t i = 0; i < n && st == EKM_OK; i++) {
        char *comma = strchr(item, ',');
        if (comma)
            *comma = '\0';
        double v = 0.0;
        if (homog_number(item, &v) || !(v > 0.0))
            st = EKM_FAIL(err, EKM_EINPUT, "--rate '%s': '%s': expected a shear rate > 0 [1/s]", arg, item);
        g->rates[i] = v;
        item = comma ? comma + 1 : item;
    }
    free(copy);
    g->n_rates = n;
    return st;
}

static json_t *homog_material_json(const ekm_closure *c, const ekm_material *m)
{
    if (!c->is_ekm) {
        /* the keys the closure reads: the EKM's it names and its own */
        json_t *o = json_object();
        for (const char *const *k = c->ekm_keys; o && *k; k++) {
            const double *v = ekm_material_key(m, *k);
            if (v)
                json_object_set_new(o, *k, json_real(*v));
        }
        for (size_t k = 0; o && k < c->nparams; k++)
            json_object_set_new(o, c->params[k].key, json_real(ekm_closure_param_value(c, k, m)));
        return o;
    }
    return json_pack("{s:f, s:f, s:f, s:f, s:f, s:f, s:f, s:f, s:f, s:f, s:f, s:f}", "rho_p", m->rho_p,
                     "phi_co", m->phi_co, "phi_cp", m->phi_cp, "T0", m->T0, "eta0", m->eta0, "zeta0",
                     m->zeta0, "lambda0", m->lambda0, "eps0", m->eps0, "nu", m->nu, "A_h", m->A_h, "B_h",
                     m->B_h, "alpha", m->alpha);
}

/* One point: its state, or a status saying there is none and why
 * (phi >= phi_cp, where ekm_homog_shear refuses phi: g(phi) diverges; or
 * no positive root of the temperature balance): the library's message.
 * The rates are checked before, so no other failure names the input. */
static json_t *homog_point_json(const ekm_scenario *sc, double phi, double rate)
{
    ekm_homog_state h;
    ekm_error why = {0};
    const ekm_status st = ekm_closure_homog(sc->closure, &sc->material, phi, rate, &h, &why);
    if (st != EKM_OK)
        return json_pack("{s:f, s:f, s:s, s:s}", "phi", phi, "rate", rate, "status", "no_steady_state",
                         "reason", why.message);
    /* a closure without a temperature: T, P_K and P_Y are null (n/a) */
    return json_pack("{s:f, s:f, s:s, s:o, s:f, s:o, s:o, s:f, s:f}", "phi", phi, "rate", rate, "status",
                     "ok", "T", ekm_json_number(h.T), "P", h.P, "P_K", ekm_json_number(h.P_K), "P_Y",
                     ekm_json_number(h.P_Y), "abs_sxz", h.sxz, "mu", h.mu);
}

static ekm_status homog_write(const char *ini, const char *material, const ekm_scenario *sc,
                              const homog_grid *g, ekm_error *err)
{
    json_t *points = json_array();
    json_t *root =
        json_pack("{s:s, s:s?, s:s, s:s?, s:o, s:{s:s, s:s, s:s, s:s, s:s, s:s, s:s, s:s}}", "scenario", ini,
                  "material_file", material, "closure", sc->closure->name, "variant",
                  !sc->closure->is_ekm                ? NULL
                  : sc->variant == EKM_VARIANT_THESIS ? "thesis"
                                                      : "full",
                  "material", homog_material_json(sc->closure, &sc->material), "units", "phi", "1", "rate",
                  "1/s", "T", "m^2/s^2", "P", "Pa", "P_K", "Pa", "P_Y", "Pa", "abs_sxz", "Pa", "mu", "1");
    ekm_status st = EKM_OK;
    if (!points || !root || json_object_set(root, "points", points) != 0)
        st = EKM_FAIL(err, EKM_ENOMEM, "out of memory (the JSON output)");
    for (long i = 0; i < g->n_phi && st == EKM_OK; i++) {
        const double phi = g->n_phi == 1
                               ? g->phi_lo
                               : g->phi_lo + (g->phi_hi - g->phi_lo) * (double)i / (double)(g->n_phi - 1);
        for (size_t j = 0; j < g->n_rates && st == EKM_OK; j++) {
            json_t *pt = homog_point_json(sc, phi, g->rates[j]);
            if (!pt || json_array_append_new(points, pt) != 0)
                st = EKM_FAIL(err, EKM_ENOMEM, "out of memory (the JSON output)");
        }
    }
    char *text = NULL;
    if (st == EKM_OK) {
        text = json_dumps(root, JSON_INDENT(1) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
        if (!text)
            st = EKM_FAIL(err, EKM_ENOMEM, "out of memory (the JSON output)");
    }
    if (st == EKM_OK && (fputs(text, stdout) == EOF || fputc('\n', stdout) == EOF || fflush(stdout) != 0))
        st = EKM_FAIL(err, EKM_EIO, "stdout: cannot write (%s)", strerror(errno));
    free(text);
    json_decref(points);
    json_decref(root);
    return st;
}

int ekm_homog_cli_main(int argc, char **argv)
{
    const char *ini = NULL, *material = NULL, *phi_arg = NULL, *rate_arg = NULL;
    int json = 0;
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    size_t n_sets = 0;
    if (!sets) {
        fprintf(stderr, "ekm: out of memory\n");
        return ekm_status_exit_code(EKM_ENOMEM);
    }
    for (int i = 0; i < argc; i++) {
        const int has_value = i + 1 < argc;
        if (strcmp(argv[i], "--material") == 0 && has_value)
            material = argv[++i];
        else if (strcmp(argv[i], "--set") == 0 && has_value)
            sets[n_sets++] = argv[++i];
        else if (strcmp(argv[i], "--phi") == 0 && has_value)
            phi_arg = argv[++i];
        else if (strcmp(argv[i], "--rate") == 0 && has_value)
            rate_arg = argv[++i];
        else if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (argv[i][0] == '-' || ini) {
            const int known = strcmp(argv[i], "--material") == 0 || strcmp(argv[i], "--set") == 0 ||
                              strcmp(argv[i], "--phi") == 0 || strcmp(argv[i], "--rate") == 0;
            char what[600];
            snprintf(what, sizeof what, known ? "%.500s: missing its value" : "unexpected argument '%.500s'",
                     argv[i]);
            free(sets);
            return homog_usage_error(what);
        } else
            ini = argv[i];
    }
    const char *missing = !ini        ? "missing scenario file"
                          : !phi_arg  ? "missing --phi LO:HI:N"
                          : !rate_arg ? "missing --rate R[,R,...]"
                          : !json     ? "missing --json (the output format)"
                                      : NULL;
    if (missing) {
        free(sets);
        return homog_usage_error(missing);
    }
    ekm_error err = {0};
    homog_grid grid = {0};
    ekm_status st = homog_parse_phi(phi_arg, &grid, &err);
    if (st == EKM_OK)
        st = homog_parse_rates(rate_arg, &grid, &err);
    if (st == EKM_OK && (double)grid.n_phi * (double)grid.n_rates > HOMOG_MAX_POINTS)
        st = EKM_FAIL(&err, EKM_EINPUT, "--phi N = %ld times %zu rates: at most %d points", grid.n_phi,
                      grid.n_rates, HOMOG_MAX_POINTS);
    ekm_scenario sc;
    int loaded = 0;
    if (st == EKM_OK) {
        st = ekm_scenario_load_material(&sc, ini, material, sets, n_sets, &err);
        loaded = 1;
    }
    free(sets);
    if (st == EKM_OK)
        st = homog_write(ini, material, &sc, &grid, &err);
    if (loaded)
        ekm_scenario_free(&sc);
    free(grid.rates);
    if (st != EKM_OK) {
        ekm_error_print("ekm", &err);
        return ekm_status_exit_code(st);
    }
    return 0;
}
