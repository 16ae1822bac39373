/* cg_output.c: HDF5 and CSV outputs of `ekmcompare cg` (see cg_output.h). */
#include "ekm_version.h"
#include "cg_output.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "h5.h"
#include "xdmf.h"

static const char *const axis_names[3] = {"x", "y", "z"};

/* A dataset [n] (nt == 0) or [nt][n] with its units from the field schema. */
static ekm_status dataset(ekm_h5_file *w, const char *name, const double *data, size_t nt, size_t n,
                          ekm_error *err)
{
    const size_t dims[2] = {nt, n};
    return nt == 0 ? ekm_h5_write_field(w, name, 1, &n, data, err)
                   : ekm_h5_write_field(w, name, 2, dims, data, err);
}

/* The sidecar's series: every [nt][n] field and its standard error, the
 * bins as cells along ParaView's Z (common/xdmf.h). */
static ekm_status commit_with_sidecar(ekm_h5_file *w, const cg_run_opts *o, const cg_grid *g,
                                      const cg_window_results *r, int nfield, ekm_error *err)
{
    ekm_xdmf_field fields[2 * CG_NFIELD];
    char se_names[CG_NFIELD][64];
    for (int f = 0; f < nfield; f++) {
        snprintf(se_names[f], sizeof se_names[f], "%s_se", cg_field_name(f));
        fields[2 * f] = (ekm_xdmf_field){.name = cg_field_name(f), .is_int = 0};
        fields[2 * f + 1] = (ekm_xdmf_field){.name = se_names[f], .is_int = 0};
    }
    const ekm_xdmf_series series = {.title = "ekmcompare cg",
                                    .h5_path = o->out,
                                    .n = g->n,
                                    .nt = r->nt,
                                    .t = r->t,
                                    .fields = fields,
                                    .nfields = 2 * (size_t)nfield};
    return ekm_xdmf_commit_fixed(w, &series, g->lo, g->dz, err);
}

int cg_output_value_ok(double v, int nan_ok)
{
    return isfinite(v) || (isnan(v) && nan_ok);
}

ekm_status cg_output_refuse(const cg_run_opts *o, const char *field, const char *suffix, const char *where,
                            double t, double v, ekm_error *err)
{
    return EKM_FAIL(err, EKM_ENUMERIC,
                    "%s%s: %s%s at %s, window t = %.9g s: expected a finite number, got %s (dump values "
                    "whose products overflow double precision: masses, velocities, stresses)",
                    o->inputs[0], o->ninputs > 1 ? " ..." : "", field, suffix, where, t,
                    isnan(v) ? "NaN"
                    : v > 0  ? "inf"
                             : "-inf");
}

/* May field f be NaN in a bin of density rho and pressure P? (cg_output.h) */
static int nan_allowed(int f, double rho, double P)
{
    switch (f) {
    case CG_F_VX:
    case CG_F_VY:
    case CG_F_VZ:
    case CG_F_T: return !(rho > 0);
    case CG_F_MU: return !(P > 0);
    case CG_F_I: return 1;
    default: return 0;
    }
}

/* The guard of cg_output.h over every value to be written. */
static ekm_status check_values(const cg_run_opts *o, const cg_grid *g, const cg_window_results *r, int nfield,
                               ekm_error *err)
{
    size_t n = g->n;
    for (size_t it = 0; it < r->nt; it++)
        for (int f = 0; f < nfield; f++)
            for (size_t k = 0; k < n; k++) {
                size_t i = it * n + k;
                double v = r->f[f][i], se = r->se[f][i];
                int ok_v = cg_output_value_ok(v, nan_allowed(f, r->f[CG_F_RHO][i], r->f[CG_F_P][i]));
                if (ok_v && cg_output_value_ok(se, 1))
                    continue;
                char where[128];
                snprintf(where, sizeof where, "%s = %.6g m (bin %zu of %zu)", axis_names[o->axis],
                         g->lo + ((double)k + 0.5) * g->dz, k + 1, n);
                return cg_output_refuse(o, cg_field_name(f), ok_v ? "_se" : "", where, r->t[it],
                                        ok_v ? se : v, err);
            }
    return EKM_OK;
}

ekm_status cg_output_h5(const cg_run_opts *o, const cg_grid *g, const cg_window_results *r,
                        const cg_kernel *k, const cg_run_info *info, ekm_error *err)
{
    int nfield = (o->nstress || o->npairs) ? CG_NFIELD : CG_F_MU;
    ekm_status rc = check_values(o, g, r, nfield, err);
    if (rc)
        return rc;
    ekm_h5_file *w; /* (its path and its sidecar's checked against the inputs by cg_opts.c) */
    if ((rc = ekm_h5_create(&w, o->out, err)))
        return rc;
    size_t n = g->n;
    double *zc = malloc(n * sizeof *zc);
    char name[64];
    if (!zc) {
        ekm_h5_abort(w);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    for (size_t i = 0; i < n; i++)
        zc[i] = g->lo + ((double)i + 0.5) * g->dz;
    rc = dataset(w, axis_names[o->axis], zc, 0, n, err);
    free(zc);
    if (!rc)
        rc = dataset(w, "t", r->t, 0, r->nt, err);
    if (!rc)
        rc = dataset(w, "nsnapshots", r->nsnap, 0, r->nt, err);
    for (int f = 0; f < nfield && !rc; f++) {
        rc = dataset(w, cg_field_name(f), r->f[f], r->nt, n, err);
        snprintf(name, sizeof name, "%s_se", cg_field_name(f));
        if (!rc)
            rc = dataset(w, name, r->se[f], r->nt, n, err);
    }
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "inputs", info->inputs, err);
    if (!rc && o->npairs)
        rc = ekm_h5_attr_set_string(w, NULL, "pair_inputs", info->pairs, err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "axis", axis_names[o->axis], err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "kernel", cg_kernel_name(k), err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "kernel_evaluation",
                                    o->exact || !strcmp(o->kernel, "bins") ? "exact, per particle"
                                                                           : "sub-grid dz/16, cloud-in-cell",
                                    err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "width", info->width, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "dz", g->dz, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "lo", g->lo, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "hi", g->hi, err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "boundary", info->wall, err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "window", info->window, err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "temperature",
                                    o->tmode == CG_T_PARTICLE ? "particle" : "consistent", err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "stress", info->stress, err);
    if (!rc) {
        char types[16 * CG_MAXTYPES + 8] = "all";
        size_t len = 0;
        for (size_t k = 0; k < o->ntypes; k++)
            len += (size_t)snprintf(types + len, sizeof types - len, "%s%d", k ? "," : "", o->types[k]);
        rc = ekm_h5_attr_set_string(w, NULL, "atom_types", types, err);
    }
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "mean_diameter", info->d, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "lateral_area", info->area, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "rho_p", o->rho_p, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "snapshots_read", (double)info->nread, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "snapshots_used", (double)info->nused, err);
    if (!rc)
        rc = ekm_h5_attr_set_double(w, NULL, "particles_outside_grid", (double)info->nout, err);
    if (!rc && info->steady)
        rc = ekm_h5_attr_set_double(w, NULL, "steady_start", info->t_start, err);
    if (!rc)
        rc = ekm_h5_attr_set_string(w, NULL, "code_version", EKMBENCH_VERSION, err);
    if (rc) {
        ekm_h5_abort(w);
        return rc;
    }
    return commit_with_sidecar(w, o, g, r, nfield, err);
}

ekm_status cg_output_csv(const cg_run_opts *o, const cg_grid *g, const cg_window_results *r, ekm_error *err)
{
    int nfield = (o->nstress || o->npairs) ? CG_NFIELD : CG_F_MU;
    ekm_status rc = check_values(o, g, r, nfield, err);
    if (rc)
        return rc;
    ekm_atomic out;
    if ((rc = ekm_atomic_open(&out, o->csv, err)))
        return rc;
    FILE *fp = out.fp;
    fprintf(fp, "t,%s", axis_names[o->axis]);
    for (int f = 0; f < nfield; f++)
        fprintf(fp, ",%s,%s_se", cg_field_name(f), cg_field_name(f));
    fputc('\n', fp);
    size_t n = g->n;
    for (size_t it = 0; it < r->nt; it++)
        for (size_t k = 0; k < n; k++) {
            fprintf(fp, "%.9g,%.9g", r->t[it], g->lo + ((double)k + 0.5) * g->dz);
            for (int f = 0; f < nfield; f++)
                fprintf(fp, ",%.9g,%.9g", r->f[f][it * n + k], r->se[f][it * n + k]);
            fputc('\n', fp);
        }
    return ekm_atomic_commit(&out, err);
}
