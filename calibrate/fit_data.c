/* fit_data.c: a rheology point from an ekmcompare cg output (fit_data.h). */
#include "fit_data.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "h5.h"

static const char *const field_names[CG_FIT_NFIELD] = {"P", "sxz", "T", "mu"};

const char *cg_fit_field_name(int f)
{
    return f >= 0 && f < CG_FIT_NFIELD ? field_names[f] : "?";
}

/* Plain mean of a profile and the mean of its SEs; every bin finite. */
static ekm_status profile_mean(const char *file, const char *name, const double *v, const double *se,
                               size_t n, int need_se, double *mean, double *mean_se, ekm_error *err)
{
    double s = 0.0, sse = 0.0;
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(v[k]))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: %s: bin %zu is not a number (an empty bin?): expected a filled "
                            "homogeneous profile",
                            file, name, k);
        s += v[k];
        if (se) {
            if (need_se && !(isfinite(se[k]) && se[k] > 0.0))
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: %s_se: bin %zu is %g: expected standard errors > 0 (a window "
                                "of at least two snapshots)",
                                file, name, k, se[k]);
            sse += se[k];
        }
    }
    *mean = s / (double)n;
    *mean_se = se ? sse / (double)n : NAN;
    return EKM_OK;
}

ekm_status cg_fit_point_from_profiles(const char *file, const cg_fit_profiles *pr, unsigned fields,
                                      cg_fit_point *pt, ekm_error *err)
{
    memset(pt, 0, sizeof *pt);
    snprintf(pt->file, sizeof pt->file, "%s", file);
    pt->nbins = pr->n;
    for (int f = 0; f < CG_FIT_NFIELD; f++)
        pt->value[f] = pt->se[f] = NAN;
    const size_t n = pr->n;
    if (n < 3)
        return EKM_FAIL(err, EKM_EINPUT, "%s: %zu bins: expected at least 3 (a slope and its linearity)",
                        file, n);
    ekm_status st = profile_mean(file, "phi", pr->phi, pr->phi_se, n, 0, &pt->phi, &pt->phi_se, err);
    if (st != EKM_OK)
        return st;
    for (int f = 0; f < CG_FIT_NFIELD; f++) {
        if (!(fields & (1u << f)))
            continue;
        if (!pr->f[f] || !pr->se[f])
            return EKM_FAIL(err, EKM_EINPUT, "%s: expected datasets %s and %s_se (a cg output%s)", file,
                            field_names[f], field_names[f],
                            f == CG_FIT_P || f == CG_FIT_SXZ || f == CG_FIT_MU ? " with --stress or --pairs"
                                                                               : "");
        st = profile_mean(file, field_names[f], pr->f[f], pr->se[f], n, 1, &pt->value[f], &pt->se[f], err);
        if (st != EKM_OK)
            return st;
        if (f == CG_FIT_SXZ)
            pt->value[f] = fabs(pt->value[f]);
    }
    /* vx = a + b z by least squares; R^2 and the SE of b from the scatter. */
    double zbar = 0.0, vbar = 0.0;
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(pr->z[k]) || !isfinite(pr->vx[k]))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: vx: bin %zu is not a number (an empty bin?): expected a filled "
                            "homogeneous profile",
                            file, k);
        zbar += pr->z[k];
        vbar += pr->vx[k];
    }
    zbar /= (double)n;
    vbar /= (double)n;
    double szz = 0.0, szv = 0.0, svv = 0.0;
    for (size_t k = 0; k < n; k++) {
        const double dz = pr->z[k] - zbar, dv = pr->vx[k] - vbar;
        szz += dz * dz;
        szv += dz * dv;
        svv += dv * dv;
    }
    const double b = szv / szz;
    double ss_res = 0.0;
    for (size_t k = 0; k < n; k++) {
        const double e = pr->vx[k] - vbar - b * (pr->z[k] - zbar);
        ss_res += e * e;
    }
    pt->r2 = svv > 0.0 ? 1.0 - ss_res / svv : 0.0;
    pt->gdot = fabs(b);
    pt->gdot_se = sqrt(ss_res / (double)(n - 2) / szz);
    if (!(pt->r2 >= CG_FIT_MIN_R2) || !(pt->gdot > 0.0))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: vx is not linear in the axis coordinate (R^2 = %.4f of the "
                        "least-squares line, expected >= %.3f): not homogeneous simple shear",
                        file, pt->r2, CG_FIT_MIN_R2);
    return EKM_OK;
}

/* The profile of one field: [nt][n] with nt == 1 or [n]; NULL if absent
 * and not required. */
static ekm_status read_profile(ekm_h5_file *r, const char *file, const char *name, int required,
                               size_t n_expect, double **out, size_t *n_out, ekm_error *err)
{
    *out = NULL;
    if (!ekm_h5_exists(r, name)) {
        if (required)
            return EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s (an ekmcompare cg output)", file,
                            name);
        return EKM_OK;
    }
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    ekm_status rc = ekm_h5_read_double(r, name, &rank, dims, out, err);
    if (rc != EKM_OK)
        return rc;
    if (rank > 2) {
        free(*out);
        *out = NULL;
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected 1 or 2 dimensions", file, name);
    }
    const size_t nt = rank == 2 ? dims[0] : 1, n = rank == 2 ? dims[1] : dims[0];
    if (nt > 1) {
        free(*out);
        *out = NULL;
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: dataset %s has %zu windows: expected one steady window (a cg "
                        "output without --every/--window)",
                        file, name, nt);
    }
    if (n_expect && n != n_expect) {
        free(*out);
        *out = NULL;
        return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s has %zu bins: expected %zu as the coordinate", file,
                        name, n, n_expect);
    }
    if (n_out)
        *n_out = n;
    return EKM_OK;
}

ekm_status cg_fit_point_read(const char *file, unsigned fields, cg_fit_point *pt, ekm_error *err)
{
    struct stat sb;
    if (stat(file, &sb) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: %s", file, strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: not a regular file", file);
    ekm_h5_file *r;
    ekm_status ost = ekm_h5_open(&r, file, err);
    if (ost != EKM_OK)
        return ost;
    char axis[16] = "z";
    ekm_error aerr = {0};
    if (!ekm_h5_attr_exists(r, NULL, "axis") ||
        ekm_h5_attr_get_string(r, NULL, "axis", axis, sizeof axis, &aerr) != EKM_OK ||
        (strcmp(axis, "x") && strcmp(axis, "y") && strcmp(axis, "z")))
        snprintf(axis, sizeof axis, "z");
    enum { Z, PHI, PHI_SE, VX, VX_SE, NBASE };
    const char *base_names[NBASE] = {axis, "phi", "phi_se", "vx", "vx_se"};
    double *base[NBASE] = {NULL};
    double *fv[CG_FIT_NFIELD] = {NULL}, *fse[CG_FIT_NFIELD] = {NULL};
    size_t n = 0;
    ekm_status st = read_profile(r, file, axis, 1, 0, &base[Z], &n, err);
    for (int q = PHI; q < NBASE && st == EKM_OK; q++)
        st = read_profile(r, file, base_names[q], q == PHI || q == VX, n, &base[q], NULL, err);
    for (int f = 0; f < CG_FIT_NFIELD && st == EKM_OK; f++) {
        if (!(fields & (1u << f)))
            continue;
        char se_name[32];
        snprintf(se_name, sizeof se_name, "%s_se", field_names[f]);
        st = read_profile(r, file, field_names[f], 0, n, &fv[f], NULL, err);
        if (st == EKM_OK)
            st = read_profile(r, file, se_name, 0, n, &fse[f], NULL, err);
    }
    ekm_h5_close(r);
    if (st == EKM_OK) {
        cg_fit_profiles pr = {.n = n,
                              .z = base[Z],
                              .phi = base[PHI],
                              .phi_se = base[PHI_SE],
                              .vx = base[VX],
                              .vx_se = base[VX_SE]};
        for (int f = 0; f < CG_FIT_NFIELD; f++) {
            pr.f[f] = fv[f];
            pr.se[f] = fse[f];
        }
        st = cg_fit_point_from_profiles(file, &pr, fields, pt, err);
    }
    for (int q = 0; q < NBASE; q++)
        free(base[q]);
    for (int f = 0; f < CG_FIT_NFIELD; f++) {
        free(fv[f]);
        free(fse[f]);
    }
    return st;
}
