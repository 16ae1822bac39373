/* status.c: the error record and the exit-code table (see status.h). */
#include "status.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void record_source(ekm_error *err, ekm_status code, const char *src_file, int src_line)
{
    err->code = code;
    err->src_file = src_file;
    err->src_line = src_line;
}

ekm_status ekm_error_set(ekm_error *err, ekm_status code, const char *src_file, int src_line, const char *fmt,
                         ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->input_file[0] = '\0';
        err->input_line = 0;
        record_source(err, code, src_file, src_line);
    }
    return code;
}

ekm_status ekm_error_set_at(ekm_error *err, ekm_status code, const char *input_file, int input_line,
                            const char *src_file, int src_line, const char *fmt, ...)
{
    if (!err)
        return code;
    /* the prefix, then the text after it (truncated to fit) */
    int prefix = 0;
    if (input_file && input_line > 0)
        prefix = snprintf(err->message, sizeof err->message, "%s:%d: ", input_file, input_line);
    else if (input_file)
        prefix = snprintf(err->message, sizeof err->message, "%s: ", input_file);
    if (prefix < 0)
        prefix = 0;
    if ((size_t)prefix >= sizeof err->message)
        prefix = (int)sizeof err->message - 1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message + prefix, sizeof err->message - (size_t)prefix, fmt, ap);
    va_end(ap);
    snprintf(err->input_file, sizeof err->input_file, "%s", input_file ? input_file : "");
    err->input_line = input_file && input_line > 0 ? input_line : 0;
    record_source(err, code, src_file, src_line);
    return code;
}

void ekm_error_clear(ekm_error *err)
{
    if (err)
        memset(err, 0, sizeof *err);
}

void ekm_error_print(const char *prog, const ekm_error *err)
{
    const char *msg = err && err->message[0] ? err->message : "unknown error";
    fprintf(stderr, "%s: %s\n", prog, msg);
    if (getenv("EKM_DEBUG") && err && err->src_file)
        fprintf(stderr, "%s: raised at %s:%d\n", prog, err->src_file, err->src_line);
}

int ekm_status_exit_code(ekm_status s)
{
    switch (s) {
    case EKM_EOF:
    case EKM_OK: return 0;
    case EKM_EUSAGE: return 1;
    case EKM_EINPUT: return 2;
    case EKM_EIO: return 3;
    case EKM_ENUMERIC: return 4;
    case EKM_ENOMEM:
    case EKM_EINTERNAL: return 5;
    case EKM_ENOTSTEADY: return 6;
    case EKM_EUNAVAILABLE: return 7;
    }
    return 5;
}

const char *ekm_status_name(ekm_status s)
{
    switch (s) {
    case EKM_EOF: return "end of data";
    case EKM_OK: return "ok";
    case EKM_EINPUT: return "input error";
    case EKM_ENOMEM: return "out of memory";
    case EKM_EIO: return "i/o error";
    case EKM_ENUMERIC: return "numerical failure";
    case EKM_EINTERNAL: return "internal error";
    case EKM_EUSAGE: return "usage error";
    case EKM_ENOTSTEADY: return "steady state not reached";
    case EKM_EUNAVAILABLE: return "unavailable";
    }
    return "unknown";
}

const char *ekm_status_symbol(ekm_status s)
{
    switch (s) {
    case EKM_EOF: return "EKM_EOF";
    case EKM_OK: return "EKM_OK";
    case EKM_EINPUT: return "EKM_EINPUT";
    case EKM_ENOMEM: return "EKM_ENOMEM";
    case EKM_EIO: return "EKM_EIO";
    case EKM_ENUMERIC: return "EKM_ENUMERIC";
    case EKM_EINTERNAL: return "EKM_EINTERNAL";
    case EKM_EUSAGE: return "EKM_EUSAGE";
    case EKM_ENOTSTEADY: return "EKM_ENOTSTEADY";
    case EKM_EUNAVAILABLE: return "EKM_EUNAVAILABLE";
    }
    return "EKM_EUNKNOWN";
}
