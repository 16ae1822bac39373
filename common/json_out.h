/* json_out.h: JSON documents built with jansson and written through
 * common/atomic (the whole file or none).
 *
 * JSON has no NaN or infinity: a value that is not finite is written as
 * null (ekm_json_number). Reals are printed with the precision the flags
 * give (JSON_REAL_PRECISION(n); jansson's "%.ng", with ".0" added to an
 * integral value and the exponent's leading zeros dropped). */
#ifndef EKM_JSON_OUT_H
#define EKM_JSON_OUT_H

#include <jansson.h>
#include <stdio.h>

#include "status.h"

/* A real, or null when v is not finite; NULL only when out of memory. */
json_t *ekm_json_number(double v);

/* obj[key] = value, taking the reference to value; returns 0, or -1 (and
 * *bad = 1) when value is NULL (a failed allocation) or the set fails:
 * a document is built with many of these and checked once. */
int ekm_json_set(json_t *obj, const char *key, json_t *value, int *bad);

/* Print root and a newline to fp; EKM_EIO naming path when it fails. */
ekm_status ekm_json_dump(const json_t *root, FILE *fp, size_t flags, const char *path, ekm_error *err);

/* Write root to path atomically (common/atomic.h); root NULL: EKM_ENOMEM,
 * nothing written. Does not take the reference to root. */
ekm_status ekm_json_write(const char *path, const json_t *root, size_t flags, ekm_error *err);

#endif
