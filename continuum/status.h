/* status.h: one status enum for every function of libekm that can fail.
 *
 * Convention (GSL/PETSc): a function that can fail returns ekm_status; the
 * caller checks it and returns it upward.  The function that detects the
 * failure writes one human-readable line into an ekm_error (owned by the
 * caller, no globals) with EKM_FAIL(), which also records the C source
 * location for debugging.  The text names the user's input location first:
 *   "chute.ini:14: [material] eps0: expected a number, got '5x0'".
 */
#ifndef EKM_STATUS_H
#define EKM_STATUS_H

#include <stdarg.h>

typedef enum {
    EKM_OK = 0,
    EKM_EINPUT,   /* bad user input: scenario file, command line */
    EKM_ENOMEM,   /* allocation failed */
    EKM_EIO,      /* file could not be read or written */
    EKM_ENUMERIC, /* solver could not continue: phi out of range, no convergence */
    EKM_EINTERNAL /* a library call failed unexpectedly */
} ekm_status;

typedef struct {
    char message[1024]; /* the one error line shown to the user */
    const char *src_file; /* where in our code it was raised */
    int src_line;
} ekm_error;

ekm_status ekm_error_set(ekm_error *err, ekm_status code, const char *src_file,
                         int src_line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

#define EKM_FAIL(err, code, ...) ekm_error_set((err), (code), __FILE__, __LINE__, __VA_ARGS__)

/* Exit code of the ekm program for a status (documented in README). */
int ekm_status_exit_code(ekm_status s);

const char *ekm_status_name(ekm_status s);

#endif
