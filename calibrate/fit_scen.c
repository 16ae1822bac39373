/* fit_scen.c: `ekmcompare fit --scenario` (fit_scen.h): CASES.json, the
 * DEM profiles, and the residuals of in-process EKM runs. */
#include "fit_scen.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "h5.h"
#include "point.h"
#include "progress.h"
#include "scenario.h"
#include "score.h"

static const char *const field_names[CG_FITSC_NFIELD] = {"phi", "vx", "T", "P", "sxz"};

const char *cg_fitsc_field_name(int f)
{
    return f >= 0 && f < CG_FITSC_NFIELD ? field_names[f] : "?";
}

static char *dup_str(const char *s)
{
    const size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static void case_free(cg_fitsc_case *c)
{
    if (c->sc_loaded)
        ekm_scenario_free(&c->sc);
    free(c->dem);
    free(c->scenario);
    free(c->material);
    for (size_t i = 0; i < c->nset; i++)
        free(c->set[i]);
    free(c->set);
    free(c->zd);
    free(c->phid);
    for (int f = 0; f < CG_FITSC_NFIELD; f++) {
        free(c->fd[f]);
        free(c->sd[f]);
        free(c->cand[f]);
    }
}

void cg_fitsc_free(cg_fitsc_problem *pb)
{
    for (size_t i = 0; i < pb->ncases; i++)
        case_free(&pb->cases[i]);
    free(pb->cases);
    pb->cases = NULL;
    pb->ncases = 0;
}

/* ---- CASES.json ---- */

static ekm_status parse_case(const char *path, size_t i, json_t *jc, unsigned cli_fields, cg_fitsc_case *c,
                             ekm_error *err)
{
    if (!json_is_object(jc))
        return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu]: expected an object", path, i);
    static const char *const known[] = {"dem", "scenario", "set", "fields", "shift_m", "weight", "material"};
    const char *key;
    json_t *v;
    json_object_foreach(jc, key, v)
    {
        size_t k = 0;
        while (k < sizeof known / sizeof *known && strcmp(known[k], key))
            k++;
        if (k == sizeof known / sizeof *known)
            return EKM_FAIL(
                err, EKM_EINPUT,
                "%s: cases[%zu]: unknown key '%s': expected dem, scenario, material, set, fields, "
                "shift_m, weight",
                path, i, key);
    }
    for (int k = 0; k < 2; k++) {
        json_t *s = json_object_get(jc, known[k]);
        if (!s)
            return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu]: missing key '%s' (a path)", path, i, known[k]);
        if (!json_is_string(s) || !json_string_length(s))
            return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu].%s: expected a path (a non-empty string)", path,
                            i, known[k]);
        char **dst = k ? &c->scenario : &c->dem;
        if (!(*dst = dup_str(json_string_value(s))))
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    json_t *mat = json_object_get(jc, "material");
    if (mat) {
        if (!json_is_string(mat) || !json_string_length(mat))
            return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu].material: expected a path (a non-empty string)",
                            path, i);
        if (!(c->material = dup_str(json_string_value(mat))))
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    json_t *set = json_object_get(jc, "set");
    if (set) {
        if (!json_is_array(set))
            return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu].set: expected an array of \"section.key=value\"",
                            path, i);
        c->set = calloc(json_array_size(set) + 1, sizeof *c->set);
        if (!c->set)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        size_t k;
        json_t *e;
        json_array_foreach(set, k, e)
        {
            if (!json_is_string(e))
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: cases[%zu].set[%zu]: expected a string \"section.key=value\"", path, i,
                                k);
            if (!(c->set[c->nset++] = dup_str(json_string_value(e))))
                return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        }
    }
    unsigned fields = (1u << CG_FITSC_NFIELD) - 1;
    json_t *jf = json_object_get(jc, "fields");
    if (jf) {
        if (!json_is_array(jf) || !json_array_size(jf))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: cases[%zu].fields: expected a non-empty array of phi, vx, T, P, sxz", path,
                            i);
        fields = 0;
        size_t k;
        json_t *e;
        json_array_foreach(jf, k, e)
        {
            int found = -1;
            for (int f = 0; f < CG_FITSC_NFIELD && json_is_string(e); f++)
                if (!strcmp(json_string_value(e), field_names[f]))
                    found = f;
            if (found < 0 || (fields & (1u << found)))
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: cases[%zu].fields[%zu]: expected distinct names among phi, vx, T, "
                                "P, sxz",
                                path, i, k);
            fields |= 1u << found;
        }
    }
    c->fields = fields & cli_fields;
    if (!c->fields)
        return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu].fields: none of them is in --fields", path, i);
    c->shift_m = 0.0;
    c->weight = 1.0;
    json_t *js = json_object_get(jc, "shift_m"), *jw = json_object_get(jc, "weight");
    if (js && !(json_is_number(js) && isfinite(json_number_value(js))))
        return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu].shift_m: expected a number [m]", path, i);
    if (jw && !(json_is_number(jw) && json_number_value(jw) > 0.0 && isfinite(json_number_value(jw))))
        return EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu].weight: expected a number > 0", path, i);
    if (js)
        c->shift_m = json_number_value(js);
    if (jw)
        c->weight = json_number_value(jw);
    return EKM_OK;
}

/* ---- the DEM profile ---- */

static ekm_status read_2d(ekm_h5_file *h, const char *ctx, const char *name, size_t ntd, size_t nzd,
                          double **out, ekm_error *err)
{
    if (!ekm_h5_exists(h, name))
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", ctx, name);
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    ekm_status st = ekm_h5_read_double(h, name, &rank, dims, out, err);
    if (st != EKM_OK)
        return st;
    if (rank != 2 || dims[0] != ntd || dims[1] != nzd) {
        free(*out);
        *out = NULL;
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected shape [%zu][%zu] (windows x bins)", ctx,
                        name, ntd, nzd);
    }
    return EKM_OK;
}

static ekm_status read_1d(ekm_h5_file *h, const char *ctx, const char *name, double **out, size_t *n,
                          ekm_error *err)
{
    if (!ekm_h5_exists(h, name))
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", ctx, name);
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    ekm_status st = ekm_h5_read_double(h, name, &rank, dims, out, err);
    if (st == EKM_OK && (rank != 1 || dims[0] == 0)) {
        free(*out);
        *out = NULL;
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected a non-empty 1-dimensional array", ctx,
                        name);
    }
    if (st == EKM_OK)
        *n = dims[0];
    return st;
}

static ekm_status read_dem(const char *path, size_t i, cg_fitsc_case *c, ekm_error *err)
{
    char ctx[1200];
    snprintf(ctx, sizeof ctx, "%s: cases[%zu].dem: %s", path, i, c->dem);
    struct stat sb;
    if (stat(c->dem, &sb) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: %s", ctx, strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: not a regular file", ctx);
    ekm_h5_file *h;
    ekm_error herr;
    if (ekm_h5_open(&h, c->dem, &herr) != EKM_OK)
        return EKM_FAIL(err, herr.code, "%s: %s", ctx, herr.message);
    char axis[16] = "";
    ekm_status st = EKM_OK;
    if (!ekm_h5_attr_exists(h, NULL, "kernel") || !ekm_h5_attr_exists(h, NULL, "axis") ||
        ekm_h5_attr_get_string(h, NULL, "axis", axis, sizeof axis, &herr) != EKM_OK ||
        (strcmp(axis, "x") && strcmp(axis, "y") && strcmp(axis, "z")))
        st = EKM_FAIL(err, EKM_EINPUT,
                      "%s: not an ekmcompare cg output (expected root attributes kernel and axis)", ctx);
    double *t = NULL;
    if (st == EKM_OK)
        st = read_1d(h, ctx, axis, &c->zd, &c->nzd, err);
    if (st == EKM_OK)
        st = read_1d(h, ctx, "t", &t, &c->ntd, err);
    free(t);
    if (st == EKM_OK)
        st = read_2d(h, ctx, "phi", c->ntd, c->nzd, &c->phid, err);
    for (int f = 0; f < CG_FITSC_NFIELD && st == EKM_OK; f++) {
        if (!(c->fields & (1u << f)))
            continue;
        char se[32];
        snprintf(se, sizeof se, "%s_se", field_names[f]);
        st = read_2d(h, ctx, field_names[f], c->ntd, c->nzd, &c->fd[f], err);
        if (st == EKM_OK)
            st = read_2d(h, ctx, se, c->ntd, c->nzd, &c->sd[f], err);
    }
    ekm_h5_close(h);
    if (st == EKM_OK)
        for (size_t k = 0; k < c->nzd; k++)
            c->zd[k] += c->shift_m; /* as score's read_axes */
    return st;
}

/* The candidate points of each field (fit_scen.h), given the EKM's cell
 * centres ze; ze NULL: the EKM's gap moves (a pressure-held wall), so no
 * point is left out for the domain here: each evaluation compares those
 * inside the cell centres of that run's last state. */
static int in_domain(const double *ze, size_t nze, double z)
{
    size_t zi;
    double az;
    return !ze || cg_score_locate(ze, nze, z, &zi, &az);
}

static ekm_status find_candidates(const char *path, size_t i, cg_fitsc_case *c, const double *ze, size_t nze,
                                  double support, ekm_error *err)
{
    const size_t n = c->ntd * c->nzd;
    double phi_max = 0.0;
    for (size_t q = 0; q < n; q++)
        if (isfinite(c->phid[q]))
            phi_max = fmax(phi_max, c->phid[q]);
    c->phi_threshold = support * phi_max;
    c->nres = 0;
    for (int f = 0; f < CG_FITSC_NFIELD; f++) {
        if (!(c->fields & (1u << f)))
            continue;
        if (!(c->cand[f] = malloc((n ? n : 1) * sizeof *c->cand[f])))
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        double sd2 = 0.0;
        size_t nd = 0;
        for (size_t k = 0; k < c->nzd; k++) {
            if (!in_domain(ze, nze, c->zd[k]))
                continue;
            for (size_t j = 0; j < c->ntd; j++) {
                const double d = c->fd[f][j * c->nzd + k];
                if (isfinite(d)) {
                    sd2 += d * d;
                    nd++;
                }
            }
        }
        const double floor_se = nd ? CG_SCORE_SE_FLOOR * sqrt(sd2 / (double)nd) : 0.0;
        for (size_t j = 0; j < c->ntd; j++)
            for (size_t k = 0; k < c->nzd; k++) {
                const size_t q = j * c->nzd + k;
                if (!in_domain(ze, nze, c->zd[k]))
                    continue;
                if (!isfinite(c->fd[f][q]) || !(isfinite(c->sd[f][q]) && c->sd[f][q] > floor_se))
                    continue;
                if (!(c->phid[q] > c->phi_threshold))
                    continue;
                c->cand[f][c->ncand[f]++] = q;
            }
        c->nres += c->ncand[f];
    }
    if (c->nres == 0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: cases[%zu]: %s: no DEM point with material, a standard error and inside "
                        "the EKM domain for the fields fitted",
                        path, i, c->dem);
    return EKM_OK;
}

ekm_status cg_fitsc_load(cg_fitsc_problem *pb, const char *cases_path, ekm_error *err)
{
    pb->cases_path = cases_path;
    pb->cases = NULL;
    pb->ncases = 0;
    pb->nres = 0;
    struct stat sb;
    if (stat(cases_path, &sb) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: %s", cases_path, strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: not a regular file", cases_path);
    json_error_t je;
    json_t *root = json_load_file(cases_path, 0, &je);
    if (!root)
        return EKM_FAIL(err, EKM_EINPUT, "%s:%d: not JSON: %s", cases_path, je.line, je.text);
    ekm_status st = EKM_OK;
    json_t *cases = json_is_object(root) ? json_object_get(root, "cases") : NULL;
    if (!json_is_object(root))
        st = EKM_FAIL(err, EKM_EINPUT, "%s: expected an object {\"cases\": [...]}", cases_path);
    else if (!cases)
        st = EKM_FAIL(err, EKM_EINPUT, "%s: missing key 'cases' (an array of cases)", cases_path);
    else if (!json_is_array(cases) || !json_array_size(cases))
        st = EKM_FAIL(err, EKM_EINPUT, "%s: cases: expected a non-empty array", cases_path);
    else if (json_object_size(root) != 1)
        st = EKM_FAIL(err, EKM_EINPUT, "%s: expected the one key 'cases' at the top level", cases_path);
    if (st == EKM_OK && !(pb->cases = calloc(json_array_size(cases), sizeof *pb->cases)))
        st = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    for (size_t i = 0; st == EKM_OK && i < json_array_size(cases); i++) {
        cg_fitsc_case *c = &pb->cases[pb->ncases++];
        st = parse_case(cases_path, i, json_array_get(cases, i), pb->fields, c, err);
        if (st == EKM_OK) {
            struct stat ss;
            if (stat(c->scenario, &ss) != 0)
                st = EKM_FAIL(err, EKM_EIO, "%s: cases[%zu].scenario: %s: cannot open: %s", cases_path, i,
                              c->scenario, strerror(errno));
        }
        if (st == EKM_OK)
            st = read_dem(cases_path, i, c, err);
        if (st != EKM_OK)
            break;
        ekm_error serr = {0};
        ekm_status ls = ekm_scenario_load_material(&c->sc, c->scenario, c->material,
                                                   (const char *const *)c->set, c->nset, &serr);
        c->sc_loaded = 1; /* also after a failed load: the reader may hold what it read */
        if (ls != EKM_OK) {
            st = EKM_FAIL(err, ls, "%s: cases[%zu].scenario: %s", cases_path, i, serr.message);
        } else if ((c->fields & (1u << CG_FITSC_T)) && !c->sc.closure->has_temperature) {
            st = EKM_FAIL(err, EKM_EINPUT, "%s: cases[%zu].fields: T: closure %s has no granular temperature",
                          cases_path, i, c->sc.closure->name);
        } else {
            const ekm_scenario *sc = &c->sc;
            c->phi_init_max = sc->phi_init;
            if (sc->bottom.kind == EKM_BC_INFLOW)
                c->phi_init_max = fmax(c->phi_init_max, sc->bottom.phi);
            if (sc->top.kind == EKM_BC_INFLOW)
                c->phi_init_max = fmax(c->phi_init_max, sc->top.phi);
            /* the initial grid (cell centres of `cells` equal cells over
             * `length`); a pressure-held wall moves it (the EKM's state
             * stretches it with the gap), so its candidates are not cut to
             * the initial domain */
            const int moving =
                ekm_boundary_pressure_wall(&sc->bottom) || ekm_boundary_pressure_wall(&sc->top);
            double *z = malloc((size_t)sc->cells * sizeof *z);
            if (!z)
                st = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
            const double dz = sc->length / sc->cells; /* as ekm_state_alloc */
            for (int j = 0; z && j < sc->cells; j++)
                z[j] = (j + 0.5) * dz;
            if (z)
                st =
                    find_candidates(cases_path, i, c, moving ? NULL : z, (size_t)sc->cells, pb->support, err);
            free(z);
        }
        pb->nres += c->nres;
    }
    json_decref(root);
    return st;
}

ekm_status cg_fitsc_start_material(const cg_fitsc_problem *pb, ekm_material *m, ekm_variant *variant,
                                   const ekm_closure **closure, ekm_error *err)
{
    const cg_fitsc_case *c = &pb->cases[0];
    ekm_scenario sc;
    ekm_error serr = {0};
    ekm_status st = ekm_scenario_load_material(&sc, c->scenario, c->material, (const char *const *)c->set,
                                               c->nset, &serr);
    if (st == EKM_OK) {
        *m = sc.material;
        *variant = sc.variant;
        *closure = sc.closure;
    } else {
        st = EKM_FAIL(err, st, "%s: cases[0].scenario: %s", pb->cases_path, serr.message);
    }
    ekm_scenario_free(&sc);
    return st;
}

/* ---- the residuals ---- */

/* Solve case c at the fitted parameters of m (its other material constants
 * its scenario's own) by the campaign's steady policy (point.h; with
 * pb->check_final, Newton's state checked against a run); the profiles and
 * cell centres into *pt. Non-zero: the solve failed. */
static int run_case(const cg_fitsc_problem *pb, cg_fitsc_case *c, const ekm_material *m, ekm_point *pt)
{
    ekm_material mc = c->sc.material;
    for (size_t k = 0; k < pb->nparams; k++)
        cg_fit_param_set(&mc, pb->param[k], cg_fit_param_get(m, pb->param[k]));
    ekm_error e = {0};
    const double t0 = ekm_now_s();
    const int bad = ekm_point_solve(&c->sc, &mc, pb->check_final, pt, &e) != EKM_OK;
    c->wall_last_s = ekm_now_s() - t0;
    c->wall_total_s += c->wall_last_s;
    c->runs++;
    if (bad)
        return 1;
    c->last_solver = pt->solver == EKM_POINT_NEWTON ? CG_FITSC_SOLVER_STEADY : CG_FITSC_SOLVER_RUN;
    if (pt->solver == EKM_POINT_NEWTON)
        c->steady_solves++;
    else
        c->stepped_runs++;
    if (pt->checked) {
        c->check_done = 1;
        c->check_difference = pt->agreement;
        c->check_run_steady = pt->run_steady;
        c->check_agrees = pt->solver == EKM_POINT_NEWTON;
    }
    return 0;
}

int cg_fitsc_residuals(cg_fitsc_problem *pb, const ekm_material *m, double *r)
{
    size_t i = 0;
    double chi2 = 0.0, wall = 0.0;
    int bad = 0;
    for (size_t ci = 0; ci < pb->ncases && !bad; ci++) {
        cg_fitsc_case *c = &pb->cases[ci];
        ekm_point pt;
        if (run_case(pb, c, m, &pt)) {
            bad = 1;
            break;
        }
        const double *ze = pt.z, *prof[CG_FITSC_NFIELD] = {pt.phi, pt.vx, pt.T, pt.P, pt.sxz};
        const size_t nze = pt.n;
        wall += c->wall_last_s;
        const double sw = sqrt(c->weight);
        c->chi2 = 0.0;
        for (int f = 0; f < CG_FITSC_NFIELD; f++) {
            c->used[f] = 0;
            c->chi2_field[f] = 0.0;
            if (!(c->fields & (1u << f)))
                continue;
            for (size_t q = 0; q < c->ncand[f]; q++) {
                const size_t p = c->cand[f][q], k = p % c->nzd;
                size_t zi;
                double az;
                double ri = 0.0;
                if (cg_score_locate(ze, nze, c->zd[k], &zi, &az)) {
                    const double phie =
                        cg_score_interp(prof[CG_FITSC_PHI], prof[CG_FITSC_PHI], nze, zi, az, 0.0);
                    if (phie > c->phi_threshold) {
                        const double e = cg_score_interp(prof[f], prof[f], nze, zi, az, 0.0);
                        ri = sw * (e - c->fd[f][p]) / c->sd[f][p];
                        c->used[f]++;
                    }
                }
                r[i++] = ri;
                c->chi2_field[f] += ri * ri;
            }
            c->chi2 += c->chi2_field[f];
        }
        chi2 += c->chi2;
        ekm_point_free(&pt);
    }
    pb->evaluations++;
    pb->ekm_wall_s += wall;
    if (pb->progress) {
        if (bad)
            fprintf(stderr,
                    "ekmcompare fit --scenario: evaluation %ld: an EKM run failed (trial rejected), elapsed "
                    "%.1f s\n",
                    pb->evaluations, ekm_now_s() - pb->started_s);
        else
            fprintf(
                stderr,
                "ekmcompare fit --scenario: evaluation %ld: chi2 = %.6g, EKM runs %.2f s, elapsed %.1f s\n",
                pb->evaluations, chi2, wall, ekm_now_s() - pb->started_s);
    }
    return bad || !isfinite(chi2);
}

static int resid_cb(void *ctx, const ekm_material *m, double *r)
{
    return cg_fitsc_residuals(ctx, m, r);
}

static ekm_status finish_cb(void *ctx, const ekm_material *m, size_t *nused, ekm_error *err)
{
    cg_fitsc_problem *pb = ctx;
    double *r = malloc(pb->nres * sizeof *r);
    if (!r)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    pb->check_final = 1; /* the fitted material's states as the campaign makes them */
    const int bad = cg_fitsc_residuals(pb, m, r);
    pb->check_final = 0;
    free(r);
    if (bad)
        return EKM_FAIL(err, EKM_ENUMERIC, "the fitted material: an EKM run failed");
    *nused = 0;
    for (size_t ci = 0; ci < pb->ncases; ci++)
        for (int f = 0; f < CG_FITSC_NFIELD; f++)
            *nused += pb->cases[ci].used[f];
    return EKM_OK;
}

void cg_fitsc_spec(cg_fitsc_problem *pb, const ekm_material *start, cg_fit_spec *sp)
{
    memset(sp, 0, sizeof *sp);
    sp->nres = pb->nres;
    sp->residuals = resid_cb;
    sp->finish = finish_cb;
    sp->ctx = pb;
    double phi_floor = 0.0;
    for (size_t ci = 0; ci < pb->ncases; ci++)
        phi_floor = fmax(phi_floor, pb->cases[ci].phi_init_max);
    sp->phi_floor = phi_floor;
    sp->jac_rel_step = CG_FITSC_JAC_STEP;
    sp->fd_step = CG_FITSC_FD_STEP;
    sp->xtol = CG_FITSC_XTOL;
    sp->gtol = CG_FITSC_GTOL;
    sp->ftol = CG_FITSC_FTOL;
    sp->max_iter = CG_FITSC_MAX_ITER;
    sp->start = *start;
    sp->nparams = pb->nparams;
    memcpy(sp->param, pb->param, sizeof sp->param);
    pb->started_s = ekm_now_s();
}
