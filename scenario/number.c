/* number.c: the number syntax of the scenario keys (number.h). */
#include "number.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A decimal floating-point literal: [-+]? (digits [. digits*] | . digits)
 * ([eE] [-+]? digits)?, representable (no overflow or underflow). */
static int is_number(const char *v, size_t len, double *out)
{
    size_t i = 0, digits = 0;
    if (i < len && (v[i] == '-' || v[i] == '+'))
        i++;
    while (i < len && v[i] >= '0' && v[i] <= '9')
        i++, digits++;
    if (i < len && v[i] == '.') {
        i++;
        while (i < len && v[i] >= '0' && v[i] <= '9')
            i++, digits++;
    }
    if (digits == 0)
        return 0;
    if (i < len && (v[i] == 'e' || v[i] == 'E')) {
        i++;
        if (i < len && (v[i] == '-' || v[i] == '+'))
            i++;
        size_t exp_digits = 0;
        while (i < len && v[i] >= '0' && v[i] <= '9')
            i++, exp_digits++;
        if (exp_digits == 0)
            return 0;
    }
    if (i != len)
        return 0;
    char buf[EKM_VALUE_MAX];
    if (len >= sizeof buf)
        return 0;
    memcpy(buf, v, len);
    buf[len] = '\0';
    char *end;
    errno = 0;
    const double x = strtod(buf, &end);
    if (*end != '\0' || errno == ERANGE || !isfinite(x))
        return 0;
    if (out)
        *out = x;
    return 1;
}

/* A decimal integer: [-+]? digits, within long long. */
static int is_integer(const char *v, long long *out)
{
    const char *p = v + (*v == '-' || *v == '+');
    if (!*p || strspn(p, "0123456789") != strlen(p))
        return 0;
    char *end;
    errno = 0;
    const long long x = strtoll(v, &end, 10);
    if (errno == ERANGE)
        return 0;
    if (out)
        *out = x;
    return 1;
}

int ekm_number_parse(const char *value, double *out)
{
    return is_number(value, strlen(value), out);
}

int ekm_number_parse_integer(const char *value, long long *out)
{
    return is_integer(value, out);
}

int ekm_number_parse_list(const char *value, double *out, size_t max, size_t *n)
{
    *n = 0;
    for (const char *p = value + strspn(value, EKM_NUMBER_BLANKS); *p; p += strspn(p, EKM_NUMBER_BLANKS)) {
        const size_t len = strcspn(p, EKM_NUMBER_BLANKS);
        double x;
        if (!is_number(p, len, &x))
            return 0;
        if (out && *n < max)
            out[*n] = x;
        p += len;
        (*n)++;
    }
    return *n > 0;
}
