#include "h5out.h"
#include "ekm_version.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "fields.h"

enum { F_PHI, F_VX, F_VZ, F_T, F_P, F_SXZ, F_SZZ, F_REGIME, N_FIELDS };

static const struct {
    const char *name;
    const char *units;
} FIELDS[N_FIELDS] = {
    {"phi", "1"}, {"vx", "m/s"}, {"vz", "m/s"}, {"T", "m^2/s^2"}, {"P", "Pa"},
    {"sxz", "Pa"}, {"szz", "Pa"}, {"regime", "1 (0 empty, 1 kinetic, 2 dense flow, 3 solid)"},
};

struct ekm_h5_writer {
    char path[1024];
    char tmp_path[1040];
    const ekm_scenario *sc;
    hid_t file;
    hid_t dset_t;
    hid_t dset[N_FIELDS];
    hsize_t nt, nz;
    double *buf[N_FIELDS - 1];
    int *regime;
    double *times; /* nt, for the XDMF sidecar */
    size_t times_cap;
};

static ekm_status set_string_attr(hid_t obj, const char *name, const char *value)
{
    hid_t type = H5Tcopy(H5T_C_S1);
    if (type < 0)
        return EKM_EIO;
    H5Tset_size(type, strlen(value) + 1);
    H5Tset_strpad(type, H5T_STR_NULLTERM);
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t attr = space >= 0 ? H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT) : -1;
    herr_t rc = attr >= 0 ? H5Awrite(attr, type, value) : -1;
    if (attr >= 0) H5Aclose(attr);
    if (space >= 0) H5Sclose(space);
    H5Tclose(type);
    return rc < 0 ? EKM_EIO : EKM_OK;
}

static ekm_status set_double_attr(hid_t obj, const char *name, double value)
{
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t attr = space >= 0 ? H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT) : -1;
    herr_t rc = attr >= 0 ? H5Awrite(attr, H5T_NATIVE_DOUBLE, &value) : -1;
    if (attr >= 0) H5Aclose(attr);
    if (space >= 0) H5Sclose(space);
    return rc < 0 ? EKM_EIO : EKM_OK;
}

static int parse_number(const char *v, double *out)
{
    char *end;
    double x = strtod(v, &end);
    if (end == v || *end != '\0' || !isfinite(x))
        return 0;
    *out = x;
    return 1;
}

static hid_t create_series(hid_t file, const char *name, hid_t type, hsize_t nz, const char *units)
{
    hsize_t dims[2] = {0, nz}, maxdims[2] = {H5S_UNLIMITED, nz}, chunk[2] = {1, nz};
    int rank = nz ? 2 : 1;
    if (!nz) { dims[0] = 0; maxdims[0] = H5S_UNLIMITED; chunk[0] = 64; }
    hid_t space = H5Screate_simple(rank, dims, maxdims);
    hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
    if (space < 0 || plist < 0 || H5Pset_chunk(plist, rank, chunk) < 0) {
        if (space >= 0) H5Sclose(space);
        if (plist >= 0) H5Pclose(plist);
        return -1;
    }
    hid_t d = H5Dcreate2(file, name, type, space, H5P_DEFAULT, plist, H5P_DEFAULT);
    H5Sclose(space);
    H5Pclose(plist);
    if (d >= 0 && set_string_attr(d, "units", units) != EKM_OK) {
        H5Dclose(d);
        return -1;
    }
    return d;
}

static ekm_status write_root_attributes(hid_t file, const ekm_scenario *sc)
{
    ekm_status rc = EKM_OK;
    for (size_t i = 0; i < sc->n_entries && rc == EKM_OK; i++) {
        double x;
        if (parse_number(sc->entries[i].value, &x))
            rc = set_double_attr(file, sc->entries[i].name, x);
        else
            rc = set_string_attr(file, sc->entries[i].name, sc->entries[i].value);
    }
    char created[32];
    time_t now = time(NULL);
    strftime(created, sizeof created, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    if (rc == EKM_OK) rc = set_double_attr(file, "gravity_x", ekm_scenario_gravity_x(sc));
    if (rc == EKM_OK) rc = set_double_attr(file, "gravity_z", ekm_scenario_gravity_z(sc));
    if (rc == EKM_OK) rc = set_string_attr(file, "variant", sc->variant == EKM_VARIANT_THESIS ? "thesis" : "full");
    if (rc == EKM_OK) rc = set_string_attr(file, "code_version", EKMBENCH_VERSION);
    if (rc == EKM_OK) rc = set_string_attr(file, "scenario_file", sc->source);
    if (rc == EKM_OK) rc = set_string_attr(file, "scenario", sc->name);
    if (rc == EKM_OK) rc = set_string_attr(file, "created", created);
    return rc;
}

static void close_all(ekm_h5_writer *w)
{
    for (int f = 0; f < N_FIELDS; f++)
        if (w->dset[f] >= 0) { H5Dclose(w->dset[f]); w->dset[f] = -1; }
    if (w->dset_t >= 0) { H5Dclose(w->dset_t); w->dset_t = -1; }
    if (w->file >= 0) { H5Fclose(w->file); w->file = -1; }
}

static void free_writer(ekm_h5_writer *w)
{
    for (int f = 0; f < N_FIELDS - 1; f++)
        free(w->buf[f]);
    free(w->regime);
    free(w->times);
    free(w);
}

void ekm_h5_writer_abort(ekm_h5_writer *w)
{
    if (!w)
        return;
    close_all(w);
    unlink(w->tmp_path);
    free_writer(w);
}

ekm_status ekm_h5_writer_open(ekm_h5_writer **out, const char *path, const ekm_scenario *sc,
                              const ekm_state *s, ekm_error *err)
{
    *out = NULL;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    ekm_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s", path);
    w->file = w->dset_t = -1;
    for (int f = 0; f < N_FIELDS; f++)
        w->dset[f] = -1;
    if (strlen(path) >= sizeof w->path) {
        free_writer(w);
        return EKM_FAIL(err, EKM_EINPUT, "%s: output path too long", path);
    }
    snprintf(w->path, sizeof w->path, "%s", path);
    snprintf(w->tmp_path, sizeof w->tmp_path, "%s.tmp", path);
    w->sc = sc;
    w->nz = (hsize_t)s->n;
    for (int f = 0; f < N_FIELDS - 1; f++)
        if (!(w->buf[f] = malloc(w->nz * sizeof(double)))) {
            free_writer(w);
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s", path);
        }
    if (!(w->regime = malloc(w->nz * sizeof(int)))) {
        free_writer(w);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory opening %s", path);
    }
    w->file = H5Fcreate(w->tmp_path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (w->file < 0) {
        free_writer(w);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot create output file", w->tmp_path);
    }
    hsize_t dz = w->nz;
    hid_t space = H5Screate_simple(1, &dz, NULL);
    hid_t d = space >= 0 ? H5Dcreate2(w->file, "z", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1;
    int ok = d >= 0 && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s->z) >= 0 &&
             set_string_attr(d, "units", "m") == EKM_OK;
    if (d >= 0) H5Dclose(d);
    if (space >= 0) H5Sclose(space);
    w->dset_t = create_series(w->file, "t", H5T_NATIVE_DOUBLE, 0, "s");
    for (int f = 0; f < N_FIELDS && ok; f++) {
        w->dset[f] = create_series(w->file, FIELDS[f].name, f == F_REGIME ? H5T_NATIVE_INT32 : H5T_NATIVE_DOUBLE,
                                   w->nz, FIELDS[f].units);
        ok = w->dset[f] >= 0;
    }
    if (!ok || w->dset_t < 0 || write_root_attributes(w->file, sc) != EKM_OK) {
        ekm_h5_writer_abort(w);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output layout", path);
    }
    *out = w;
    return EKM_OK;
}

static int append_row(hid_t dset, hid_t memtype, hsize_t row, hsize_t nz, const void *data)
{
    hsize_t dims[2] = {row + 1, nz}, start[2] = {row, 0}, count[2] = {1, nz};
    int rank = nz ? 2 : 1;
    if (!nz) { dims[0] = row + 1; start[0] = row; count[0] = 1; }
    if (H5Dset_extent(dset, dims) < 0)
        return 0;
    hid_t fspace = H5Dget_space(dset);
    hid_t mspace = H5Screate_simple(rank, count, NULL);
    int ok = fspace >= 0 && mspace >= 0 &&
             H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
             H5Dwrite(dset, memtype, mspace, fspace, H5P_DEFAULT, data) >= 0;
    if (fspace >= 0) H5Sclose(fspace);
    if (mspace >= 0) H5Sclose(mspace);
    return ok;
}

ekm_status ekm_h5_writer_append(ekm_h5_writer *w, const ekm_state *s, ekm_error *err)
{
    ekm_fields fl = {.vx = w->buf[F_VX], .vz = w->buf[F_VZ], .P = w->buf[F_P],
                     .sxz = w->buf[F_SXZ], .szz = w->buf[F_SZZ], .regime = w->regime};
    ekm_fields_compute(w->sc, s, s->t, &fl);
    memcpy(w->buf[F_PHI], s->phi, w->nz * sizeof(double));
    memcpy(w->buf[F_T], s->T, w->nz * sizeof(double));
    for (int f = 0; f < N_FIELDS - 1; f++)
        for (hsize_t j = 0; j < w->nz; j++)
            if (!isfinite(w->buf[f][j]))
                return EKM_FAIL(err, EKM_ENUMERIC, "t = %g s, cell %llu (z = %g m): field %s is not finite (%g); "
                                "nothing written", s->t, (unsigned long long)j, s->z[j], FIELDS[f].name, w->buf[f][j]);
    if (w->nt == w->times_cap) {
        size_t cap = w->times_cap ? 2 * w->times_cap : 64;
        double *t = realloc(w->times, cap * sizeof *t);
        if (!t)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory writing %s", w->path);
        w->times = t;
        w->times_cap = cap;
    }
    w->times[w->nt] = s->t;
    int ok = append_row(w->dset_t, H5T_NATIVE_DOUBLE, w->nt, 0, &s->t);
    for (int f = 0; f < N_FIELDS && ok; f++)
        ok = append_row(w->dset[f], f == F_REGIME ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE, w->nt, w->nz,
                        f == F_REGIME ? (const void *)w->regime : (const void *)w->buf[f]);
    if (!ok)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot append output at t = %g s", w->tmp_path, s->t);
    w->nt++;
    return EKM_OK;
}

void ekm_h5_xdmf_path(const char *h5_path, char *out, size_t size)
{
    size_t len = strlen(h5_path);
    if (len > 3 && strcmp(h5_path + len - 3, ".h5") == 0)
        snprintf(out, size, "%.*s.xdmf", (int)(len - 3), h5_path);
    else
        snprintf(out, size, "%s.xdmf", h5_path);
}

static ekm_status write_xdmf(const ekm_h5_writer *w, const char *xdmf_tmp, ekm_error *err)
{
    const char *base = strrchr(w->path, '/');
    base = base ? base + 1 : w->path;
    FILE *fp = fopen(xdmf_tmp, "w");
    if (!fp)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot create XDMF sidecar", xdmf_tmp);
    const unsigned long long nt = w->nt, nz = w->nz;
    const double dz = w->sc->length / (double)w->nz;
    fprintf(fp, "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
                "<!-- ekm output %s: slab fields along z, shown along the mesh x axis -->\n"
                "<Xdmf Version=\"2.0\">\n <Domain>\n"
                "  <Grid Name=\"%s\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
            base, w->sc->name);
    for (unsigned long long i = 0; i < nt; i++) {
        fprintf(fp, "   <Grid Name=\"frame%llu\" GridType=\"Uniform\">\n"
                    "    <Time Value=\"%.17g\"/>\n"
                    "    <Topology TopologyType=\"2DCoRectMesh\" Dimensions=\"1 %llu\"/>\n"
                    "    <Geometry GeometryType=\"ORIGIN_DXDY\">\n"
                    "     <DataItem Dimensions=\"2\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">0 %.17g</DataItem>\n"
                    "     <DataItem Dimensions=\"2\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">1 %.17g</DataItem>\n"
                    "    </Geometry>\n",
                i, w->times[i], nz, 0.5 * dz, dz);
        for (int f = 0; f < N_FIELDS; f++) {
            fprintf(fp, "    <Attribute Name=\"%s\" AttributeType=\"Scalar\" Center=\"Node\">\n"
                        "     <DataItem ItemType=\"HyperSlab\" Dimensions=\"1 %llu\" Type=\"HyperSlab\">\n"
                        "      <DataItem Dimensions=\"3 2\" Format=\"XML\">%llu 0 1 1 1 %llu</DataItem>\n"
                        "      <DataItem Dimensions=\"%llu %llu\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">%s:/%s</DataItem>\n"
                        "     </DataItem>\n    </Attribute>\n",
                    FIELDS[f].name, nz, i, nz, nt, nz, f == F_REGIME ? "Int" : "Float", f == F_REGIME ? 4 : 8,
                    base, FIELDS[f].name);
        }
        fprintf(fp, "   </Grid>\n");
    }
    fprintf(fp, "  </Grid>\n </Domain>\n</Xdmf>\n");
    if (fclose(fp) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write XDMF sidecar", xdmf_tmp);
    return EKM_OK;
}

ekm_status ekm_h5_writer_set_attr(ekm_h5_writer *w, const char *name, double value, ekm_error *err)
{
    if (set_double_attr(w->file, name, value) != EKM_OK)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the attribute %s", w->path, name);
    return EKM_OK;
}

ekm_status ekm_h5_writer_commit(ekm_h5_writer *w, ekm_error *err)
{
    char xdmf[1100], xdmf_tmp[1110];
    ekm_h5_xdmf_path(w->path, xdmf, sizeof xdmf);
    snprintf(xdmf_tmp, sizeof xdmf_tmp, "%s.tmp", xdmf);
    close_all(w);
    ekm_status rc = write_xdmf(w, xdmf_tmp, err);
    if (rc == EKM_OK && rename(w->tmp_path, w->path) != 0)
        rc = EKM_FAIL(err, EKM_EIO, "%s: cannot rename the finished output into place", w->path);
    if (rc == EKM_OK && rename(xdmf_tmp, xdmf) != 0)
        rc = EKM_FAIL(err, EKM_EIO, "%s: cannot rename the XDMF sidecar into place", xdmf);
    if (rc != EKM_OK) {
        unlink(w->tmp_path);
        unlink(xdmf_tmp);
    }
    free_writer(w);
    return rc;
}
