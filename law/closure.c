/* closure.c: the table of closure styles and its lookups (closure.h). */
#include "closure.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The registered closures: one line per style (its file law/closure_<name>.c).
 * The order fixes the law_p slots of their parameters. */
static const ekm_closure *const CLOSURES[] = {
    &ekm_closure_ekm_full,
    &ekm_closure_ekm_thesis,
    &ekm_closure_mu_i,
    &ekm_closure_ekm_jam,
};
#define N_CLOSURES (sizeof CLOSURES / sizeof CLOSURES[0])

size_t ekm_closure_count(void)
{
    return N_CLOSURES;
}

const ekm_closure *ekm_closure_at(size_t i)
{
    return i < N_CLOSURES ? CLOSURES[i] : NULL;
}

const ekm_closure *ekm_closure_find(const char *name, ekm_error *err)
{
    for (size_t i = 0; i < N_CLOSURES; i++)
        if (strcmp(CLOSURES[i]->name, name) == 0)
            return CLOSURES[i];
    char list[256] = "";
    for (size_t i = 0; i < N_CLOSURES; i++) {
        const size_t n = strlen(list);
        snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", CLOSURES[i]->name);
    }
    if (err)
        EKM_FAIL(err, EKM_EINPUT, "unknown closure '%s': expected one of %s", name, list);
    return NULL;
}

const ekm_closure *ekm_closure_of_variant(ekm_variant v)
{
    return v == EKM_VARIANT_THESIS ? &ekm_closure_ekm_thesis : &ekm_closure_ekm_full;
}

size_t ekm_closure_slot(const ekm_closure *c, size_t k)
{
    size_t slot = 0;
    for (size_t i = 0; i < N_CLOSURES && CLOSURES[i] != c; i++)
        slot += CLOSURES[i]->nparams;
    return slot + k;
}

double *ekm_closure_param_ptr(const ekm_closure *c, size_t k, ekm_material *m)
{
    return c->params[k].field ? c->params[k].field(m) : &m->law_p[ekm_closure_slot(c, k)];
}

double ekm_closure_param_value(const ekm_closure *c, size_t k, const ekm_material *m)
{
    ekm_material copy = *m; /* the field accessors take a writable material */
    return *ekm_closure_param_ptr(c, k, &copy);
}

double *ekm_closure_slot_ptr(size_t slot, ekm_material *m)
{
    for (size_t i = 0; i < N_CLOSURES; i++) {
        if (slot < CLOSURES[i]->nparams)
            return ekm_closure_param_ptr(CLOSURES[i], slot, m);
        slot -= CLOSURES[i]->nparams;
    }
    return NULL;
}

int ekm_closure_param_find(const char *key, const ekm_closure **c, size_t *k)
{
    for (size_t i = 0; i < N_CLOSURES; i++)
        for (size_t j = 0; j < CLOSURES[i]->nparams; j++)
            if (strcmp(CLOSURES[i]->params[j].key, key) == 0) {
                *c = CLOSURES[i];
                *k = j;
                return 0;
            }
    return -1;
}

int ekm_closure_reads_ekm_key(const ekm_closure *c, const char *key)
{
    if (!c->ekm_keys)
        return 1;
    for (const char *const *k = c->ekm_keys; *k; k++)
        if (strcmp(*k, key) == 0)
            return 1;
    return 0;
}

void ekm_closure_clear_params(ekm_material *m)
{
    for (size_t i = 0; i < EKM_LAW_PARAMS_MAX; i++)
        m->law_p[i] = NAN;
}

ekm_status ekm_closure_check(const ekm_closure *c, const ekm_material *m, ekm_error *err)
{
    return c->check(c, m, err);
}

ekm_status ekm_closure_homog(const ekm_closure *c, const ekm_material *m, double phi, double gdot,
                             ekm_homog_state *out, ekm_error *err)
{
    return c->homog(c, m, phi, gdot, out, err);
}

ekm_status ekm_closure_homog_at_pressure(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                                         ekm_homog_state *out, ekm_error *err)
{
    return c->homog_p(c, m, P, gdot, out, err);
}

ekm_status ekm_closure_require_ekm(const ekm_closure *c, const char *what, ekm_error *err)
{
    if (c->ekm_transport)
        return EKM_OK;
    return EKM_FAIL(err, EKM_EUNAVAILABLE,
                    "[model] closure = %s: %s solves the EKM's transport law only (ekm_full, ekm_thesis, "
                    "ekm_jam); %s runs in ekm homog and ekmcompare fit --rheology%s (docs/model/closures.md)",
                    c->name, what, c->name,
                    c->local_stress ? ", and in ekm run and ekm steady of a dense slab" : "");
}
