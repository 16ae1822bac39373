/* resolve.h: the other tools' sections of a scenario file ([dem] [compare]
 * [campaign] [figures]) and the resolved scenario (docs/resolved-scenario.md).
 *
 * The scenario reader (scenario.h) checks every key of these sections as it
 * reads it (tool_keys.h: known name, valid <engine>./<size>. prefix, value
 * of the key's type) and keeps it as written. ekm_resolve()
 * then picks, for one engine and size, the value of every key (the lookup
 * rule <engine>.<size>.k, <size>.k, <engine>.k, k, default; a --set of the
 * plain k beats every variant), fills the defaults (also the derived ones:
 * dem.restitution_input = dem.restitution, dem.t_end = run.t_end, ...), and
 * builds the sweep points with their tags, deck variables and the `ekm run
 * --set` overrides that compute the same point.
 */
#ifndef EKM_RESOLVE_H
#define EKM_RESOLVE_H

#include <stddef.h>

#include "scenario.h"
#include "status.h"

/* One resolved key. */
typedef struct {
    char name[64];   /* "section.key", the plain key */
    char value[160]; /* as written (or the default) */
    char from[600];  /* "FILE:LINE", "--set" or "default" */
    char as[64];     /* the key as written when a prefixed variant was chosen, else "" */
} ekm_resolve_key;

/* One sweep point: up to 3 deck variables, up to 6 ekm overrides. */
typedef struct {
    char tag[160]; /* "" for the single point, "theta22", "phi0.50-rate10", "p100-rate10" */
    size_t n_vars;
    char var_name[3][16];  /* "theta"; "phi", "rate"; "pressure", "rate"; [+ "dump_every"] */
    char var_value[3][64]; /* as written in the sweep list (dump_every: computed) */
    size_t n_sets;
    char set[6][96]; /* "gravity.angle=22", "top.velocity=0.1", ... */
} ekm_resolve_point;

typedef struct {
    char engine[16];       /* "" when not given */
    char size[16];         /* "" when not given */
    ekm_resolve_key *keys; /* ekm's sections in registry order, then [dem], [compare] */
    size_t n_keys;
    ekm_resolve_point *points;
    size_t n_points;
} ekm_resolved;

/* Resolve a loaded scenario for engine (liggghts, lammps or NULL) and size
 * (smoke, ref or NULL). Call ekm_resolve_free() in every case. */
ekm_status ekm_resolve(const ekm_scenario *s, const char *engine, const char *size, ekm_resolved *r,
                       ekm_error *err);

/* Keep only the point tagged tag; an unknown tag is an error listing the tags. */
ekm_status ekm_resolve_keep_point(ekm_resolved *r, const char *tag, ekm_error *err);

/* The resolved key named "section.key", or NULL. */
const ekm_resolve_key *ekm_resolve_find(const ekm_resolved *r, const char *name);

void ekm_resolve_free(ekm_resolved *r);

#endif
