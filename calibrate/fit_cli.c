/* fit_cli.c: the command line of `ekmcompare fit` (fit_cli.h): options,
 * the start material (libekm's scenario reader), the data (--rheology:
 * fit_data.c; --scenario: fit_scen.c), the fit (fit.c), the outputs
 * (fit_out.c). */
#include "fit_cli.h"

#include "atomic.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fit.h"
#include "fit_data.h"
#include "fit_out.h"
#include "fit_scen.h"
#include "h5kind.h"
#include "scenario.h"
#include "status.h"

static const char fit_usage[] =
    "usage: ekmcompare fit --rheology CG.h5 [CG.h5 ...] --params T0,phi_co,eta0,eps0,nu[,...]\n"
    "                      [--control pressure CG.h5 ...] [--start FILE.ini [--material M.ini]] [--closure "
    "NAME]\n"
    "                      [--fields P,sxz,T]\n"
    "                      [--starts N] -o FIT.json [--ini FIT.ini] [--quiet]\n"
    "       ekmcompare fit --scenario CASES.json --params eta0,eps0[,...] [--fields phi,vx,T,P,sxz]\n"
    "                      [--start FILE.ini] [--starts N] [--support FRAC] [--progress] -o FIT.json\n"
    "                      [--ini FIT.ini] [--quiet]\n";

typedef struct {
    int rheology;
    const char *scenario; /* --scenario CASES.json */
    const char *support;  /* --support FRAC */
    int progress;
    const char **inputs;
    int *at_pressure; /* per input: 1 after --control pressure */
    size_t ninputs;
    const char *params, *start, *fields, *json, *ini;
    const char *closure;  /* --closure NAME: the start file's [model] closure replaced */
    const char *material; /* --material M.ini: the start file's [material] replaced */
    int nstarts;
    int quiet;
} fit_args;

static int usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "ekmcompare fit: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (see ekmcompare fit --help)\n");
    return ekm_status_exit_code(EKM_EUSAGE);
}

static int parse_args(int argc, char **argv, fit_args *a)
{
    int at_pressure = 0;
    for (int i = 0; i < argc; i++) {
        const char *s = argv[i];
        if (s[0] != '-') {
            a->at_pressure[a->ninputs] = at_pressure;
            a->inputs[a->ninputs++] = s;
            continue;
        }
        if (!strcmp(s, "--control")) {
            if (i + 1 >= argc)
                return usage("%s", "--control: missing its value (volume or pressure)");
            const char *v = argv[++i];
            if (strcmp(v, "volume") && strcmp(v, "pressure"))
                return usage(
                    "--control %s: expected volume or pressure (the control of the CG files after it)", v);
            at_pressure = !strcmp(v, "pressure");
            continue;
        }
        if (!strcmp(s, "--rheology")) {
            a->rheology = 1;
            continue;
        }
        if (!strcmp(s, "--quiet")) {
            a->quiet = 1;
            continue;
        }
        if (!strcmp(s, "--progress")) {
            a->progress = 1;
            continue;
        }
        const char **dst = !strcmp(s, "--scenario")   ? &a->scenario
                           : !strcmp(s, "--support")  ? &a->support
                           : !strcmp(s, "--params")   ? &a->params
                           : !strcmp(s, "--start")    ? &a->start
                           : !strcmp(s, "--closure")  ? &a->closure
                           : !strcmp(s, "--material") ? &a->material
                           : !strcmp(s, "--fields")   ? &a->fields
                           : !strcmp(s, "-o")         ? &a->json
                           : !strcmp(s, "--ini")      ? &a->ini
                                                      : NULL;
        if (!dst && strcmp(s, "--starts"))
            return usage("unknown option '%s'", s);
        if (i + 1 >= argc)
            return usage("%s: expected a value", s);
        const char *v = argv[++i];
        if (dst) {
            *dst = v;
            continue;
        }
        char *end;
        const long n = strtol(v, &end, 10);
        if (end == v || *end || n < 1 || n > 1000)
            return usage("--starts: expected an integer in [1, 1000], got '%s'", v);
        a->nstarts = (int)n;
    }
    if (a->rheology && a->scenario)
        return usage("%s", "expected --rheology CG.h5 ... or --scenario CASES.json, not both");
    if (!a->rheology && !a->scenario)
        return usage("%s", "expected --rheology CG.h5 ... or --scenario CASES.json");
    if (a->rheology && !a->ninputs)
        return usage("%s", "--rheology: expected at least one CG file");
    if (a->scenario && a->ninputs)
        return usage("unexpected argument '%s' (--scenario takes one CASES.json)", a->inputs[0]);
    if (!a->params)
        return usage("%s", "expected --params (e.g. T0,phi_co,eta0,eps0,nu)");
    if (a->closure && !a->rheology)
        return usage("%s", "--closure: for --rheology (a --scenario fit takes each case's closure)");
    if (a->material && !(a->rheology && a->start))
        return usage("%s", "--material M.ini: for --rheology with --start FILE.ini (it replaces the start "
                           "file's [material])");
    if (!a->json)
        return usage("%s", "expected -o FIT.json");
    return 0;
}

/* Split a comma list into the parameter indices of pb. */
static ekm_status parse_params(const char *list, cg_fit_problem *pb, ekm_error *err)
{
    const char *p = list;
    pb->nparams = 0;
    for (;;) {
        const char *q = strchr(p, ',');
        const size_t len = q ? (size_t)(q - p) : strlen(p);
        char name[32];
        if (len == 0 || len >= sizeof name)
            return EKM_FAIL(err, EKM_EINPUT, "--params: expected comma-separated [material] keys, got '%s'",
                            list);
        memcpy(name, p, len);
        name[len] = '\0';
        const int idx = cg_fit_param_lookup(name);
        if (idx < 0) {
            char known[256] = "";
            for (int i = 0; i < cg_fit_param_count(); i++)
                snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", i ? ", " : "",
                         cg_fit_param_name(i));
            return EKM_FAIL(err, EKM_EINPUT,
                            "--params: unknown parameter '%s': expected [material] keys (%s)", name, known);
        }
        if (pb->nparams == CG_FIT_MAXP)
            return EKM_FAIL(err, EKM_EINPUT, "--params: at most %d parameters, got '%s'", CG_FIT_MAXP, list);
        pb->param[pb->nparams++] = idx;
        if (!q)
            return EKM_OK;
        p = q + 1;
    }
}

/* A comma-separated list of distinct names among name(0..n-1) as a bit mask;
 * `known` lists them for the message. */
static ekm_status parse_name_mask(const char *list, const char *(*name)(int), int n, const char *known,
                                  unsigned *mask, ekm_error *err)
{
    const char *p = list;
    *mask = 0;
    for (;;) {
        const char *q = strchr(p, ',');
        const size_t len = q ? (size_t)(q - p) : strlen(p);
        int found = -1;
        for (int f = 0; f < n; f++)
            if (strlen(name(f)) == len && !strncmp(p, name(f), len))
                found = f;
        if (found < 0 || (*mask & (1u << found)))
            return EKM_FAIL(err, EKM_EINPUT, "--fields: expected distinct names among %s, got '%s'", known,
                            list);
        *mask |= 1u << found;
        if (!q)
            return EKM_OK;
        p = q + 1;
    }
}

static ekm_status parse_fields(const char *list, unsigned *mask, ekm_error *err)
{
    return parse_name_mask(list, cg_fit_field_name, CG_FIT_NFIELD, "P, sxz, T, mu", mask, err);
}

/* The output must not be one of the inputs (the CG files or --start). */
static ekm_status check_not_input(const char *out, const fit_args *a, ekm_error *err)
{
    if (!out)
        return EKM_OK;
    ekm_status st = ekm_atomic_refuse_input(out, a->inputs, a->ninputs, err);
    if (st == EKM_OK && a->start)
        st = ekm_atomic_refuse_input(out, &a->start, 1, err);
    return st;
}

/* -o and --ini must be two files (the second would replace the first). */
static ekm_status check_outputs_apart(const fit_args *a, ekm_error *err)
{
    if (!a->json || !a->ini)
        return EKM_OK;
    const char *json = a->json;
    if (ekm_atomic_refuse_input(a->ini, &json, 1, err) != EKM_OK)
        return EKM_FAIL(err, EKM_EIO, "--ini %s: the same file as -o %s: expected two outputs", a->ini,
                        a->json);
    return EKM_OK;
}

static void print_summary(const cg_fit_problem *pb, const cg_fit_result *res)
{
    printf("ekmcompare fit --rheology: %zu points, %zu residuals, %zu fitted, chi2/dof = %.4g (dof %ld), "
           "%d/%d starts converged\n",
           pb->npts, res->nres, res->nfree, res->chi2_dof, res->dof, res->starts_converged, res->starts_run);
    printf("| parameter | start | value | SE | identifiable |\n|---|---:|---:|---:|---|\n");
    for (size_t j = 0; j < res->nparams; j++)
        printf("| %s | %.6g | %.6g | %.3g | %s |\n", cg_fit_param_name(res->param[j]), res->start[j],
               res->value[j], res->se[j], res->identifiable[j] ? "yes" : res->why_not[j]);
}

static ekm_status run_fit(const fit_args *a, ekm_error *err)
{
    cg_fit_problem pb = {.nstarts = a->nstarts, .seed = 20261201ul};
    ekm_status st = parse_params(a->params, &pb, err);
    if (st == EKM_OK)
        st = parse_fields(a->fields ? a->fields : "P,sxz,T", &pb.fields, err);
    if (st != EKM_OK)
        return st;
    char source[600];
    if (a->start) {
        /* --closure NAME: the start file read as with --set model.closure=NAME */
        char set[128];
        snprintf(set, sizeof set, "model.closure=%s", a->closure ? a->closure : "");
        const char *sets[] = {set};
        ekm_scenario sc;
        st = ekm_scenario_load_material(&sc, a->start, a->material, a->closure ? sets : NULL,
                                        a->closure ? 1 : 0, err);
        pb.start = sc.material;
        pb.variant = sc.variant;
        pb.closure = sc.closure;
        ekm_scenario_free(&sc);
        if (st != EKM_OK)
            return st;
        if (a->material)
            snprintf(source, sizeof source, "%s with [material] of %s", a->start, a->material);
        else
            snprintf(source, sizeof source, "%s", a->start);
    } else {
        pb.start = ekm_material_thesis();
        pb.variant = EKM_VARIANT_FULL;
        pb.closure = ekm_closure_of_variant(pb.variant);
        if (a->closure) {
            ekm_error cerr;
            pb.closure = ekm_closure_find(a->closure, &cerr);
            if (!pb.closure)
                return EKM_FAIL(err, EKM_EINPUT, "--closure: %s", cerr.message);
            if (!pb.closure->is_ekm)
                return EKM_FAIL(
                    err, EKM_EINPUT,
                    "--closure %s: its parameters have no defaults: give --start FILE.ini with its "
                    "[material] keys",
                    a->closure);
            pb.variant = pb.closure->variant;
        }
        snprintf(source, sizeof source, "thesis material (ekm_material_thesis)");
    }
    st = check_not_input(a->json, a, err);
    if (st == EKM_OK)
        st = check_not_input(a->ini, a, err);
    if (st == EKM_OK)
        st = check_outputs_apart(a, err);
    if (st != EKM_OK)
        return st;
    cg_fit_point *pts = calloc(a->ninputs, sizeof *pts);
    if (!pts)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    for (size_t k = 0; k < a->ninputs && st == EKM_OK; k++) {
        st = cg_h5kind_check_path(a->inputs[k], "fit", "--rheology", CG_H5KIND_CG, err);
        if (st == EKM_OK)
            st = cg_fit_point_read(a->inputs[k], pb.fields, &pts[k], err);
        pts[k].at_pressure = a->at_pressure[k];
    }
    pb.pts = pts;
    pb.npts = a->ninputs;
    cg_fit_result res;
    memset(&res, 0, sizeof res);
    if (st == EKM_OK)
        st = cg_fit_run(&pb, &res, err);
    if (st == EKM_OK) {
        const cg_fit_outputs o = {.pb = &pb,
                                  .nstarts = pb.nstarts,
                                  .variant = pb.variant,
                                  .closure = pb.closure,
                                  .res = &res,
                                  .start_source = source,
                                  .json_path = a->json,
                                  .ini_path = a->ini};
        st = cg_fit_write(&o, err);
    }
    if (st == EKM_OK && !a->quiet)
        print_summary(&pb, &res);
    cg_fit_result_free(&res);
    free(pts);
    return st;
}

static ekm_status parse_scen_fields(const char *list, unsigned *mask, ekm_error *err)
{
    return parse_name_mask(list, cg_fitsc_field_name, CG_FITSC_NFIELD, "phi, vx, T, P, sxz", mask, err);
}

static void print_scen_summary(const cg_fitsc_problem *sc, const cg_fit_result *res)
{
    printf(
        "ekmcompare fit --scenario: %zu cases, %zu candidate points, %zu fitted, chi2/dof = %.4g (dof %ld), "
        "%d/%d starts converged, %ld evaluations, EKM %.1f s\n",
        sc->ncases, sc->nres, res->nfree, res->chi2_dof, res->dof, res->starts_converged, res->starts_run,
        sc->evaluations, sc->ekm_wall_s);
    printf("| parameter | start | value | SE | identifiable |\n|---|---:|---:|---:|---|\n");
    for (size_t j = 0; j < res->nparams; j++)
        printf("| %s | %.6g | %.6g | %.3g | %s |\n", cg_fit_param_name(res->param[j]), res->start[j],
               res->value[j], res->se[j], res->identifiable[j] ? "yes" : res->why_not[j]);
}

static ekm_status run_scenario_fit(const fit_args *a, ekm_error *err)
{
    cg_fitsc_problem sc;
    memset(&sc, 0, sizeof sc);
    cg_fit_problem pp = {0}; /* --params parsed into its list */
    ekm_status st = parse_params(a->params, &pp, err);
    if (st == EKM_OK)
        st = parse_scen_fields(a->fields ? a->fields : "phi,vx,T,P,sxz", &sc.fields, err);
    sc.support = CG_FITSC_SUPPORT;
    if (st == EKM_OK && a->support) {
        char *end;
        sc.support = strtod(a->support, &end);
        if (end == a->support || *end || !(sc.support > 0.0 && sc.support < 1.0))
            st = EKM_FAIL(err, EKM_EUSAGE,
                          "--support: expected a fraction in (0, 1) of the largest DEM phi, got '%s'",
                          a->support);
    }
    if (st != EKM_OK)
        return st;
    sc.nparams = pp.nparams;
    memcpy(sc.param, pp.param, sizeof sc.param);
    const char *ins[2] = {a->scenario, a->start};
    const size_t nins = a->start ? 2 : 1;
    if (a->json)
        st = ekm_atomic_refuse_input(a->json, ins, nins, err);
    if (st == EKM_OK && a->ini)
        st = ekm_atomic_refuse_input(a->ini, ins, nins, err);
    if (st == EKM_OK)
        st = check_outputs_apart(a, err);
    if (st == EKM_OK)
        st = cg_fitsc_load(&sc, a->scenario, err);
    /* every case's files are inputs too: its DEM file and its scenario */
    for (size_t i = 0; i < sc.ncases && st == EKM_OK; i++) {
        const char *case_inputs[3] = {sc.cases[i].dem, sc.cases[i].scenario, sc.cases[i].material};
        const size_t n_in = sc.cases[i].material ? 3 : 2;
        if (a->json)
            st = ekm_atomic_refuse_input(a->json, case_inputs, n_in, err);
        if (st == EKM_OK && a->ini)
            st = ekm_atomic_refuse_input(a->ini, case_inputs, n_in, err);
    }
    ekm_material start;
    ekm_variant variant = EKM_VARIANT_FULL;
    const ekm_closure *closure = ekm_closure_of_variant(variant);
    char source[600];
    if (st == EKM_OK)
        st = cg_fitsc_start_material(&sc, &start, &variant, &closure, err);
    if (st == EKM_OK && a->start) {
        ekm_scenario ss;
        st = ekm_scenario_load(&ss, a->start, NULL, 0, err);
        if (st == EKM_OK) { /* the fitted keys start from FILE.ini */
            ekm_material fm = ss.material;
            for (size_t k = 0; k < sc.nparams; k++)
                cg_fit_param_set(&start, sc.param[k], cg_fit_param_get(&fm, sc.param[k]));
        }
        ekm_scenario_free(&ss);
        snprintf(source, sizeof source, "%s (the fitted keys; the others from each case's scenario)",
                 a->start);
    } else {
        snprintf(source, sizeof source, "%s: the [material] of cases[0] (the others: each case's own)",
                 a->scenario);
    }
    cg_fit_result res;
    memset(&res, 0, sizeof res);
    if (st == EKM_OK) {
        sc.progress = a->progress || (!a->quiet && isatty(STDERR_FILENO));
        cg_fit_spec sp;
        cg_fitsc_spec(&sc, &start, &sp);
        sp.nstarts = a->nstarts ? a->nstarts : CG_FITSC_STARTS;
        sp.seed = 20261201ul;
        st = cg_fit_solve(&sp, &res, err);
        if (st == EKM_OK) {
            const cg_fit_outputs o = {.sc = &sc,
                                      .nstarts = sp.nstarts,
                                      .variant = variant,
                                      .closure = closure, /* cases[0]'s */
                                      .res = &res,
                                      .start_source = source,
                                      .json_path = a->json,
                                      .ini_path = a->ini};
            st = cg_fit_write(&o, err);
        }
        if (st == EKM_OK && !a->quiet)
            print_scen_summary(&sc, &res);
    }
    cg_fit_result_free(&res);
    cg_fitsc_free(&sc);
    return st;
}

int cg_fit_main(int argc, char **argv)
{
    for (int i = 0; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(fit_usage, stdout);
            return 0;
        }
    fit_args a = {.nstarts = 0};
    a.inputs = calloc((size_t)argc + 1, sizeof *a.inputs);
    a.at_pressure = calloc((size_t)argc + 1, sizeof *a.at_pressure);
    if (!a.inputs || !a.at_pressure) {
        free(a.inputs);
        free(a.at_pressure);
        fprintf(stderr, "ekmcompare fit: out of memory\n");
        return ekm_status_exit_code(EKM_ENOMEM);
    }
    int rc = parse_args(argc, argv, &a);
    if (!rc) {
        ekm_error err = {.message = ""};
        if (a.rheology && !a.nstarts)
            a.nstarts = 8;
        const ekm_status st = a.scenario ? run_scenario_fit(&a, &err) : run_fit(&a, &err);
        if (st != EKM_OK)
            ekm_error_print("ekmcompare", &err);
        rc = ekm_status_exit_code(st);
    }
    free(a.inputs);
    free(a.at_pressure);
    return rc;
}
