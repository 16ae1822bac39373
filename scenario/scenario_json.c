/* scenario_json.c: the resolved scenario as JSON (jansson), the shape of
 * docs/resolved-scenario.md. */
#include "scenario_json.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "closure.h"
#include "slab_takes.h"
#include "ekm_version.h"

/* json_object_set_new that remembers a failure (NULL value, out of memory). */
static void put(json_t *obj, const char *name, json_t *value, int *failed)
{
    if (!obj || !value || json_object_set_new(obj, name, value) != 0)
        *failed = 1;
}

static void append(json_t *arr, json_t *value, int *failed)
{
    if (!arr || !value || json_array_append_new(arr, value) != 0)
        *failed = 1;
}

static json_t *string_or_null(const char *s)
{
    return s[0] ? json_string(s) : json_null();
}

static json_t *resolved_object(const ekm_scenario *s, const ekm_resolved *r, int *failed)
{
    json_t *root = json_object();
    put(root, "format", json_string(EKM_JSON_RESOLVED_FORMAT), failed);
    put(root, "format_version", json_integer(EKM_JSON_RESOLVED_VERSION), failed);
    put(root, "file", json_string(s->source), failed);
    put(root, "scenario", json_string(s->name), failed);
    put(root, "engine", string_or_null(r->engine), failed);
    put(root, "size", string_or_null(r->size), failed);
    put(root, "code_version", json_string(EKMBENCH_VERSION), failed);
    /* the closure style the [material] keys belong to (docs/model/closures.md) */
    json_t *closure = json_object(), *own = json_array(), *grains = json_array();
    put(closure, "name", json_string(s->closure->name), failed);
    put(closure, "ekm_transport", json_boolean(s->closure->ekm_transport), failed);
    put(closure, "has_temperature", json_boolean(s->closure->has_temperature), failed);
    for (size_t k = 0; k < s->closure->nparams; k++)
        append(s->closure->params[k].grain_property ? grains : own, json_string(s->closure->params[k].key),
               failed);
    /* does the 1D solver of the closure take this scenario (slab_takes.h)? */
    ekm_error why = {0};
    const int takes = ekm_scenario_slab_takes(s, &why) == EKM_OK;
    const ekm_closure *c = s->closure;
    put(closure, "slab_solver",
        c->ekm_transport                  ? json_string("ekm")
        : c->local_stress && c->local_phi ? json_string("local")
                                          : json_null(),
        failed);
    put(closure, "slab_takes", json_boolean(takes), failed);
    put(closure, "slab_why", takes ? json_null() : json_string(why.message), failed);
    put(closure, "params", own, failed);
    put(closure, "grain_properties", grains, failed);
    put(root, "closure", closure, failed);
    json_t *keys = json_object();
    for (size_t i = 0; i < r->n_keys; i++) {
        const ekm_resolve_key *k = &r->keys[i];
        json_t *o = json_object();
        put(o, "value", json_string(k->value), failed);
        put(o, "from", json_string(k->from), failed);
        if (k->as[0])
            put(o, "as", json_string(k->as), failed);
        put(keys, k->name, o, failed);
    }
    put(root, "keys", keys, failed);
    json_t *points = json_array();
    for (size_t i = 0; i < r->n_points; i++) {
        const ekm_resolve_point *p = &r->points[i];
        json_t *o = json_object(), *vars = json_object(), *sets = json_array();
        put(o, "tag", json_string(p->tag), failed);
        for (size_t j = 0; j < p->n_vars; j++)
            put(vars, p->var_name[j], json_string(p->var_value[j]), failed);
        put(o, "vars", vars, failed);
        for (size_t j = 0; j < p->n_sets; j++)
            append(sets, json_string(p->set[j]), failed);
        put(o, "ekm_set", sets, failed);
        append(points, o, failed);
    }
    put(root, "points", points, failed);
    return root;
}

/* JSON strings are UTF-8: a value that is not is bad input, named by key. */
static ekm_status check_utf8(const ekm_scenario *s, const ekm_resolved *r, ekm_error *err)
{
    for (size_t i = 0; i < r->n_keys; i++) {
        json_t *v = json_string(r->keys[i].value);
        if (!v) {
            const char *name = r->keys[i].name, *dot = strchr(name, '.');
            return EKM_FAIL(err, EKM_EINPUT, "%s: [%.*s] %s: expected UTF-8 text", r->keys[i].from,
                            (int)(dot - name), name, dot + 1);
        }
        json_decref(v);
    }
    json_t *v = json_string(s->source);
    if (!v)
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected a file name in UTF-8", s->source);
    json_decref(v);
    return EKM_OK;
}

ekm_status ekm_json_write_resolved(FILE *out, const ekm_scenario *s, const ekm_resolved *r, ekm_error *err)
{
    ekm_status st = check_utf8(s, r, err);
    if (st != EKM_OK)
        return st;
    int failed = 0;
    json_t *root = resolved_object(s, r, &failed);
    char *text = failed ? NULL : json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_ENSURE_ASCII);
    json_decref(root);
    if (!text)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory writing the resolved scenario");
    /* all of it or an error: the text is complete before anything is written */
    const int ok = fputs(text, out) >= 0 && fputc('\n', out) != EOF && fflush(out) == 0 && !ferror(out);
    free(text);
    if (!ok)
        return EKM_FAIL(err, EKM_EIO, "cannot write the resolved scenario to standard output");
    return EKM_OK;
}
