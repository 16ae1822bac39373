/* h5.c: the HDF5 layer (see h5.h). */
#include "h5.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/types.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "schema.h"

#include "atomic.h"

_Static_assert(sizeof(int) == 4, "EKM_H5_INT datasets are int32: int must be 32 bits");

struct ekm_h5_file {
    hid_t file;     /* -1 once closed */
    int writing;    /* created by ekm_h5_create (then `out` is active) */
    ekm_atomic out; /* the temporary (open, empty until commit) and the target (writing) */
    char *path;     /* target (writing) or input (reading) */
};

void ekm_h5_quiet(void)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

const char *ekm_h5_path(const ekm_h5_file *f)
{
    return f->path;
}

/* H5Xclose-style closer called at most once per handle: *h is -1 after,
 * whatever the result (a failed close must not be retried). */
static int close_once(hid_t *h, herr_t (*closer)(hid_t))
{
    if (*h < 0)
        return 0;
    const hid_t id = *h;
    *h = -1;
    return closer(id) < 0 ? -1 : 0;
}

static void free_file(ekm_h5_file *f)
{
    free(f->path);
    free(f);
}

/* Bytes by which the in-memory file image grows (the core driver). */
enum { CORE_INCREMENT = 1 << 20 };

ekm_status ekm_h5_create(ekm_h5_file **out, const char *path, ekm_error *err)
{
    *out = NULL;
    ekm_h5_quiet();
    ekm_h5_file *f = calloc(1, sizeof *f);
    if (!f || !(f->path = strdup(path))) {
        free(f);
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", path);
    }
    f->file = -1;
    /* the temporary exists (empty) from now on, so a target that cannot
     * be written fails here, before any work */
    ekm_status st = ekm_atomic_open(&f->out, path, err);
    if (st != EKM_OK) {
        free_file(f);
        return st;
    }
    f->writing = 1;
    /* HDF5 writes into memory only (core driver, no backing store): a
     * failing disk can never make H5Fclose fail (HDF5 1.10 frees the file
     * of a failed close but keeps its id, and closes it again at exit);
     * the image reaches the disk through ekm_atomic_write at commit */
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl >= 0 && H5Pset_fapl_core(fapl, CORE_INCREMENT, 0) >= 0)
        f->file = H5Fcreate(f->out.tmp_path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    close_once(&fapl, H5Pclose);
    if (f->file < 0) {
        ekm_atomic_abort(&f->out);
        free_file(f);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot create the output file", path);
    }
    *out = f;
    return EKM_OK;
}

ekm_status ekm_h5_finish(ekm_h5_file *f, ekm_atomic *out, ekm_error *err)
{
    if (!f->writing) {
        ekm_h5_close(f);
        return EKM_FAIL(err, EKM_EINTERNAL, "commit of a file opened for reading");
    }
    ekm_status st = EKM_OK;
    void *image = NULL;
    ssize_t size = -1;
    if (H5Fflush(f->file, H5F_SCOPE_GLOBAL) >= 0)
        size = H5Fget_file_image(f->file, NULL, 0);
    if (size > 0 && !(image = malloc((size_t)size)))
        st = EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory (%lld bytes)", f->path, (long long)size);
    else if (size <= 0 || H5Fget_file_image(f->file, image, (size_t)size) != size)
        st = EKM_FAIL(err, EKM_EINTERNAL, "%s: cannot take the HDF5 file image", f->path);
    if (close_once(&f->file, H5Fclose) != 0 && st == EKM_OK)
        st = EKM_FAIL(err, EKM_EINTERNAL, "%s: cannot close the HDF5 file", f->path);
    if (st == EKM_OK)
        st = ekm_atomic_write(&f->out, image, (size_t)size, err);
    free(image);
    if (st == EKM_OK)
        st = ekm_atomic_finish(&f->out, err);
    if (st == EKM_OK)
        *out = f->out;
    else
        ekm_atomic_abort(&f->out);
    free_file(f);
    return st;
}

ekm_status ekm_h5_commit(ekm_h5_file *f, ekm_error *err)
{
    ekm_atomic out;
    ekm_status st = ekm_h5_finish(f, &out, err);
    return st == EKM_OK ? ekm_atomic_commit(&out, err) : st;
}

void ekm_h5_abort(ekm_h5_file *f)
{
    if (!f)
        return;
    close_once(&f->file, H5Fclose);
    if (f->writing)
        ekm_atomic_abort(&f->out);
    free_file(f);
}

ekm_status ekm_h5_open(ekm_h5_file **out, const char *path, ekm_error *err)
{
    *out = NULL;
    ekm_h5_quiet();
    if (access(path, R_OK) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: no such readable file", path);
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: not a regular file", path);
    if (H5Fis_hdf5(path) <= 0)
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected an HDF5 file", path);
    ekm_h5_file *f = calloc(1, sizeof *f);
    if (!f || !(f->path = strdup(path))) {
        free(f);
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", path);
    }
    f->file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f->file < 0) {
        free_file(f);
        return EKM_FAIL(err, EKM_EINPUT, "%s: cannot open as HDF5", path);
    }
    *out = f;
    return EKM_OK;
}

void ekm_h5_close(ekm_h5_file *f)
{
    if (!f)
        return;
    if (f->writing) {
        ekm_h5_abort(f);
        return;
    }
    close_once(&f->file, H5Fclose);
    free_file(f);
}

/* ---- attributes ---------------------------------------------------- */

static int is_root(const char *obj)
{
    return !obj || obj[0] == '\0' || strcmp(obj, "/") == 0;
}

/* "FILE: " or "FILE: dataset OBJ: " for messages. */
static void where(const ekm_h5_file *f, const char *obj, char *out, size_t size)
{
    if (is_root(obj))
        snprintf(out, size, "%s", f->path);
    else
        snprintf(out, size, "%s: dataset %s", f->path, obj);
}

/* Open the object attributes go on; *owned says whether to close it. */
static hid_t open_object(ekm_h5_file *f, const char *obj, int *owned)
{
    *owned = 0;
    if (is_root(obj))
        return f->file;
    if (H5Lexists(f->file, obj, H5P_DEFAULT) <= 0)
        return -1;
    *owned = 1;
    return H5Oopen(f->file, obj, H5P_DEFAULT);
}

/* Create attribute name on obj of the given memory/file type and
 * dataspace, and write value. */
static int write_attr(hid_t obj, const char *name, hid_t type, hid_t space, const void *value)
{
    hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    if (attr < 0)
        return -1;
    int rc = H5Awrite(attr, type, value) < 0 ? -1 : 0;
    if (close_once(&attr, H5Aclose) != 0)
        rc = -1;
    return rc;
}

static int string_attr(hid_t obj, const char *name, const char *value)
{
    hid_t type = H5Tcopy(H5T_C_S1), space = H5Screate(H5S_SCALAR);
    int rc = type >= 0 && space >= 0 && H5Tset_size(type, strlen(value) + 1) >= 0 &&
                     H5Tset_strpad(type, H5T_STR_NULLTERM) >= 0
                 ? write_attr(obj, name, type, space, value)
                 : -1;
    if (close_once(&space, H5Sclose) != 0)
        rc = -1;
    if (close_once(&type, H5Tclose) != 0)
        rc = -1;
    return rc;
}

/* n == 0: scalar; else a 1D array of n. */
static int numeric_attr(hid_t obj, const char *name, hid_t type, const void *values, size_t n, int scalar)
{
    hsize_t dim = (hsize_t)n;
    hid_t space = scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &dim, NULL);
    int rc = space >= 0 ? write_attr(obj, name, type, space, values) : -1;
    if (close_once(&space, H5Sclose) != 0)
        rc = -1;
    return rc;
}

typedef enum { A_STRING, A_DOUBLE, A_INT } attr_kind;

static ekm_status set_attr(ekm_h5_file *f, const char *obj, const char *name, attr_kind kind,
                           const void *values, size_t n, int scalar, ekm_error *err)
{
    int owned;
    hid_t o = open_object(f, obj, &owned);
    int rc = -1;
    if (o >= 0) {
        if (kind == A_STRING)
            rc = string_attr(o, name, values);
        else
            rc = numeric_attr(o, name, kind == A_DOUBLE ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT, values, n,
                              scalar);
    }
    if (owned && close_once(&o, H5Oclose) != 0)
        rc = -1;
    if (rc != 0) {
        char w[EKM_ATOMIC_PATH_MAX + 300];
        where(f, obj, w, sizeof w);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the attribute %s", w, name);
    }
    return EKM_OK;
}

ekm_status ekm_h5_attr_set_string(ekm_h5_file *f, const char *obj, const char *name, const char *value,
                                  ekm_error *err)
{
    return set_attr(f, obj, name, A_STRING, value, 0, 1, err);
}

ekm_status ekm_h5_attr_set_double(ekm_h5_file *f, const char *obj, const char *name, double value,
                                  ekm_error *err)
{
    return set_attr(f, obj, name, A_DOUBLE, &value, 1, 1, err);
}

ekm_status ekm_h5_attr_set_int(ekm_h5_file *f, const char *obj, const char *name, int value, ekm_error *err)
{
    return set_attr(f, obj, name, A_INT, &value, 1, 1, err);
}

ekm_status ekm_h5_attr_set_double_array(ekm_h5_file *f, const char *obj, const char *name,
                                        const double *values, size_t n, ekm_error *err)
{
    return set_attr(f, obj, name, A_DOUBLE, values, n, 0, err);
}

ekm_status ekm_h5_attr_set_int_array(ekm_h5_file *f, const char *obj, const char *name, const int *values,
                                     size_t n, ekm_error *err)
{
    return set_attr(f, obj, name, A_INT, values, n, 0, err);
}

/* ---- datasets ------------------------------------------------------ */

static hid_t file_type(ekm_h5_type t)
{
    return t == EKM_H5_INT ? H5T_NATIVE_INT32 : H5T_NATIVE_DOUBLE;
}

static hid_t mem_type(ekm_h5_type t)
{
    return t == EKM_H5_INT ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE;
}

/* units and description on an open dataset; 0 on success. */
static int describe(hid_t d, const char *units, const char *description)
{
    if (units && string_attr(d, "units", units) != 0)
        return -1;
    if (description && string_attr(d, "description", description) != 0)
        return -1;
    return 0;
}

ekm_status ekm_h5_write(ekm_h5_file *f, const char *name, ekm_h5_type type, int rank, const size_t *dims,
                        const void *data, const char *units, const char *description, ekm_error *err)
{
    if (rank < 1 || rank > EKM_H5_MAX_RANK)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: dataset %s: rank %d, expected 1 to %d", f->path, name, rank,
                        EKM_H5_MAX_RANK);
    hsize_t hd[EKM_H5_MAX_RANK];
    size_t total = 1;
    for (int i = 0; i < rank; i++) {
        hd[i] = (hsize_t)dims[i];
        total *= dims[i];
    }
    hid_t space = H5Screate_simple(rank, hd, NULL), d = -1;
    int ok = space >= 0 && (d = H5Dcreate2(f->file, name, file_type(type), space, H5P_DEFAULT, H5P_DEFAULT,
                                           H5P_DEFAULT)) >= 0;
    if (ok && total > 0)
        ok = H5Dwrite(d, mem_type(type), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0;
    if (ok)
        ok = describe(d, units, description) == 0;
    if (close_once(&d, H5Dclose) != 0)
        ok = 0;
    if (close_once(&space, H5Sclose) != 0)
        ok = 0;
    if (!ok)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the dataset %s", f->path, name);
    return EKM_OK;
}

ekm_status ekm_h5_write_double(ekm_h5_file *f, const char *name, int rank, const size_t *dims,
                               const double *data, const char *units, const char *description, ekm_error *err)
{
    return ekm_h5_write(f, name, EKM_H5_DOUBLE, rank, dims, data, units, description, err);
}

ekm_status ekm_h5_write_field(ekm_h5_file *f, const char *name, int rank, const size_t *dims,
                              const double *data, ekm_error *err)
{
    const char *units = ekm_field_units(name);
    if (!units)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: no units for %s in the field schema", f->path, name);
    return ekm_h5_write_double(f, name, rank, dims, data, units, NULL, err);
}

ekm_status ekm_h5_write_int(ekm_h5_file *f, const char *name, int rank, const size_t *dims, const int *data,
                            const char *units, const char *description, ekm_error *err)
{
    return ekm_h5_write(f, name, EKM_H5_INT, rank, dims, data, units, description, err);
}

ekm_status ekm_h5_create_series(ekm_h5_file *f, const char *name, ekm_h5_type type, int rank,
                                const size_t *row_dims, size_t chunk_rows, const char *units,
                                const char *description, ekm_error *err)
{
    if (rank < 1 || rank > EKM_H5_MAX_RANK || chunk_rows == 0)
        return EKM_FAIL(err, EKM_EINTERNAL,
                        "%s: series %s: rank %d, chunk %zu rows: expected rank 1 to %d, "
                        "chunk >= 1",
                        f->path, name, rank, chunk_rows, EKM_H5_MAX_RANK);
    hsize_t dims[EKM_H5_MAX_RANK] = {0}, maxdims[EKM_H5_MAX_RANK] = {H5S_UNLIMITED},
            chunk[EKM_H5_MAX_RANK] = {(hsize_t)chunk_rows};
    for (int i = 1; i < rank; i++)
        dims[i] = maxdims[i] = chunk[i] = (hsize_t)row_dims[i - 1];
    hid_t space = H5Screate_simple(rank, dims, maxdims), plist = H5Pcreate(H5P_DATASET_CREATE), d = -1;
    int ok = space >= 0 && plist >= 0 && H5Pset_chunk(plist, rank, chunk) >= 0 &&
             (d = H5Dcreate2(f->file, name, file_type(type), space, H5P_DEFAULT, plist, H5P_DEFAULT)) >= 0 &&
             describe(d, units, description) == 0;
    if (close_once(&d, H5Dclose) != 0)
        ok = 0;
    if (close_once(&plist, H5Pclose) != 0)
        ok = 0;
    if (close_once(&space, H5Sclose) != 0)
        ok = 0;
    if (!ok)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot create the dataset %s", f->path, name);
    return EKM_OK;
}

ekm_status ekm_h5_append(ekm_h5_file *f, const char *name, const void *row, ekm_error *err)
{
    hid_t d = H5Dopen2(f->file, name, H5P_DEFAULT), fspace = -1, mspace = -1, type = -1;
    hsize_t dims[EKM_H5_MAX_RANK], start[EKM_H5_MAX_RANK] = {0}, count[EKM_H5_MAX_RANK];
    int ok = d >= 0 && (fspace = H5Dget_space(d)) >= 0;
    const int rank = ok ? H5Sget_simple_extent_ndims(fspace) : -1;
    ok = ok && rank >= 1 && rank <= EKM_H5_MAX_RANK && H5Sget_simple_extent_dims(fspace, dims, NULL) >= 0;
    if (close_once(&fspace, H5Sclose) != 0)
        ok = 0;
    if (ok) {
        start[0] = dims[0];
        count[0] = 1;
        for (int i = 1; i < rank; i++)
            count[i] = dims[i];
        dims[0]++;
        ok = H5Dset_extent(d, dims) >= 0 && (fspace = H5Dget_space(d)) >= 0 &&
             (mspace = H5Screate_simple(rank, count, NULL)) >= 0 &&
             H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
             (type = H5Dget_type(d)) >= 0;
    }
    if (ok)
        ok = H5Dwrite(d, H5Tget_class(type) == H5T_INTEGER ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE, mspace,
                      fspace, H5P_DEFAULT, row) >= 0;
    if (close_once(&type, H5Tclose) != 0)
        ok = 0;
    if (close_once(&mspace, H5Sclose) != 0)
        ok = 0;
    if (close_once(&fspace, H5Sclose) != 0)
        ok = 0;
    if (close_once(&d, H5Dclose) != 0)
        ok = 0;
    if (!ok)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot append to the dataset %s", f->path, name);
    return EKM_OK;
}

ekm_status ekm_h5_row_view(ekm_h5_file *f, const char *view, const char *source, size_t row, ekm_error *err)
{
    hid_t d = H5Dopen2(f->file, source, H5P_DEFAULT), sspace = -1, vspace = -1, type = -1, dcpl = -1,
          lcpl = -1, v = -1;
    hsize_t dims[3] = {0, 0, 1};
    int rank = 0;
    int ok = d >= 0 && (sspace = H5Dget_space(d)) >= 0 &&
             ((rank = H5Sget_simple_extent_ndims(sspace)) == 2 || rank == 3) &&
             H5Sget_simple_extent_dims(sspace, dims, NULL) >= 0 && row < dims[0] &&
             (type = H5Dget_type(d)) >= 0;
    if (ok) {
        /* rank 3 (a 2D grid per row): the view is the row's [dims1][dims2] */
        const hsize_t start[3] = {row, 0, 0}, count[3] = {1, dims[1], dims[2]};
        ok = H5Sselect_hyperslab(sspace, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
             (vspace = H5Screate_simple(rank - 1, &dims[1], NULL)) >= 0 &&
             (dcpl = H5Pcreate(H5P_DATASET_CREATE)) >= 0 &&
             H5Pset_virtual(dcpl, vspace, ".", source, sspace) >= 0 &&
             (lcpl = H5Pcreate(H5P_LINK_CREATE)) >= 0 && H5Pset_create_intermediate_group(lcpl, 1) >= 0 &&
             (v = H5Dcreate2(f->file, view, type, vspace, lcpl, dcpl, H5P_DEFAULT)) >= 0;
    }
    if (close_once(&v, H5Dclose) != 0)
        ok = 0;
    close_once(&lcpl, H5Pclose);
    close_once(&dcpl, H5Pclose);
    close_once(&type, H5Tclose);
    close_once(&vspace, H5Sclose);
    close_once(&sspace, H5Sclose);
    close_once(&d, H5Dclose);
    if (!ok)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the dataset %s (row %llu of %s)", f->path, view,
                        (unsigned long long)row, source);
    return EKM_OK;
}

/* ---- reading ------------------------------------------------------- */

int ekm_h5_exists(ekm_h5_file *f, const char *name)
{
    return f && f->file >= 0 && H5Lexists(f->file, name, H5P_DEFAULT) > 0;
}

int ekm_h5_attr_exists(ekm_h5_file *f, const char *obj, const char *name)
{
    int owned;
    hid_t o = open_object(f, obj, &owned);
    int yes = o >= 0 && H5Aexists(o, name) > 0;
    if (owned)
        close_once(&o, H5Oclose);
    return yes;
}

static ekm_status read_dataset(ekm_h5_file *f, const char *name, hid_t memtype, size_t elem, int *rank,
                               size_t dims[EKM_H5_MAX_RANK], void **data, ekm_error *err)
{
    *data = NULL;
    *rank = 0;
    if (!ekm_h5_exists(f, name))
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", f->path, name);
    hid_t d = H5Dopen2(f->file, name, H5P_DEFAULT), space = -1;
    ekm_status st = EKM_OK;
    if (d < 0 || (space = H5Dget_space(d)) < 0) {
        st = EKM_FAIL(err, EKM_EINPUT, "%s: cannot open the dataset %s", f->path, name);
    } else {
        const int r = H5Sget_simple_extent_ndims(space);
        hsize_t hd[EKM_H5_MAX_RANK];
        if (r < 1 || r > EKM_H5_MAX_RANK || H5Sget_simple_extent_dims(space, hd, NULL) < 0) {
            st = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected 1 to %d dimensions", f->path, name,
                          EKM_H5_MAX_RANK);
        } else {
            size_t total = 1;
            for (int i = 0; i < r; i++) {
                dims[i] = (size_t)hd[i];
                total *= dims[i];
            }
            *rank = r;
            *data = malloc((total ? total : 1) * elem);
            if (!*data)
                st = EKM_FAIL(err, EKM_ENOMEM, "%s: dataset %s: out of memory", f->path, name);
            else if (total && H5Dread(d, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, *data) < 0)
                st = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected numbers", f->path, name);
        }
    }
    if (close_once(&space, H5Sclose) != 0 && st == EKM_OK)
        st = EKM_FAIL(err, EKM_EIO, "%s: dataset %s: cannot close", f->path, name);
    if (close_once(&d, H5Dclose) != 0 && st == EKM_OK)
        st = EKM_FAIL(err, EKM_EIO, "%s: dataset %s: cannot close", f->path, name);
    if (st != EKM_OK) {
        free(*data);
        *data = NULL;
        *rank = 0;
    }
    return st;
}

ekm_status ekm_h5_read_double(ekm_h5_file *f, const char *name, int *rank, size_t dims[EKM_H5_MAX_RANK],
                              double **data, ekm_error *err)
{
    void *p;
    ekm_status st = read_dataset(f, name, H5T_NATIVE_DOUBLE, sizeof(double), rank, dims, &p, err);
    *data = p;
    return st;
}

ekm_status ekm_h5_read_int(ekm_h5_file *f, const char *name, int *rank, size_t dims[EKM_H5_MAX_RANK],
                           int **data, ekm_error *err)
{
    void *p;
    ekm_status st = read_dataset(f, name, H5T_NATIVE_INT, sizeof(int), rank, dims, &p, err);
    *data = p;
    return st;
}

typedef enum { GET_STRING, GET_DOUBLE, GET_INT, GET_DOUBLE_ARRAY } get_kind;

/* One attribute read; out/size/cap/n by kind. */
static ekm_status get_attr(ekm_h5_file *f, const char *obj, const char *name, get_kind kind, void *out,
                           size_t size, size_t *n, ekm_error *err)
{
    char w[EKM_ATOMIC_PATH_MAX + 300];
    where(f, obj, w, sizeof w);
    int owned;
    hid_t o = open_object(f, obj, &owned);
    if (o < 0 || H5Aexists(o, name) <= 0) {
        const int no_object = o < 0;
        if (owned)
            close_once(&o, H5Oclose);
        if (no_object)
            return EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", f->path, obj);
        return EKM_FAIL(err, EKM_EINPUT, "%s: expected an attribute %s", w, name);
    }
    hid_t a = H5Aopen(o, name, H5P_DEFAULT), type = -1, space = -1, mt = -1;
    ekm_status st = EKM_OK;
    if (a < 0 || (type = H5Aget_type(a)) < 0 || (space = H5Aget_space(a)) < 0) {
        st = EKM_FAIL(err, EKM_EINPUT, "%s: cannot open the attribute %s", w, name);
        goto out;
    }
    const H5T_class_t cls = H5Tget_class(type);
    const hssize_t npoints = H5Sget_simple_extent_npoints(space);
    const int numeric = cls == H5T_FLOAT || cls == H5T_INTEGER;
    if (kind == GET_STRING && cls == H5T_STRING && !H5Tis_variable_str(type)) {
        const size_t len = H5Tget_size(type);
        char *tmp = malloc(len + 1);
        if (!tmp || (mt = H5Tcopy(H5T_C_S1)) < 0 || H5Tset_size(mt, len + 1) < 0 || H5Aread(a, mt, tmp) < 0)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: cannot read the attribute %s", w, name);
        else if (tmp[len] = '\0', strlen(tmp) >= size)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute %s: longer than %zu characters", w, name, size - 1);
        else
            memcpy(out, tmp, strlen(tmp) + 1);
        free(tmp);
    } else if (kind == GET_STRING && cls == H5T_STRING) {
        char *s = NULL;
        if ((mt = H5Tcopy(H5T_C_S1)) < 0 || H5Tset_size(mt, H5T_VARIABLE) < 0 || H5Aread(a, mt, &s) < 0 || !s)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: cannot read the attribute %s", w, name);
        else if (strlen(s) >= size)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute %s: longer than %zu characters", w, name, size - 1);
        else
            memcpy(out, s, strlen(s) + 1);
        if (s)
            H5free_memory(s);
    } else if (kind == GET_STRING && numeric && npoints == 1) {
        double v;
        if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: cannot read the attribute %s", w, name);
        else if (snprintf(out, size, "%.17g", v) >= (int)size)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute %s: longer than %zu characters", w, name, size - 1);
    } else if ((kind == GET_DOUBLE || kind == GET_INT) && numeric && npoints == 1 &&
               (kind == GET_DOUBLE || cls == H5T_INTEGER)) {
        if (H5Aread(a, kind == GET_DOUBLE ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT, out) < 0)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: cannot read the attribute %s", w, name);
    } else if (kind == GET_DOUBLE_ARRAY && numeric && npoints >= 0) {
        *n = (size_t)npoints;
        if ((size_t)npoints > size)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute %s: %lld values, expected at most %zu", w, name,
                          (long long)npoints, size);
        else if (npoints > 0 && H5Aread(a, H5T_NATIVE_DOUBLE, out) < 0)
            st = EKM_FAIL(err, EKM_EINPUT, "%s: cannot read the attribute %s", w, name);
    } else {
        static const char *const expected[] = {"a string or a number", "a number", "an integer", "numbers"};
        st = EKM_FAIL(err, EKM_EINPUT, "%s: attribute %s: expected %s", w, name, expected[kind]);
    }
out:
    close_once(&mt, H5Tclose);
    close_once(&space, H5Sclose);
    close_once(&type, H5Tclose);
    close_once(&a, H5Aclose);
    if (owned)
        close_once(&o, H5Oclose);
    return st;
}

ekm_status ekm_h5_attr_get_string(ekm_h5_file *f, const char *obj, const char *name, char *buf, size_t size,
                                  ekm_error *err)
{
    if (size == 0)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: attribute %s: no room for the value", f->path, name);
    return get_attr(f, obj, name, GET_STRING, buf, size, NULL, err);
}

ekm_status ekm_h5_attr_get_double(ekm_h5_file *f, const char *obj, const char *name, double *value,
                                  ekm_error *err)
{
    return get_attr(f, obj, name, GET_DOUBLE, value, 0, NULL, err);
}

ekm_status ekm_h5_attr_get_int(ekm_h5_file *f, const char *obj, const char *name, int *value, ekm_error *err)
{
    return get_attr(f, obj, name, GET_INT, value, 0, NULL, err);
}

ekm_status ekm_h5_attr_get_double_array(ekm_h5_file *f, const char *obj, const char *name, double *values,
                                        size_t cap, size_t *n, ekm_error *err)
{
    return get_attr(f, obj, name, GET_DOUBLE_ARRAY, values, cap, n, err);
}
