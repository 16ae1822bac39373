/* number.h: the one number syntax of every scenario key
 * (docs/scenario-format.md), read the same way by ekm's own sections, the
 * other tools' sections and the sweep lists.
 *
 * A number is a decimal floating-point literal, the whole value
 * ([-+]? digits [. digits] [e [-+] digits], or [-+]? . digits ...; no
 * blanks, hex, inf or nan), finite and without overflow or underflow.
 */
#ifndef EKM_NUMBER_H
#define EKM_NUMBER_H

#include <stddef.h>

/* The blanks that separate the numbers of a list. */
#define EKM_NUMBER_BLANKS " \t"

/* The longest value any scenario key may have, its NUL included [chars]. */
#define EKM_VALUE_MAX 160

/* Returns 1 and *out (out may be NULL) when value is one number; else 0. */
int ekm_number_parse(const char *value, double *out);

/* A list of numbers separated by blanks (spaces, tabs), the syntax of the
 * sweep lists ([dem] rates) and of [bottom]/[top] inlet_x: each a number as
 * ekm_number_parse reads it. Returns 1 when value is such a list of at
 * least one number, with *n their count and out[0 .. min(*n, max)) the
 * first max of them (out may be NULL); otherwise 0. */
int ekm_number_parse_list(const char *value, double *out, size_t max, size_t *n);

/* A decimal integer, the whole value ([-+]? digits) within long long:
 * 1 and *out (out may be NULL), or 0. */
int ekm_number_parse_integer(const char *value, long long *out);

#endif
