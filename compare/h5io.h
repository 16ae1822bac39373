/* h5io.h: the HDF5 files of ekmcompare: an atomic writer (temporary name,
 * renamed on commit, removed on abort) and a reader for 1D/2D double
 * datasets and string/number attributes (our cg files and ekm's output).
 * Every HDF5 object opened here is closed here; HDF5's own error stack
 * printing is switched off by cg_h5_quiet() and errors come back as
 * one-line messages naming the file and dataset.
 */
#ifndef CG_H5IO_H
#define CG_H5IO_H

#include <stddef.h>

#include "error.h"

typedef struct cg_h5w cg_h5w;
typedef struct cg_h5r cg_h5r;

/* Silence HDF5's automatic error printing (call once in programs). */
void cg_h5_quiet(void);

int cg_h5w_create(cg_h5w **w, const char *path, cg_error *err);
/* 1D dataset [n] (nt == 0) or 2D [nt][n], with a `units` attribute. */
int cg_h5w_dataset(cg_h5w *w, const char *name, const double *data, size_t nt,
                   size_t n, const char *units, cg_error *err);
int cg_h5w_attr_str(cg_h5w *w, const char *name, const char *value, cg_error *err);
int cg_h5w_attr_double(cg_h5w *w, const char *name, double value, cg_error *err);
/* Close and rename to the final name. */
int cg_h5w_commit(cg_h5w *w, cg_error *err);
/* Close and remove the temporary file; NULL is harmless. */
void cg_h5w_abort(cg_h5w *w);

int cg_h5r_open(cg_h5r **r, const char *path, cg_error *err);
void cg_h5r_close(cg_h5r *r);
int cg_h5r_has(cg_h5r *r, const char *name);
/* Read a double dataset: 1D ([n], *nt = 0) or 2D ([nt][n]); malloc'ed. */
int cg_h5r_read(cg_h5r *r, const char *name, double **data, size_t *nt, size_t *n,
                cg_error *err);
/* Root attribute as a string (numbers are formatted); 0 if found. */
int cg_h5r_attr_str(cg_h5r *r, const char *name, char *buf, size_t size);

#endif
