/* h5.h: the one HDF5 layer of ekmbench (only this module calls HDF5's
 * file-creation functions; outputs are created atomically via atomic.h).
 *
 * A file is an opaque ekm_h5_file, created for writing (ekm_h5_create:
 * built in memory, written to a temporary in the target's directory and
 * renamed by ekm_h5_commit, removed by ekm_h5_abort) or opened for reading (ekm_h5_open, closed by
 * ekm_h5_close).  Datasets and attributes are named by path: `obj` is the
 * object an attribute is attached to, NULL or "/" for the file's root
 * group, else a dataset name ("phi").
 *
 * Layout choices (kept byte-for-byte from the files ekm and ekmcompare
 * wrote before this module): strings are fixed-length, NUL-terminated
 * scalar attributes of strlen+1 bytes; numbers are scalar H5T_NATIVE_DOUBLE
 * / H5T_NATIVE_INT (int32) attributes; datasets are contiguous (fixed) or
 * chunked with an unlimited first dimension (extendible time series); the
 * optional `units` and `description` attributes are such strings.
 *
 * Every HDF5 status is checked, every handle closed exactly once (a failed
 * close is not retried), HDF5's own error-stack printing is off, and every
 * failure is one line naming the file and the dataset or attribute.
 *
 * A file being written lives in memory (HDF5's core driver) until commit,
 * which writes its image to the temporary with ordinary checked writes: a
 * full disk or a file-size limit is "PATH: cannot write the output file:
 * No space left on device" (EKM_EIO), never a failed H5Fclose (HDF5 1.10
 * keeps the id of a file whose close failed and closes it again at exit, a
 * use after free).  The memory held is the size of the file (twice that
 * while commit copies out its image).
 */
#ifndef EKM_H5_H
#define EKM_H5_H

#include <stddef.h>

#include "atomic.h"
#include "status.h"

typedef struct ekm_h5_file ekm_h5_file;

typedef enum { EKM_H5_DOUBLE, EKM_H5_INT } ekm_h5_type; /* float64 / int32 */

enum { EKM_H5_MAX_RANK = 3 };

/* Turn off HDF5's automatic error printing (done by create/open too). */
void ekm_h5_quiet(void);

/* Writing: create PATH atomically (nothing appears at PATH until commit). */
ekm_status ekm_h5_create(ekm_h5_file **out, const char *path, ekm_error *err);
/* Close the file and rename it into place; frees f (also on failure). */
ekm_status ekm_h5_commit(ekm_h5_file *f, ekm_error *err);
/* Close the file and write it, complete and fsynced, to its temporary,
 * handed over in *out for ekm_atomic_commit or ekm_atomic_abort (to write
 * a sidecar before either is renamed); frees f; on failure nothing is
 * left. */
ekm_status ekm_h5_finish(ekm_h5_file *f, ekm_atomic *out, ekm_error *err);
/* Close and remove the temporary; frees f; NULL is harmless. */
void ekm_h5_abort(ekm_h5_file *f);

/* Reading: EKM_EIO when PATH cannot be read, EKM_EINPUT when it is not
 * an HDF5 file. */
ekm_status ekm_h5_open(ekm_h5_file **out, const char *path, ekm_error *err);
/* Close a file opened for reading; frees f; NULL is harmless. */
void ekm_h5_close(ekm_h5_file *f);

/* The target path the file was created or opened with. */
const char *ekm_h5_path(const ekm_h5_file *f);

/* Attributes on obj (NULL/"/" root, else a dataset). */
ekm_status ekm_h5_attr_set_string(ekm_h5_file *f, const char *obj, const char *name, const char *value,
                                  ekm_error *err);
ekm_status ekm_h5_attr_set_double(ekm_h5_file *f, const char *obj, const char *name, double value,
                                  ekm_error *err);
ekm_status ekm_h5_attr_set_int(ekm_h5_file *f, const char *obj, const char *name, int value, ekm_error *err);
ekm_status ekm_h5_attr_set_double_array(ekm_h5_file *f, const char *obj, const char *name,
                                        const double *values, size_t n, ekm_error *err);
ekm_status ekm_h5_attr_set_int_array(ekm_h5_file *f, const char *obj, const char *name, const int *values,
                                     size_t n, ekm_error *err);

/* A fixed dataset of rank 1-3 (dims[rank]), written at once from data
 * (row-major; may be NULL when a dimension is 0).  units/description:
 * string attributes, each skipped when NULL. */
ekm_status ekm_h5_write(ekm_h5_file *f, const char *name, ekm_h5_type type, int rank, const size_t *dims,
                        const void *data, const char *units, const char *description, ekm_error *err);
ekm_status ekm_h5_write_double(ekm_h5_file *f, const char *name, int rank, const size_t *dims,
                               const double *data, const char *units, const char *description,
                               ekm_error *err);
ekm_status ekm_h5_write_int(ekm_h5_file *f, const char *name, int rank, const size_t *dims, const int *data,
                            const char *units, const char *description, ekm_error *err);

/* A dataset of the field schema (common/schema.h): as ekm_h5_write_double,
 * its units the schema's; a name the schema lacks is EKM_EINTERNAL. */
ekm_status ekm_h5_write_field(ekm_h5_file *f, const char *name, int rank, const size_t *dims,
                              const double *data, ekm_error *err);

/* An extendible dataset of rank 1-3: first dimension 0 and unlimited,
 * the others row_dims[rank-1]; chunks of chunk_rows rows. */
ekm_status ekm_h5_create_series(ekm_h5_file *f, const char *name, ekm_h5_type type, int rank,
                                const size_t *row_dims, size_t chunk_rows, const char *units,
                                const char *description, ekm_error *err);
/* Append one row (prod(row_dims) values of the series' type). */
ekm_status ekm_h5_append(ekm_h5_file *f, const char *name, const void *row, ekm_error *err);

/* A virtual dataset VIEW (1D, created with its groups) showing row `row`
 * of the 2D dataset SOURCE of the same file, without copying it (a plain
 * dataset to readers that cannot select a row, e.g. ParaView's Xdmf3
 * readers).  A 3D SOURCE [nt][n][m] gives the 2D view [n][m] of row `row`. */
ekm_status ekm_h5_row_view(ekm_h5_file *f, const char *view, const char *source, size_t row, ekm_error *err);

/* Existence: a dataset (or any link) named name; an attribute on obj. */
int ekm_h5_exists(ekm_h5_file *f, const char *name);
int ekm_h5_attr_exists(ekm_h5_file *f, const char *obj, const char *name);

/* Read a whole dataset of rank 1-3 converted to doubles / ints: *rank,
 * dims[0..rank-1], *data malloc'ed (free() it; never NULL on success).
 * A missing dataset: EKM_EINPUT "FILE: expected a dataset NAME". */
ekm_status ekm_h5_read_double(ekm_h5_file *f, const char *name, int *rank, size_t dims[EKM_H5_MAX_RANK],
                              double **data, ekm_error *err);
ekm_status ekm_h5_read_int(ekm_h5_file *f, const char *name, int *rank, size_t dims[EKM_H5_MAX_RANK],
                           int **data, ekm_error *err);

/* Read attributes.  get_string: a string attribute (fixed or variable
 * length) as is; a numeric scalar formatted with "%.17g".  get_double /
 * get_int: a numeric scalar.  get_double_array: up to cap values, *n the
 * attribute's length (EKM_EINPUT when longer than cap).  A missing
 * attribute: EKM_EINPUT "FILE: OBJ: expected an attribute NAME". */
ekm_status ekm_h5_attr_get_string(ekm_h5_file *f, const char *obj, const char *name, char *buf, size_t size,
                                  ekm_error *err);
ekm_status ekm_h5_attr_get_double(ekm_h5_file *f, const char *obj, const char *name, double *value,
                                  ekm_error *err);
ekm_status ekm_h5_attr_get_int(ekm_h5_file *f, const char *obj, const char *name, int *value, ekm_error *err);
ekm_status ekm_h5_attr_get_double_array(ekm_h5_file *f, const char *obj, const char *name, double *values,
                                        size_t cap, size_t *n, ekm_error *err);

#endif
