/* fit_out.c: FIT.json and FIT.ini of `ekmcompare fit` (fit_out.h). */
#include "fit_out.h"

#include "atomic.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ekm_version.h"

#include "json_out.h"

static const char *const variant_names[] = {"full", "thesis"};

static json_t *fit_json(const cg_fit_outputs *o)
{
    const cg_fit_problem *pb = o->pb;
    const cg_fit_result *res = o->res;
    json_t *root = json_object();
    json_t *params = json_object(), *corr = json_object(), *ident = json_object(), *why = json_object();
    json_t *start_values = json_object();
    for (size_t j = 0; j < res->nparams; j++) {
        const char *name = cg_fit_param_name(res->param[j]);
        json_object_set_new(params, name,
                            json_pack("{s:o, s:o}", "value", ekm_json_number(res->value[j]), "se",
                                      ekm_json_number(res->se[j])));
        json_t *row = json_object();
        for (size_t i = 0; i < res->nparams; i++)
            if (i != j)
                json_object_set_new(row, cg_fit_param_name(res->param[i]), ekm_json_number(res->corr[j][i]));
        json_object_set_new(corr, name, row);
        json_object_set_new(ident, name, json_boolean(res->identifiable[j]));
        if (!res->identifiable[j])
            json_object_set_new(why, name, json_string(res->why_not[j]));
        json_object_set_new(start_values, name, json_real(res->start[j]));
    }
    json_object_set_new(root, "params", params);
    json_object_set_new(root, "chi2", ekm_json_number(res->chi2));
    json_object_set_new(root, "chi2_dof", ekm_json_number(res->chi2_dof));
    json_object_set_new(root, "dof", json_integer(res->dof));
    json_object_set_new(root, "correlation", corr);
    json_object_set_new(root, "identifiable", ident);
    json_object_set_new(root, "why_not", why);
    json_t *fields = json_array();
    if (pb) {
        json_t *points = json_array();
        for (int f = 0; f < CG_FIT_NFIELD; f++)
            if (pb->fields & (1u << f))
                json_array_append_new(fields, json_string(cg_fit_field_name(f)));
        for (size_t k = 0; k < pb->npts; k++) {
            const cg_fit_point *pt = &pb->pts[k];
            json_t *resid = json_object(), *data = json_object(), *model = json_object();
            for (int f = 0; f < CG_FIT_NFIELD; f++) {
                if (!(pb->fields & (1u << f)))
                    continue;
                const char *name = cg_fit_field_name(f);
                json_object_set_new(resid, name, ekm_json_number(res->resid[k * CG_FIT_NFIELD + f]));
                json_object_set_new(data, name,
                                    json_pack("{s:o, s:o}", "value", ekm_json_number(pt->value[f]), "se",
                                              ekm_json_number(pt->se[f])));
                json_object_set_new(model, name, ekm_json_number(res->model[k * CG_FIT_NFIELD + f]));
            }
            json_object_set_new(model, "phi", ekm_json_number(res->model_phi[k]));
            json_array_append_new(
                points, json_pack("{s:s, s:s, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o}", "file", pt->file,
                                  "control", pt->at_pressure ? "pressure" : "volume", "phi",
                                  ekm_json_number(pt->phi), "phi_se", ekm_json_number(pt->phi_se), "gdot",
                                  ekm_json_number(pt->gdot), "gdot_se", ekm_json_number(pt->gdot_se), "vx_r2",
                                  ekm_json_number(pt->r2), "residuals", resid, "data", data, "model", model));
        }
        json_object_set_new(root, "points", points);
    } else {
        const cg_fitsc_problem *sc = o->sc;
        for (int f = 0; f < CG_FITSC_NFIELD; f++)
            if (sc->fields & (1u << f))
                json_array_append_new(fields, json_string(cg_fitsc_field_name(f)));
        json_t *cases = json_array();
        for (size_t i = 0; i < sc->ncases; i++) {
            const cg_fitsc_case *c = &sc->cases[i];
            json_t *set = json_array(), *per = json_object();
            for (size_t k = 0; k < c->nset; k++)
                json_array_append_new(set, json_string(c->set[k]));
            size_t used = 0;
            for (int f = 0; f < CG_FITSC_NFIELD; f++) {
                if (!(c->fields & (1u << f)))
                    continue;
                used += c->used[f];
                json_object_set_new(per, cg_fitsc_field_name(f),
                                    json_pack("{s:I, s:I, s:o}", "candidates", (json_int_t)c->ncand[f],
                                              "points_used", (json_int_t)c->used[f], "chi2",
                                              ekm_json_number(c->chi2_field[f])));
            }
            json_t *jc = json_pack(
                "{s:s, s:s, s:o, s:s, s:o, s:o, s:o, s:I, s:o, s:o, s:o, s:o, s:I}", "scenario", c->scenario,
                "dem", c->dem, "set", set, "support", "phi > threshold on both sides", "phi_threshold",
                ekm_json_number(c->phi_threshold), "shift_m", ekm_json_number(c->shift_m), "weight",
                ekm_json_number(c->weight), "points_used", (json_int_t)used, "chi2", ekm_json_number(c->chi2),
                "fields", per, "ekm_wall_s_last", ekm_json_number(c->wall_last_s), "ekm_wall_s_total",
                ekm_json_number(c->wall_total_s), "ekm_runs", (json_int_t)c->runs);
            if (jc) {
                /* how the runs were made (fit_scen.c solve_case) */
                json_object_set_new(jc, "ekm_steady_solves", json_integer((json_int_t)c->steady_solves));
                json_object_set_new(jc, "ekm_stepped_runs", json_integer((json_int_t)c->stepped_runs));
                json_object_set_new(jc, "ekm_solver_last",
                                    json_string(c->last_solver == CG_FITSC_SOLVER_STEADY ? "ekm steady"
                                                : c->last_solver == CG_FITSC_SOLVER_RUN  ? "ekm run"
                                                                                         : "none"));
                if (c->check_done)
                    json_object_set_new(jc, "steady_check",
                                        json_pack("{s:b, s:b, s:o, s:f, s:s}", "agrees", c->check_agrees,
                                                  "run_steady", c->check_run_steady, "difference",
                                                  ekm_json_number(c->check_difference), "tolerance",
                                                  CG_FITSC_AGREE_TOL, "kept",
                                                  c->check_agrees ? "ekm steady" : "ekm run"));
            }
            json_array_append_new(cases, jc);
        }
        json_object_set_new(root, "cases", cases);
        json_object_set_new(root, "evaluations",
                            json_pack("{s:I, s:o}", "count", (json_int_t)sc->evaluations, "ekm_wall_s",
                                      ekm_json_number(sc->ekm_wall_s)));
        json_object_set_new(root, "support", ekm_json_number(sc->support));
    }
    json_object_set_new(root, "start",
                        json_pack("{s:s, s:o}", "source", o->start_source, "values", start_values));
    json_t *material = json_object();
    for (int i = 0; i < cg_fit_param_count(); i++)
        if (cg_fit_param_read_by(o->closure, i))
            json_object_set_new(material, cg_fit_param_name(i), json_real(cg_fit_param_get(&res->fitted, i)));
    json_object_set_new(root, "material", material);
    json_object_set_new(root, "fields", fields);
    json_object_set_new(root, "closure", json_string(o->closure->name));
    json_object_set_new(root, "variant",
                        o->closure->is_ekm ? json_string(variant_names[o->variant == EKM_VARIANT_THESIS])
                                           : json_null());
    json_object_set_new(root, "starts",
                        json_pack("{s:i, s:i, s:i}", "requested", o->nstarts, "run", res->starts_run,
                                  "converged", res->starts_converged));
    json_object_set_new(root, "covariance_scale", ekm_json_number(res->cov_scale));
    json_object_set_new(root, "code_version", json_string(EKMBENCH_VERSION));
    return root;
}

static void ini_write(FILE *fp, const cg_fit_outputs *o)
{
    const cg_fit_problem *pb = o->pb;
    const cg_fitsc_problem *sc = o->sc;
    const cg_fit_result *res = o->res;
    fprintf(fp, "; [material] fitted by ekmcompare fit %s (ekmbench %s)\n", pb ? "--rheology" : "--scenario",
            EKMBENCH_VERSION);
    fprintf(fp, "; chi2/dof = %.6g (chi2 = %.6g, dof = %ld); fields", res->chi2_dof, res->chi2, res->dof);
    if (pb) {
        for (int f = 0; f < CG_FIT_NFIELD; f++)
            if (pb->fields & (1u << f))
                fprintf(fp, " %s", cg_fit_field_name(f));
        fprintf(fp, "; start: %s\n; inputs (%zu):\n", o->start_source, pb->npts);
        for (size_t k = 0; k < pb->npts; k++)
            fprintf(fp, ";   %s\n", pb->pts[k].file);
    } else {
        for (int f = 0; f < CG_FITSC_NFIELD; f++)
            if (sc->fields & (1u << f))
                fprintf(fp, " %s", cg_fitsc_field_name(f));
        fprintf(fp, "; start: %s\n; cases of %s (%zu):\n", o->start_source, sc->cases_path, sc->ncases);
        for (size_t i = 0; i < sc->ncases; i++) {
            fprintf(fp, ";   %s against %s", sc->cases[i].scenario, sc->cases[i].dem);
            for (size_t k = 0; k < sc->cases[i].nset; k++)
                fprintf(fp, " --set %s", sc->cases[i].set[k]);
            fputc('\n', fp);
        }
    }
    if (!o->closure->is_ekm)
        fprintf(fp, "; the [material] of [model] closure = %s\n", o->closure->name);
    fprintf(fp, "[material]\n");
    for (int i = 0; i < cg_fit_param_count(); i++) {
        if (!cg_fit_param_read_by(o->closure, i))
            continue;
        const char *name = cg_fit_param_name(i);
        fprintf(fp, "%-7s = %.17g", name, cg_fit_param_get(&res->fitted, i));
        size_t j = 0;
        while (j < res->nparams && res->param[j] != i)
            j++;
        if (j == res->nparams)
            fprintf(fp, " ; start value (not fitted)\n");
        else if (res->identifiable[j])
            fprintf(fp, " ; fitted, SE %.3g\n", res->se[j]);
        else
            fprintf(fp, " ; start value: not identifiable: %s\n", res->why_not[j]);
    }
}

/* Both outputs (FIT.json and, with --ini, FIT.ini) through common/atomic:
 * written under temporary names, renamed only when both are complete, and
 * the JSON removed again if the INI cannot be renamed (both or neither). */
ekm_status cg_fit_write(const cg_fit_outputs *o, ekm_error *err)
{
    ekm_atomic tj, ti;
    ekm_status st = ekm_atomic_open(&tj, o->json_path, err);
    if (st != EKM_OK)
        return st;
    json_t *root = fit_json(o);
    st = root ? ekm_json_dump(root, tj.fp, JSON_INDENT(1) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17),
                              o->json_path, err)
              : EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory building the JSON", o->json_path);
    json_decref(root);
    if (st != EKM_OK) {
        ekm_atomic_abort(&tj);
        return st;
    }
    if (o->ini_path) {
        st = ekm_atomic_open(&ti, o->ini_path, err);
        if (st != EKM_OK) {
            ekm_atomic_abort(&tj);
            return st;
        }
        ini_write(ti.fp, o);
    }
    st = ekm_atomic_commit(&tj, err);
    if (st != EKM_OK) {
        if (o->ini_path)
            ekm_atomic_abort(&ti);
        return st;
    }
    if (o->ini_path) {
        st = ekm_atomic_commit(&ti, err);
        if (st != EKM_OK)
            unlink(o->json_path); /* both or neither */
    }
    return st;
}
