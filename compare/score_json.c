/* score_json.c: SCORE.json of `ekmcompare score` (declared in score.h). */
#include "score.h"

#include <math.h>
#include <string.h>

#include "ekm_version.h"
#include "json_out.h"
#include "scalars.h"

#define SCORE_JSON_FLAGS (JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(9))

/* a value in grain diameters (NaN without a diameter) */
static double in_d(double v, double d)
{
    return (isfinite(d) && d > 0) ? v / d : NAN;
}

int cg_score_is_sha256(const char *s)
{
    if (!s || strlen(s) != 64)
        return 0;
    for (; *s; s++)
        if (!((*s >= '0' && *s <= '9') || (*s >= 'a' && *s <= 'f')))
            return 0;
    return 1;
}

/* every option that produced the numbers, so that a reader (the figures,
 * the regression test) needs no scenario file to know or redo them */
static json_t *options_json(const cg_score_opts *o, const cg_score_field *res, size_t nres, const int *kinds,
                            size_t nk, const cg_score_summary *sm, int *bad)
{
    int other_dem = 0;
    json_t *opt = json_object(), *fields = json_array(), *scalars = json_array();
    for (size_t i = 0; i < nres; i++) {
        other_dem |= res[i].se_both;
        if (json_array_append_new(fields, json_string(res[i].name))) /* fails also on a NULL array */
            *bad = 1;
    }
    for (size_t i = 0; i < nk; i++)
        if (json_array_append_new(scalars, json_string(cg_scalar_name((cg_scalar_kind)kinds[i]))))
            *bad = 1;
    ekm_json_set(opt, "fields", fields, bad);
    ekm_json_set(opt, "ekm_time", json_string(o->ekm_last ? "last" : "interp"), bad);
    ekm_json_set(opt, "shift_m", ekm_json_number(o->shift), bad);
    ekm_json_set(opt, "model", json_string(other_dem ? "dem" : "ekm"), bad);
    ekm_json_set(opt, "se", json_string(other_dem ? "dem and model in quadrature" : "dem"), bad);
    ekm_json_set(opt, "se_floor_rel_rms", ekm_json_number(CG_SCORE_SE_FLOOR), bad);
    ekm_json_set(opt, "support", ekm_json_number(o->support), bad);
    ekm_json_set(opt, "support_phi", ekm_json_number(sm->support_phi), bad);
    ekm_json_set(opt, "scalars", scalars, bad);
    return opt;
}

static json_t *free_surface_json(const cg_score_summary *sm, int *bad)
{
    json_t *fs = json_object();
    ekm_json_set(
        fs, "definition",
        json_string("layer height: the highest z where phi crosses half its profile maximum (linear), "
                    "at the last DEM time compared"),
        bad);
    ekm_json_set(fs, "t_s", ekm_json_number(sm->t), bad);
    ekm_json_set(fs, "dem_m", ekm_json_number(sm->dem_height), bad);
    ekm_json_set(fs, "model_m", ekm_json_number(sm->model_height), bad);
    ekm_json_set(fs, "offset_m", ekm_json_number(sm->model_height - sm->dem_height), bad);
    ekm_json_set(fs, "mean_diameter_m", ekm_json_number(sm->mean_diameter), bad);
    ekm_json_set(fs, "dem_d", ekm_json_number(in_d(sm->dem_height, sm->mean_diameter)), bad);
    ekm_json_set(fs, "model_d", ekm_json_number(in_d(sm->model_height, sm->mean_diameter)), bad);
    ekm_json_set(fs, "offset_d", ekm_json_number(in_d(sm->model_height - sm->dem_height, sm->mean_diameter)),
                 bad);
    return fs;
}

static json_t *fields_json(const cg_score_field *res, size_t nres, int *bad)
{
    json_t *all = json_object();
    for (size_t i = 0; i < nres; i++) {
        json_t *f = json_object();
        if (res[i].na) { /* n/a: the reason, no numbers */
            ekm_json_set(f, "n_a", json_string(res[i].na), bad);
            ekm_json_set(all, res[i].name, f, bad);
            continue;
        }
        ekm_json_set(f, "points", json_integer((json_int_t)res[i].points), bad);
        ekm_json_set(f, "points_with_se", json_integer((json_int_t)res[i].points_se), bad);
        ekm_json_set(f, "points_left_out", json_integer((json_int_t)res[i].points_left_out), bad);
        ekm_json_set(f, "rel_l2", ekm_json_number(res[i].rel_l2), bad);
        ekm_json_set(f, "noise_normalised", ekm_json_number(res[i].noise), bad);
        ekm_json_set(f, "se", json_string(res[i].se_both ? "both, in quadrature" : "dem"), bad);
        ekm_json_set(all, res[i].name, f, bad);
    }
    return all;
}

/* the model's steadiness (null: not an EKM run to steady) */
static json_t *model_run_json(const cg_score_summary *sm, int *bad)
{
    if (!sm->run_until_steady)
        return json_null();
    json_t *r = json_object();
    ekm_json_set(r, "stop", json_string("steady"), bad);
    ekm_json_set(r, "steady", json_integer(sm->run_steady), bad);
    ekm_json_set(r, "steady_time_s", ekm_json_number(sm->run_steady_time), bad);
    ekm_json_set(r, "drift_per_s", ekm_json_number(sm->run_steady_drift), bad);
    ekm_json_set(r, "acceleration", ekm_json_number(sm->run_steady_acceleration), bad);
    return r;
}

static json_t *scalars_json(const cg_score_summary *sm, int *bad)
{
    json_t *all = json_object();
    for (size_t i = 0; i < sm->nscalars; i++) {
        const cg_score_scalar *c = &sm->scalar[i];
        const double diff = c->model - c->dem;
        const double se2 = (isfinite(c->dem_se) ? c->dem_se * c->dem_se : 0) +
                           (isfinite(c->model_se) ? c->model_se * c->model_se : 0);
        json_t *s = json_object();
        ekm_json_set(s, "t_s", ekm_json_number(c->t), bad);
        ekm_json_set(s, "dem", ekm_json_number(c->dem), bad);
        ekm_json_set(s, "dem_se", ekm_json_number(c->dem_se), bad);
        ekm_json_set(s, "model", ekm_json_number(c->model), bad);
        ekm_json_set(s, "model_se", ekm_json_number(c->model_se), bad);
        ekm_json_set(s, "rel_error", ekm_json_number(diff / fabs(c->dem)), bad);
        ekm_json_set(s, "error_over_se",
                     ekm_json_number(isfinite(c->dem_se) && se2 > 0 ? diff / sqrt(se2) : NAN), bad);
        ekm_json_set(s, "units", json_string(c->units), bad);
        ekm_json_set(all, c->name, s, bad);
    }
    return all;
}

/* the inputs' record: table.sh recomputes the checksums and shows a score
 * whose input is gone or changed as missing */
static json_t *inputs_json(const cg_score_opts *o, int *bad)
{
    json_t *in = json_object();
    ekm_json_set(in, "dem", json_pack("{s:s, s:s}", "path", o->dem, "sha256", o->dem_sha256), bad);
    ekm_json_set(in, "ekm", json_pack("{s:s, s:s}", "path", o->ekm, "sha256", o->ekm_sha256), bad);
    return in;
}

ekm_status cg_score_json_write(const cg_score_opts *o, const cg_score_field *res, size_t nres,
                               const char *time_mode, const int *scalar_kinds, size_t nkinds,
                               const cg_score_summary *sm, ekm_error *err)
{
    int bad = 0;
    json_t *root = json_object();
    ekm_json_set(root, "dem", json_string(o->dem), &bad);
    ekm_json_set(root, "ekm", json_string(o->ekm), &bad);
    ekm_json_set(root, "time", json_string(time_mode), &bad);
    ekm_json_set(root, "code_version", json_string(EKMBENCH_VERSION), &bad);
    ekm_json_set(root, "options", options_json(o, res, nres, scalar_kinds, nkinds, sm, &bad), &bad);
    ekm_json_set(root, "free_surface", free_surface_json(sm, &bad), &bad);
    ekm_json_set(root, "fields", fields_json(res, nres, &bad), &bad);
    ekm_json_set(root, "model_run", model_run_json(sm, &bad), &bad);
    ekm_json_set(root, "scalars", scalars_json(sm, &bad), &bad);
    if (o->dem_sha256 && o->ekm_sha256)
        ekm_json_set(root, "inputs", inputs_json(o, &bad), &bad);
    ekm_status st = bad ? EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory building the JSON", o->json)
                        : ekm_json_write(o->json, root, SCORE_JSON_FLAGS, err);
    json_decref(root);
    return st;
}
