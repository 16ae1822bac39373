/* xdmf.c: the XDMF sidecar of a profile time series (see xdmf.h). */
#include "xdmf.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "atomic.h"
#include "utf8.h"

void ekm_xdmf_path(const char *h5_path, char *out, size_t size)
{
    const size_t len = strlen(h5_path);
    if (len > 3 && strcmp(h5_path + len - 3, ".h5") == 0)
        snprintf(out, size, "%.*s.xdmf", (int)(len - 3), h5_path);
    else
        snprintf(out, size, "%s.xdmf", h5_path);
}

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

ekm_status ekm_xdmf_check_name(const char *h5_path, const char *opt, ekm_error *err)
{
    const unsigned char *base = (const unsigned char *)base_name(h5_path);
    for (const unsigned char *s = base; *s;) {
        unsigned int cp = 0;
        const size_t len = *s < 0x80 ? 1 : ekm_utf8_sequence(s, &cp);
        if (*s < 0x20 || *s == 0x7F || len == 0 || cp == 0xFFFE || cp == 0xFFFF)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "%s: expected an output name its XDMF sidecar can name (UTF-8 without control "
                            "characters), got byte 0x%02X at byte %zu of the name",
                            opt, (unsigned)*s, (size_t)(s - base) + 1);
        s += len;
    }
    return EKM_OK;
}

void ekm_xdmf_escape(FILE *fp, const char *text)
{
    const unsigned char *s = (const unsigned char *)text;
    while (*s) {
        switch (*s) {
        case '&': fputs("&amp;", fp); break;
        case '<': fputs("&lt;", fp); break;
        case '>': fputs("&gt;", fp); break;
        case '"': fputs("&quot;", fp); break;
        case '\'': fputs("&apos;", fp); break;
        default:
            if (*s < 0x20) { /* tab, newline included: not kept in a name */
                fputc('?', fp);
            } else {
                unsigned int cp;
                const size_t len = ekm_utf8_sequence(s, &cp);
                if (len == 0 || cp == 0xFFFE || cp == 0xFFFF) { /* not XML characters */
                    fputc('?', fp);
                } else {
                    fwrite(s, 1, len, fp);
                    s += len - 1;
                }
            }
        }
        s++;
    }
}

ekm_status ekm_xdmf_add_views(ekm_h5_file *f, const ekm_xdmf_series *s, ekm_error *err)
{
    char view[256];
    for (size_t k = 0; k < s->nfields; k++)
        for (size_t i = 0; i < s->nt; i++) {
            snprintf(view, sizeof view, "xdmf/%s/%zu", s->fields[k].name, i);
            ekm_status st = ekm_h5_row_view(f, view, s->fields[k].name, i, err);
            if (st != EKM_OK)
                return st;
        }
    return EKM_OK;
}

/* The 2D grid (s->nx > 0): n x nx cells in ParaView's Z-X plane. */
static void write_grid2d(FILE *fp, const ekm_xdmf_series *s)
{
    const char *base = base_name(s->h5_path);
    fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
          "<!-- 2D grid: x along ParaView's X, z along its Z, one cell thick in Y (the averaged\n"
          "     direction); every field cell-centred (docs/compare.md) -->\n"
          "<Xdmf Version=\"2.0\">\n <Domain>\n  <Grid Name=\"",
          fp);
    ekm_xdmf_escape(fp, s->title);
    fputs("\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", fp);
    for (size_t i = 0; i < s->nt; i++) {
        fprintf(fp,
                "   <Grid Name=\"frame%zu\" GridType=\"Uniform\">\n"
                "    <Time Value=\"%.17g\"/>\n"
                "    <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"%zu 2 %zu\"/>\n"
                "    <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
                "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
                "%.17g 0 %.17g</DataItem>\n"
                "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
                "%.17g %.17g %.17g</DataItem>\n"
                "    </Geometry>\n",
                i, s->t[i], s->n + 1, s->nx + 1, s->lo[i], s->x0, s->dz[i], s->dx, s->dx);
        for (size_t k = 0; k < s->nfields; k++) {
            const ekm_xdmf_field *fl = &s->fields[k];
            fputs("    <Attribute Name=\"", fp);
            ekm_xdmf_escape(fp, fl->name);
            fprintf(fp,
                    "\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                    "     <DataItem Dimensions=\"%zu 1 %zu\" NumberType=\"%s\" Precision=\"%d\" "
                    "Format=\"HDF\">",
                    s->n, s->nx, fl->is_int ? "Int" : "Float", fl->is_int ? 4 : 8);
            ekm_xdmf_escape(fp, base);
            fputs(":/xdmf/", fp);
            ekm_xdmf_escape(fp, fl->name);
            fprintf(fp, "/%zu</DataItem>\n    </Attribute>\n", i);
        }
        fputs("   </Grid>\n", fp);
    }
    fputs("  </Grid>\n </Domain>\n</Xdmf>\n", fp);
}

void ekm_xdmf_write(FILE *fp, const ekm_xdmf_series *s)
{
    if (s->nx > 0) {
        write_grid2d(fp, s);
        return;
    }
    const char *base = base_name(s->h5_path);
    fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
          "<!-- profile along ParaView's Z axis (the slab normal z): one column of cells, one cell\n"
          "     wide in X and Y; every field cell-centred (docs/output-format.md) -->\n"
          "<Xdmf Version=\"2.0\">\n <Domain>\n  <Grid Name=\"",
          fp);
    ekm_xdmf_escape(fp, s->title);
    fputs("\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", fp);
    for (size_t i = 0; i < s->nt; i++) {
        /* 3DCoRectMesh: dimensions, origin and spacing in the order Z Y X */
        fprintf(fp,
                "   <Grid Name=\"frame%zu\" GridType=\"Uniform\">\n"
                "    <Time Value=\"%.17g\"/>\n"
                "    <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"%zu 2 2\"/>\n"
                "    <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
                "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
                "%.17g 0 0</DataItem>\n"
                "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
                "%.17g %.17g %.17g</DataItem>\n"
                "    </Geometry>\n",
                i, s->t[i], s->n + 1, s->lo[i], s->dz[i], s->dz[i], s->dz[i]);
        for (size_t k = 0; k < s->nfields; k++) {
            const ekm_xdmf_field *fl = &s->fields[k];
            fputs("    <Attribute Name=\"", fp);
            ekm_xdmf_escape(fp, fl->name);
            fprintf(fp,
                    "\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                    "     <DataItem Dimensions=\"%zu\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">",
                    s->n, fl->is_int ? "Int" : "Float", fl->is_int ? 4 : 8);
            ekm_xdmf_escape(fp, base);
            fputs(":/xdmf/", fp);
            ekm_xdmf_escape(fp, fl->name);
            fprintf(fp, "/%zu</DataItem>\n    </Attribute>\n", i);
        }
        fputs("   </Grid>\n", fp);
    }
    fputs("  </Grid>\n </Domain>\n</Xdmf>\n", fp);
}

ekm_status ekm_xdmf_commit_with(ekm_h5_file *h5, const ekm_xdmf_series *s, ekm_error *err)
{
    char xdmf[EKM_ATOMIC_PATH_MAX + 8];
    ekm_xdmf_path(s->h5_path, xdmf, sizeof xdmf);
    ekm_status st = ekm_xdmf_add_views(h5, s, err);
    if (st != EKM_OK) {
        ekm_h5_abort(h5);
        return st;
    }
    ekm_atomic data, sidecar;
    st = ekm_h5_finish(h5, &data, err); /* frees h5 */
    if (st != EKM_OK)
        return st;
    st = ekm_atomic_open(&sidecar, xdmf, err);
    if (st != EKM_OK) {
        ekm_atomic_abort(&data);
        return st;
    }
    ekm_xdmf_write(sidecar.fp, s);
    st = ekm_atomic_finish(&sidecar, err);
    if (st != EKM_OK) {
        ekm_atomic_abort(&data);
        return st;
    }
    /* both complete on disk: rename the data, then the sidecar.  A data
     * rename that failed leaves the old pair as it was.  Once the data are
     * renamed (also when only the directory's fsync failed after it) the
     * old sidecar no longer describes them: the new one is renamed too, or,
     * if that fails, the old one removed; the first error is returned. */
    st = ekm_atomic_commit(&data, err);
    if (st != EKM_OK && !data.renamed) {
        ekm_atomic_abort(&sidecar);
        return st;
    }
    ekm_error sidecar_err;
    const ekm_status sidecar_st = ekm_atomic_commit(&sidecar, st == EKM_OK ? err : &sidecar_err);
    if (sidecar_st != EKM_OK && !sidecar.renamed)
        unlink(xdmf); /* the old sidecar, of the old data */
    return st != EKM_OK ? st : sidecar_st;
}

ekm_status ekm_xdmf_commit_fixed(ekm_h5_file *h5, const ekm_xdmf_series *s, double lo, double dz,
                                 ekm_error *err)
{
    const size_t n = s->nt ? s->nt : 1;
    double *los = malloc(n * sizeof *los), *dzs = malloc(n * sizeof *dzs);
    if (!los || !dzs) {
        free(los);
        free(dzs);
        ekm_h5_abort(h5);
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory writing the XDMF sidecar", s->h5_path);
    }
    for (size_t i = 0; i < n; i++) {
        los[i] = lo;
        dzs[i] = dz;
    }
    ekm_xdmf_series fixed = *s;
    fixed.lo = los;
    fixed.dz = dzs;
    const ekm_status st = ekm_xdmf_commit_with(h5, &fixed, err);
    free(los);
    free(dzs);
    return st;
}
