/* status.h: one status enum and one error record for every program of
 * ekmbench (ekm, ekmcompare, the benchmarks).
 *
 * Convention (GSL/PETSc): a function that can fail returns ekm_status; the
 * caller checks it and returns it upward.  The function that detects the
 * failure writes one human-readable line into an ekm_error (owned by the
 * caller, no globals) with EKM_FAIL() or, when it knows where in the user's
 * input the problem is, EKM_FAIL_AT(), which prefixes "FILE:LINE: " and
 * stores the input location too.  Both record the C source location for
 * debugging (printed by ekm_error_print when EKM_DEBUG is set):
 *   "chute.ini:14: [material] eps0: expected a number, got '5x0'".
 * The program's exit code comes from ekm_status_exit_code(), the one table
 * of docs/exit-codes.md.
 */
#ifndef EKM_STATUS_H
#define EKM_STATUS_H

#include <stdarg.h>

typedef enum {
    EKM_EOF = -1, /* end of data: indicative, not an error (exit code 0) */
    EKM_OK = 0,
    EKM_EINPUT,      /* bad user input: scenario file, --set value, dump, HDF5/JSON input */
    EKM_ENOMEM,      /* allocation failed */
    EKM_EIO,         /* a file could not be opened, read or written */
    EKM_ENUMERIC,    /* the computation could not continue: phi out of range, no convergence */
    EKM_EINTERNAL,   /* a library call failed unexpectedly */
    EKM_EUSAGE,      /* bad command line: unknown option, missing argument */
    EKM_ENOTSTEADY,  /* finished, but the required steady state was not reached */
    EKM_EUNAVAILABLE /* a required program is missing or cannot run this case */
} ekm_status;

typedef struct {
    ekm_status code;      /* the status of the last failure recorded */
    char message[1024];   /* the one error line shown to the user */
    char input_file[512]; /* the user's input it refers to ("" when none) */
    int input_line;       /* line in input_file (0 when unknown) */
    const char *src_file; /* where in our code it was raised */
    int src_line;
} ekm_error;

/* Record a failure (err may be NULL); returns code, for
 * `return EKM_FAIL(err, EKM_EIO, "%s: cannot write", path);`. */
ekm_status ekm_error_set(ekm_error *err, ekm_status code, const char *src_file, int src_line, const char *fmt,
                         ...) __attribute__((format(printf, 5, 6)));

/* As ekm_error_set, with the user's input location: the message becomes
 * "INPUT_FILE:INPUT_LINE: text" ("INPUT_FILE: text" when input_line <= 0,
 * just "text" when input_file is NULL) and both are stored. */
ekm_status ekm_error_set_at(ekm_error *err, ekm_status code, const char *input_file, int input_line,
                            const char *src_file, int src_line, const char *fmt, ...)
    __attribute__((format(printf, 7, 8)));

#define EKM_FAIL(err, code, ...) ekm_error_set((err), (code), __FILE__, __LINE__, __VA_ARGS__)
#define EKM_FAIL_AT(err, code, input_file, input_line, ...) \
    ekm_error_set_at((err), (code), (input_file), (input_line), __FILE__, __LINE__, __VA_ARGS__)

/* Forget a recorded failure (code EKM_OK, empty message). */
void ekm_error_clear(ekm_error *err);

/* "PROG: message" on stderr; with the environment variable EKM_DEBUG set,
 * a second line "PROG: raised at SRC_FILE:SRC_LINE". */
void ekm_error_print(const char *prog, const ekm_error *err);

/* The process exit code for a status: docs/exit-codes.md (0 for EKM_OK and
 * EKM_EOF, 1 usage, 2 input, 3 i/o, 4 numeric, 5 internal/memory,
 * 6 not steady, 7 unavailable). */
int ekm_status_exit_code(ekm_status s);

/* Short lower-case description ("input error") and the C name ("EKM_EINPUT"). */
const char *ekm_status_name(ekm_status s);
const char *ekm_status_symbol(ekm_status s);

#endif
