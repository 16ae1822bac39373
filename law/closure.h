/* closure.h: the closures of the flow regimes as named styles, registered
 * in one table (closure.c), chosen by `[model] closure = NAME`
 * (docs/model/closures.md).
 *
 * A closure is the constitutive law of the flowing material: its stresses
 * and, where it has one, its granular temperature's heating and
 * dissipation. Each style is a file (law/closure_<name>.c) that defines
 * one ekm_closure: its name, its [material] keys beyond the EKM's (with
 * units), a range check and its pure functions. Adding a closure is
 * writing that file and adding its line to the table in closure.c (and
 * the file to law/CMakeLists.txt).
 *
 * The EKM's two variants are the styles ekm_full and ekm_thesis
 * (`[model] variant = full | thesis` is the older spelling of the same).
 * Every solver runs the styles that are the EKM's transport law with
 * their material (ekm_transport: the EKM's, and ekm_jam, whose phi_J and
 * beta are the material's phi_cp and g_beta). The other styles run where
 * their functions exist: the homogeneous steady shear (`ekm homog`,
 * `ekmcompare fit --rheology`) and, with local_stress and local_phi, the
 * dense slab solver (continuum/local_slab.h: `ekm run`, `ekm steady`);
 * elsewhere the tool refuses them by name (ekm_closure_require_ekm).
 *
 * A style's parameters live in ekm_material.law_p, one slot per
 * registered parameter in the table's order, NAN when not given; or, for
 * a parameter that is an EKM material field under its own name (field),
 * in that field.
 */
#ifndef EKM_CLOSURE_H
#define EKM_CLOSURE_H

#include <stddef.h>

#include "homogeneous.h"
#include "model.h"
#include "status.h"

/* The range of a closure parameter, which the fit keeps every trial in
 * (calibrate/fit.c: each its own transform). */
typedef enum {
    EKM_PARAM_POSITIVE = 0,   /* > 0 (log) */
    EKM_PARAM_ABOVE_PREVIOUS, /* > the parameter listed just before it (log of the difference) */
    EKM_PARAM_BELOW_PREVIOUS, /* in (0, the parameter listed just before it) (logistic of the ratio) */
    EKM_PARAM_PHI_ABOVE_DATA, /* a volume fraction in (every data point's phi, 1) (logistic) */
} ekm_param_range;

/* One [material] key of a closure beyond the EKM's. */
typedef struct {
    const char *key;       /* the key, also the fit's parameter name */
    const char *unit;      /* SI unit, "1" for a number */
    const char *about;     /* one line: what it is */
    ekm_param_range range; /* what the fit keeps it in */
    /* NULL: held in its law_p slot; else the ekm_material field that holds
     * it (ekm_jam's phi_J: &m->phi_cp) */
    double *(*field)(ekm_material *m);
    /* 1: a property of the grains (mu_i's d), given as rho_p is, not a
     * constitutive constant: the campaign's closure fits hold it */
    int grain_property;
} ekm_closure_param;

typedef struct ekm_closure ekm_closure;
struct ekm_closure {
    const char *name;    /* `[model] closure` value */
    const char *about;   /* one line, with its reference */
    int is_ekm;          /* 1: one of the EKM's two variants (ekm_full, ekm_thesis) */
    int ekm_transport;   /* 1: the EKM's transport law (model.h) with its material, variant
                          * below: every solver runs it */
    ekm_variant variant; /* ekm_transport: which variant */
    int has_temperature; /* 0: no granular temperature (its T is n/a: NAN) */
    /* the EKM [material] keys it reads (NULL-terminated; NULL: all of them) */
    const char *const *ekm_keys;
    const ekm_closure_param *params; /* its own [material] keys (law_p) */
    size_t nparams;
    /* range check of its parameters; the message names the [material] key */
    ekm_status (*check)(const ekm_closure *c, const ekm_material *m, ekm_error *err);
    /* the steady homogeneous simple shear at volume fraction phi and shear
     * rate gdot = |du/dz| > 0 [1/s] (homogeneous.h); a closure without a
     * temperature sets T, P_K, P_Y and r to NAN */
    ekm_status (*homog)(const ekm_closure *c, const ekm_material *m, double phi, double gdot,
                        ekm_homog_state *out, ekm_error *err);
    /* the same at a given pressure P > 0 [Pa] (pressure control); out->phi
     * is the volume fraction found */
    ekm_status (*homog_p)(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                          ekm_homog_state *out, ekm_error *err);
    /* A local rheology without a temperature, which the dense slab solver
     * runs (continuum/local_slab.h; NULL: the closure has none):
     * local_stress: the shear stress tau [Pa] at pressure P > 0 [Pa] and
     * shear rate gdot = du/dz [1/s], its viscosity's divergence at gdot -> 0
     * cut at gdot_min > 0 [1/s], with dtau/dgdot [Pa s] (> 0) into *dtau;
     * local_phi: the volume fraction of the material sheared at |gdot|
     * under P (its dilatancy law); *beyond = 1 where that lies outside the
     * law's range and phi is held at the range's end (else 0). */
    double (*local_stress)(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                           double gdot_min, double *dtau);
    double (*local_phi)(const ekm_closure *c, const ekm_material *m, double P, double gdot, int *beyond);
};

/* The registered closures, in the table's order. */
size_t ekm_closure_count(void);
const ekm_closure *ekm_closure_at(size_t i);

/* The closure named `name`; NULL if none (err then says so and lists the
 * names, for a message "[model] closure: ..."). */
const ekm_closure *ekm_closure_find(const char *name, ekm_error *err);

/* The EKM style of a variant (ekm_full, ekm_thesis). */
const ekm_closure *ekm_closure_of_variant(ekm_variant v);

/* The slot in ekm_material.law_p of parameter k of closure c. */
size_t ekm_closure_slot(const ekm_closure *c, size_t k);

/* Where parameter k of closure c is held in m: its law_p slot or its field. */
double *ekm_closure_param_ptr(const ekm_closure *c, size_t k, ekm_material *m);
double ekm_closure_param_value(const ekm_closure *c, size_t k, const ekm_material *m);

/* The same by global slot (ekm_closure_slot's numbering over every
 * registered closure; the fit's parameter index space); NULL when no
 * registered parameter has that slot. */
double *ekm_closure_slot_ptr(size_t slot, ekm_material *m);

/* The closure and parameter index whose [material] key is `key`, over
 * every registered closure; 0 if found, -1 if not. */
int ekm_closure_param_find(const char *key, const ekm_closure **c, size_t *k);

/* 1 if closure c reads the EKM [material] key `key`. */
int ekm_closure_reads_ekm_key(const ekm_closure *c, const char *key);

/* Every law_p slot set to NAN (not given). */
void ekm_closure_clear_params(ekm_material *m);

/* c's range check (for an EKM style, ekm_material_check). */
ekm_status ekm_closure_check(const ekm_closure *c, const ekm_material *m, ekm_error *err);

/* c's steady homogeneous simple shear (see the struct). */
ekm_status ekm_closure_homog(const ekm_closure *c, const ekm_material *m, double phi, double gdot,
                             ekm_homog_state *out, ekm_error *err);

/* c's steady homogeneous simple shear at a given pressure (see the struct). */
ekm_status ekm_closure_homog_at_pressure(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                                         ekm_homog_state *out, ekm_error *err);

/* EKM_OK for a style that is the EKM's transport law (ekm_transport);
 * else EKM_EUNAVAILABLE naming the closure and `what` (the tool or command
 * that needs the EKM, e.g. "ekm run"). */
ekm_status ekm_closure_require_ekm(const ekm_closure *c, const char *what, ekm_error *err);

/* The registered styles (closure_<name>.c). */
extern const ekm_closure ekm_closure_ekm_full;
extern const ekm_closure ekm_closure_ekm_thesis;
extern const ekm_closure ekm_closure_mu_i;
extern const ekm_closure ekm_closure_ekm_jam;

#endif
