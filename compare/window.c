/* window.c: averaging windows (see window.h). */
#include "window.h"

#include <math.h>
#include <stdlib.h>

ekm_status cg_window_alloc(cg_window *fz, const cg_grid *g, ekm_error *err)
{
    ekm_status rc = cg_blocks_alloc(&fz->b, CG_NPRIM * g->n, CG_WINDOW_BLOCKS, err);
    if (rc)
        return rc;
    fz->g = g;
    fz->mean = malloc(CG_NPRIM * g->n * sizeof(double));
    fz->fld = malloc(CG_NFIELD * g->n * sizeof(double));
    fz->bf = malloc(CG_WINDOW_BLOCKS * CG_NFIELD * g->n * sizeof(double));
    fz->series = malloc(CG_WINDOW_BLOCKS * sizeof(double));
    fz->work = malloc(CG_WINDOW_BLOCKS * sizeof(double));
    if (!fz->mean || !fz->fld || !fz->bf || !fz->series || !fz->work)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    return EKM_OK;
}

void cg_window_free(cg_window *fz)
{
    cg_blocks_free(fz->b);
    free(fz->mean);
    free(fz->fld);
    free(fz->bf);
    free(fz->series);
    free(fz->work);
}

void cg_window_add(cg_window *fz, const double *prim)
{
    cg_blocks_add(fz->b, prim);
}

void cg_series_free(double *t, double *nsnap, double **f, double **se, int nfield)
{
    free(t);
    free(nsnap);
    for (int k = 0; k < nfield; k++) {
        free(f[k]);
        free(se[k]);
    }
}

ekm_status cg_series_grow(double **t, double **nsnap, double **f, double **se, int nfield, size_t n,
                          size_t nt, size_t *cap, size_t first, ekm_error *err)
{
    if (nt < *cap)
        return EKM_OK;
    size_t c = *cap ? 2 * *cap : first;
    double *p = realloc(*t, c * sizeof *p);
    if (!p)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    *t = p;
    if (!(p = realloc(*nsnap, c * sizeof *p)))
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    *nsnap = p;
    for (int k = 0; k < nfield; k++) {
        if (!(p = realloc(f[k], c * n * sizeof *p)))
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        f[k] = p;
        if (!(p = realloc(se[k], c * n * sizeof *p)))
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        se[k] = p;
    }
    *cap = c;
    return EKM_OK;
}

void cg_window_results_free(cg_window_results *r)
{
    cg_series_free(r->t, r->nsnap, r->f, r->se, CG_NFIELD);
}

static ekm_status results_grow(cg_window_results *r, ekm_error *err)
{
    return cg_series_grow(&r->t, &r->nsnap, r->f, r->se, CG_NFIELD, r->n, r->nt, &r->cap, 8, err);
}

ekm_status cg_window_finish(cg_window *fz, cg_window_results *r, double t_mid, double d, double rho_p,
                            ekm_error *err)
{
    ekm_status rc = results_grow(r, err);
    if (rc)
        return rc;
    size_t n = fz->g->n, nf = CG_NFIELD * n, nb = fz->b->nblocks;
    cg_blocks_mean(fz->b, fz->mean);
    cg_profile_derive(fz->mean, fz->g, d, rho_p, fz->fld);
    for (size_t j = 0; j < nb; j++) {
        cg_blocks_block_mean(fz->b, j, fz->mean);
        cg_profile_derive(fz->mean, fz->g, d, rho_p, fz->bf + j * nf);
    }
    for (int f = 0; f < CG_NFIELD; f++)
        for (size_t k = 0; k < n; k++) {
            size_t idx = (size_t)f * n + k;
            r->f[f][r->nt * n + k] = fz->fld[idx];
            for (size_t j = 0; j < nb; j++)
                fz->series[j] = fz->bf[j * nf + idx];
            r->se[f][r->nt * n + k] = nb >= 2 ? cg_stats_se(fz->series, nb, fz->work) : NAN;
        }
    r->t[r->nt] = t_mid;
    r->nsnap[r->nt] = (double)fz->b->nsnap;
    r->nt++;
    cg_blocks_reset(fz->b);
    return EKM_OK;
}
