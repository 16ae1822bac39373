/* cg2d_output.c: HDF5 (+ XDMF) and CSV outputs of `ekmcompare cg --axes
 * x,z` (see cg2d_output.h). */
#include "ekm_version.h"
#include "cg2d_output.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "cg_output.h"
#include "h5.h"
#include "xdmf.h"

static int nfields_of(const cg_run_opts *o)
{
    return o->nstress || o->npairs ? CG2D_NFIELD : CG2D_NFIELD_KINETIC;
}

static ekm_status centres(const cg_grid *g, double **out, ekm_error *err)
{
    double *c = malloc(g->n * sizeof *c);
    if (!c)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    for (size_t i = 0; i < g->n; i++)
        c[i] = g->lo + ((double)i + 0.5) * g->dz;
    *out = c;
    return EKM_OK;
}

static const char *boundary_name(const cg_grid *g)
{
    return g->periodic ? "periodic" : g->reflect ? "walls: kernel reflected" : "open (--range)";
}

static ekm_status write_attrs(ekm_h5_file *w, const cg2d_output *st, ekm_error *err)
{
    const cg_run_opts *o = st->o;
    const cg2d_grid *g = st->g;
    char stress[256];
    if (o->nstress)
        snprintf(stress, sizeof stress, "kinetic + per-atom %s %s %s %s %s %s", o->stress[0], o->stress[1],
                 o->stress[2], o->stress[3], o->stress[4], o->stress[5]);
    else if (o->npairs)
        snprintf(stress, sizeof stress, "kinetic + contacts from pair dumps (branch line integral), %s",
                 o->npaircols == 9 ? "positions" : "atom ids");
    else
        snprintf(stress, sizeof stress, "kinetic only");
    char types[16 * CG_MAXTYPES + 8] = "all";
    size_t len = 0;
    for (size_t k = 0; k < o->ntypes; k++)
        len += (size_t)snprintf(types + len, sizeof types - len, "%s%d", k ? "," : "", o->types[k]);
    char se[160];
    if (o->ensemble)
        snprintf(se, sizeof se, "across %zu independent runs: sd/sqrt(runs)", st->nruns);
    else
        snprintf(se, sizeof se, "blocking over snapshots (at most %d blocks per window)", CG2D_BLOCKS);
    const struct {
        const char *name, *value;
    } strs[] = {{"inputs", st->inputs},
                {"axis", "x,z"},
                {"averaged_over", "y"},
                {"kernel", st->kernel},
                {"kernel_evaluation", "exact, per particle: product of the 1D bin weights along x and z"},
                {"boundary", boundary_name(&g->gz)},
                {"x_boundary", boundary_name(&g->gx)},
                {"window", st->window},
                {"temperature", o->tmode == CG_T_PARTICLE ? "particle" : "consistent"},
                {"stress", stress},
                {"atom_types", types},
                {"standard_error", se},
                {"code_version", EKMBENCH_VERSION}};
    ekm_status rc = EKM_OK;
    for (size_t i = 0; i < sizeof strs / sizeof strs[0] && !rc; i++)
        rc = ekm_h5_attr_set_string(w, NULL, strs[i].name, strs[i].value, err);
    if (!rc && o->npairs) {
        char pairs[4096] = "";
        size_t used = 0;
        for (size_t i = 0; i < o->npairs && used + 2 < sizeof pairs; i++)
            used += (size_t)snprintf(pairs + used, sizeof pairs - used, "%s%s", i ? "\n" : "", o->pairs[i]);
        rc = ekm_h5_attr_set_string(w, NULL, "pair_inputs", pairs, err);
    }
    const struct {
        const char *name;
        double value;
    } nums[] = {{"width", st->width},
                {"dz", g->gz.dz},
                {"lo", g->gz.lo},
                {"hi", g->gz.hi},
                {"dx", g->gx.dz},
                {"x_lo", g->gx.lo},
                {"x_hi", g->gx.hi},
                {"mean_diameter", st->d},
                {"averaged_length", st->length_y},
                {"rho_p", o->rho_p},
                {"snapshots_read", (double)st->nread},
                {"snapshots_used", (double)st->nused},
                {"particles_outside_grid", (double)st->nout},
                {"runs", (double)(o->ensemble ? st->nruns : 1)}};
    for (size_t i = 0; i < sizeof nums / sizeof nums[0] && !rc; i++)
        rc = ekm_h5_attr_set_double(w, NULL, nums[i].name, nums[i].value, err);
    return rc;
}

/* May field f be NaN in a cell of density rho and pressure P? (cg_output.h) */
static int nan_allowed(int f, double rho, double P)
{
    switch (f) {
    case CG2D_F_VX:
    case CG2D_F_VY:
    case CG2D_F_VZ:
    case CG2D_F_T: return !(rho > 0);
    case CG2D_F_MU: return !(P > 0);
    default: return 0;
    }
}

/* The guard of cg_output.h over every value to be written. */
static ekm_status check_values(const cg2d_output *st, ekm_error *err)
{
    const cg2d_grid *g = st->g;
    const cg2d_results *r = st->r;
    size_t nx = g->gx.n, n = cg2d_ncell(g);
    int nfield = nfields_of(st->o);
    for (size_t it = 0; it < r->nt; it++)
        for (int f = 0; f < nfield; f++)
            for (size_t c = 0; c < n; c++) {
                size_t i = it * n + c;
                double v = r->f[f][i], se = r->se[f][i];
                int ok_v = cg_output_value_ok(v, nan_allowed(f, r->f[CG2D_F_RHO][i], r->f[CG2D_F_P][i]));
                if (ok_v && cg_output_value_ok(se, 1))
                    continue;
                char where[160];
                snprintf(where, sizeof where, "x = %.6g m, z = %.6g m (cell %zu, %zu)",
                         g->gx.lo + ((double)(c % nx) + 0.5) * g->gx.dz,
                         g->gz.lo + ((double)(c / nx) + 0.5) * g->gz.dz, c % nx + 1, c / nx + 1);
                return cg_output_refuse(st->o, cg2d_field_name(f), ok_v ? "_se" : "", where, r->t[it],
                                        ok_v ? se : v, err);
            }
    return EKM_OK;
}

ekm_status cg2d_output_h5(const cg2d_output *st, ekm_error *err)
{
    const cg_run_opts *o = st->o;
    const cg2d_grid *g = st->g;
    const cg2d_results *r = st->r;
    ekm_status rc = check_values(st, err);
    if (rc)
        return rc;
    ekm_h5_file *w;
    if ((rc = ekm_h5_create(&w, o->out, err)))
        return rc;
    double *xc = NULL, *zc = NULL;
    rc = centres(&g->gx, &xc, err);
    if (!rc)
        rc = centres(&g->gz, &zc, err);
    if (!rc)
        rc = ekm_h5_write_field(w, "x", 1, &g->gx.n, xc, err);
    if (!rc)
        rc = ekm_h5_write_field(w, "z", 1, &g->gz.n, zc, err);
    free(xc);
    free(zc);
    if (!rc)
        rc = ekm_h5_write_field(w, "t", 1, &r->nt, r->t, err);
    if (!rc)
        rc = ekm_h5_write_field(w, "nsnapshots", 1, &r->nt, r->nsnap, err);
    int nfield = nfields_of(o);
    const size_t dims[3] = {r->nt, g->gz.n, g->gx.n};
    char name[64];
    for (int f = 0; f < nfield && !rc; f++) {
        rc = ekm_h5_write_field(w, cg2d_field_name(f), 3, dims, r->f[f], err);
        snprintf(name, sizeof name, "%s_se", cg2d_field_name(f));
        if (!rc)
            rc = ekm_h5_write_field(w, name, 3, dims, r->se[f], err);
    }
    if (!rc)
        rc = write_attrs(w, st, err);
    if (rc) {
        ekm_h5_abort(w);
        return rc;
    }
    ekm_xdmf_field fields[2 * CG2D_NFIELD];
    char se_names[CG2D_NFIELD][64];
    for (int f = 0; f < nfield; f++) {
        snprintf(se_names[f], sizeof se_names[f], "%s_se", cg2d_field_name(f));
        fields[2 * f] = (ekm_xdmf_field){.name = cg2d_field_name(f), .is_int = 0};
        fields[2 * f + 1] = (ekm_xdmf_field){.name = se_names[f], .is_int = 0};
    }
    const ekm_xdmf_series series = {.title = "ekmcompare cg --axes x,z",
                                    .h5_path = o->out,
                                    .n = g->gz.n,
                                    .nt = r->nt,
                                    .t = r->t,
                                    .fields = fields,
                                    .nfields = 2 * (size_t)nfield,
                                    .nx = g->gx.n,
                                    .x0 = g->gx.lo,
                                    .dx = g->gx.dz};
    return ekm_xdmf_commit_fixed(w, &series, g->gz.lo, g->gz.dz, err);
}

ekm_status cg2d_output_csv(const cg2d_output *st, ekm_error *err)
{
    const cg_run_opts *o = st->o;
    const cg2d_grid *g = st->g;
    const cg2d_results *r = st->r;
    ekm_status rc = check_values(st, err);
    if (rc)
        return rc;
    ekm_atomic out;
    if ((rc = ekm_atomic_open(&out, o->csv, err)))
        return rc;
    FILE *fp = out.fp;
    int nfield = nfields_of(o);
    fputs("t,x,z", fp);
    for (int f = 0; f < nfield; f++)
        fprintf(fp, ",%s,%s_se", cg2d_field_name(f), cg2d_field_name(f));
    fputc('\n', fp);
    size_t nx = g->gx.n, n = cg2d_ncell(g);
    for (size_t it = 0; it < r->nt; it++)
        for (size_t c = 0; c < n; c++) {
            fprintf(fp, "%.9g,%.9g,%.9g", r->t[it], g->gx.lo + ((double)(c % nx) + 0.5) * g->gx.dz,
                    g->gz.lo + ((double)(c / nx) + 0.5) * g->gz.dz);
            for (int f = 0; f < nfield; f++)
                fprintf(fp, ",%.9g,%.9g", r->f[f][it * n + c], r->se[f][it * n + c]);
            fputc('\n', fp);
        }
    return ekm_atomic_commit(&out, err);
}
