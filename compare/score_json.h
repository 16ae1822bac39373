/* score_json.h: SCORE.json of `ekmcompare score` (score.h), written with
 * jansson (common/json_out.h).
 *
 * The keys, in this order: dem, ekm (the input paths), time (how the model
 * times were matched), code_version, options (everything that produced the
 * numbers: fields, ekm_time, shift_m, model, se, se_floor_rel_rms, support,
 * support_phi, scalars), free_surface, fields, model_run, scalars, and
 * inputs (each input's path and sha256) when the caller gave the checksums.
 * Reals are printed to 9 significant digits (the options too: give --shift
 * and --support with at most 9); a value that is not finite is null. */
#ifndef CG_SCORE_JSON_H
#define CG_SCORE_JSON_H

#include <stddef.h>

#include "score.h"
#include "status.h"

/* Write o->json atomically. time_mode: "ekm last output" or
 * "interpolated"; scalar_kinds (nkinds): the scalars asked for, sets
 * expanded (scalars.h kinds). */
ekm_status cg_score_json_write(const cg_score_opts *o, const cg_score_field *res, size_t nres,
                               const char *time_mode, const int *scalar_kinds, size_t nkinds,
                               const cg_score_summary *sm, ekm_error *err);

/* 1 when s is a SHA-256 digest as sha256sum prints it (64 hexadecimal digits, lower case). */
int cg_score_is_sha256(const char *s);

#endif
