/* h5io.c: HDF5 writer and reader (see h5io.h). */
#include "h5io.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

struct cg_h5w {
  hid_t file;
  char *path;  /* final name */
  char *tmp;   /* temporary name */
};

struct cg_h5r {
  hid_t file;
  char *path;
};

void cg_h5_quiet(void) { H5Eset_auto2(H5E_DEFAULT, NULL, NULL); }

int cg_h5w_create(cg_h5w **out, const char *path, cg_error *err)
{
  *out = NULL;
  cg_h5w *w = calloc(1, sizeof *w);
  size_t n = strlen(path) + 32;
  if (w) {
    w->path = strdup(path);
    w->tmp = malloc(n);
  }
  if (!w || !w->path || !w->tmp) {
    if (w) { free(w->path); free(w->tmp); free(w); }
    return CG_ERROR(err, CG_ESYS, "%s: out of memory", path);
  }
  snprintf(w->tmp, n, "%s.tmp.%ld", path, (long)getpid());
  w->file = H5Fcreate(w->tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (w->file < 0) {
    free(w->path); free(w->tmp); free(w);
    return CG_ERROR(err, CG_ESYS, "%s: cannot create the output file", path);
  }
  *out = w;
  return CG_OK;
}

static int attr_str(hid_t obj, const char *name, const char *value)
{
  hid_t type = H5Tcopy(H5T_C_S1), space = H5Screate(H5S_SCALAR), a = -1;
  int ok = type >= 0 && space >= 0;
  if (ok) ok = H5Tset_size(type, strlen(value) + 1) >= 0;
  if (ok) ok = H5Tset_strpad(type, H5T_STR_NULLTERM) >= 0;
  if (ok) ok = (a = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0;
  if (ok) ok = H5Awrite(a, type, value) >= 0;
  if (a >= 0) H5Aclose(a);
  if (space >= 0) H5Sclose(space);
  if (type >= 0) H5Tclose(type);
  return ok;
}

int cg_h5w_dataset(cg_h5w *w, const char *name, const double *data, size_t nt, size_t n,
                   const char *units, cg_error *err)
{
  hsize_t dims[2] = {nt, n};
  int rank = 2;
  if (nt == 0) { dims[0] = n; rank = 1; }
  hid_t space = H5Screate_simple(rank, dims, NULL), d = -1;
  int ok = space >= 0;
  if (ok) ok = (d = H5Dcreate2(w->file, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT,
                               H5P_DEFAULT, H5P_DEFAULT)) >= 0;
  if (ok && (nt ? nt : 1) * n > 0) ok = H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0;
  if (ok && units) ok = attr_str(d, "units", units);
  if (d >= 0) H5Dclose(d);
  if (space >= 0) H5Sclose(space);
  if (!ok) return CG_ERROR(err, CG_ESYS, "%s: cannot write dataset %s", w->path, name);
  return CG_OK;
}

int cg_h5w_attr_str(cg_h5w *w, const char *name, const char *value, cg_error *err)
{
  if (!attr_str(w->file, name, value))
    return CG_ERROR(err, CG_ESYS, "%s: cannot write attribute %s", w->path, name);
  return CG_OK;
}

int cg_h5w_attr_double(cg_h5w *w, const char *name, double value, cg_error *err)
{
  hid_t space = H5Screate(H5S_SCALAR), a = -1;
  int ok = space >= 0;
  if (ok) ok = (a = H5Acreate2(w->file, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0;
  if (ok) ok = H5Awrite(a, H5T_NATIVE_DOUBLE, &value) >= 0;
  if (a >= 0) H5Aclose(a);
  if (space >= 0) H5Sclose(space);
  if (!ok) return CG_ERROR(err, CG_ESYS, "%s: cannot write attribute %s", w->path, name);
  return CG_OK;
}

static void h5w_release(cg_h5w *w)
{
  free(w->path);
  free(w->tmp);
  free(w);
}

int cg_h5w_commit(cg_h5w *w, cg_error *err)
{
  int ok = H5Fclose(w->file) >= 0;
  w->file = -1;
  if (ok && rename(w->tmp, w->path) == 0) {
    h5w_release(w);
    return CG_OK;
  }
  unlink(w->tmp);
  int rc = CG_ERROR(err, CG_ESYS, "%s: cannot write the output file", w->path);
  h5w_release(w);
  return rc;
}

void cg_h5w_abort(cg_h5w *w)
{
  if (!w) return;
  if (w->file >= 0) H5Fclose(w->file);
  unlink(w->tmp);
  h5w_release(w);
}

int cg_h5r_open(cg_h5r **out, const char *path, cg_error *err)
{
  *out = NULL;
  if (access(path, R_OK) != 0)
    return CG_ERROR(err, CG_EINPUT, "%s: cannot open: no such readable file", path);
  htri_t is = H5Fis_hdf5(path);
  if (is <= 0) return CG_ERROR(err, CG_EINPUT, "%s: expected an HDF5 file", path);
  cg_h5r *r = calloc(1, sizeof *r);
  if (!r || !(r->path = strdup(path))) {
    free(r);
    return CG_ERROR(err, CG_ESYS, "out of memory");
  }
  r->file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (r->file < 0) {
    free(r->path);
    free(r);
    return CG_ERROR(err, CG_EINPUT, "%s: cannot open as HDF5", path);
  }
  *out = r;
  return CG_OK;
}

void cg_h5r_close(cg_h5r *r)
{
  if (!r) return;
  if (r->file >= 0) H5Fclose(r->file);
  free(r->path);
  free(r);
}

int cg_h5r_has(cg_h5r *r, const char *name)
{
  return H5Lexists(r->file, name, H5P_DEFAULT) > 0;
}

int cg_h5r_read(cg_h5r *r, const char *name, double **data, size_t *nt, size_t *n,
                cg_error *err)
{
  *data = NULL;
  if (!cg_h5r_has(r, name))
    return CG_ERROR(err, CG_EINPUT, "%s: expected a dataset %s", r->path, name);
  hid_t d = H5Dopen2(r->file, name, H5P_DEFAULT), space = -1;
  int rc = CG_OK;
  if (d < 0 || (space = H5Dget_space(d)) < 0) {
    rc = CG_ERROR(err, CG_EINPUT, "%s: cannot open dataset %s", r->path, name);
    goto out;
  }
  int rank = H5Sget_simple_extent_ndims(space);
  hsize_t dims[2] = {0, 0};
  if (rank < 1 || rank > 2 || H5Sget_simple_extent_dims(space, dims, NULL) < 0) {
    rc = CG_ERROR(err, CG_EINPUT, "%s: dataset %s: expected 1 or 2 dimensions", r->path, name);
    goto out;
  }
  *nt = rank == 2 ? dims[0] : 0;
  *n = rank == 2 ? dims[1] : dims[0];
  size_t total = (rank == 2 ? dims[0] : 1) * (*n);
  *data = malloc((total ? total : 1) * sizeof **data);
  if (!*data) {
    rc = CG_ERROR(err, CG_ESYS, "out of memory");
    goto out;
  }
  if (total && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, *data) < 0) {
    free(*data);
    *data = NULL;
    rc = CG_ERROR(err, CG_EINPUT, "%s: dataset %s: expected numbers", r->path, name);
  }
out:
  if (space >= 0) H5Sclose(space);
  if (d >= 0) H5Dclose(d);
  return rc;
}

int cg_h5r_attr_str(cg_h5r *r, const char *name, char *buf, size_t size)
{
  if (size == 0 || H5Aexists(r->file, name) <= 0) return 1;
  hid_t a = H5Aopen(r->file, name, H5P_DEFAULT);
  if (a < 0) return 1;
  hid_t type = H5Aget_type(a);
  int rc = 1;
  if (type >= 0 && H5Tget_class(type) == H5T_STRING && !H5Tis_variable_str(type)) {
    size_t len = H5Tget_size(type);
    char *tmp = malloc(len + 1);
    hid_t mt = H5Tcopy(H5T_C_S1);
    if (tmp && mt >= 0 && H5Tset_size(mt, len + 1) >= 0 && H5Aread(a, mt, tmp) >= 0) {
      tmp[len] = '\0';
      snprintf(buf, size, "%s", tmp);
      rc = 0;
    }
    if (mt >= 0) H5Tclose(mt);
    free(tmp);
  } else if (type >= 0 && H5Tget_class(type) == H5T_STRING) {
    char *s = NULL;
    hid_t mt = H5Tcopy(H5T_C_S1);
    H5Tset_size(mt, H5T_VARIABLE);
    if (H5Aread(a, mt, &s) >= 0 && s) {
      snprintf(buf, size, "%s", s);
      H5free_memory(s);
      rc = 0;
    }
    H5Tclose(mt);
  } else if (type >= 0 && (H5Tget_class(type) == H5T_FLOAT || H5Tget_class(type) == H5T_INTEGER)) {
    double v;
    if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) >= 0) {
      snprintf(buf, size, "%.17g", v);
      rc = 0;
    }
  }
  if (type >= 0) H5Tclose(type);
  H5Aclose(a);
  return rc;
}
