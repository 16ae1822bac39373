#include "status.h"

#include <stdio.h>

ekm_status ekm_error_set(ekm_error *err, ekm_status code, const char *src_file,
                         int src_line, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->src_file = src_file;
        err->src_line = src_line;
    }
    return code;
}

int ekm_status_exit_code(ekm_status s)
{
    switch (s) {
    case EKM_OK: return 0;
    case EKM_EINPUT: return 2;
    case EKM_EIO: return 3;
    case EKM_ENUMERIC: return 4;
    case EKM_ENOMEM:
    case EKM_EINTERNAL: return 5;
    }
    return 5;
}

const char *ekm_status_name(ekm_status s)
{
    switch (s) {
    case EKM_OK: return "ok";
    case EKM_EINPUT: return "input error";
    case EKM_ENOMEM: return "out of memory";
    case EKM_EIO: return "i/o error";
    case EKM_ENUMERIC: return "numerical failure";
    case EKM_EINTERNAL: return "internal error";
    }
    return "unknown";
}
