/* error.h: status codes and the one-line error record of ekmcompare.
 *
 * Every function that can fail returns an int status from enum cg_status
 * and, on failure, fills a cg_error whose text is the user-facing line
 * "input:line: what was expected". The source file and line where the
 * error was raised are kept separately (for --debug), as LAMMPS's FLERR.
 * CG_EOF is indicative (end of data), not an error.
 */
#ifndef CG_ERROR_H
#define CG_ERROR_H

enum cg_status {
  CG_EOF = -1,    /* end of data: indicative, not an error */
  CG_OK = 0,
  CG_EINPUT = 1,  /* bad input file or data */
  CG_EUSAGE = 2,  /* bad command line */
  CG_ESYS = 3     /* out of memory, cannot write output */
};

typedef struct {
  int status;          /* enum cg_status of the last error */
  char msg[1024];      /* user-facing text, starts with "input:line: " */
  const char *src;     /* source file that raised it */
  int src_line;        /* source line that raised it */
} cg_error;

/* Record an error; returns status so callers can `return CG_ERROR(...)`. */
int cg_error_set(cg_error *e, int status, const char *src, int line,
                 const char *fmt, ...) __attribute__((format(printf, 5, 6)));

#define CG_ERROR(e, status, ...) \
  cg_error_set((e), (status), __FILE__, __LINE__, __VA_ARGS__)

/* Clear an error record. */
void cg_error_clear(cg_error *e);

#endif
