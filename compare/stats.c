/* stats.c: block averages and blocking standard errors (see stats.h). */
#include "stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SE_MIN_BLOCKS 8 /* fewest blocks for a level to count in the SE */

ekm_status cg_blocks_alloc(cg_blocks **out, size_t m, size_t bmax, ekm_error *err)
{
    *out = NULL;
    if (bmax < 2 || bmax % 2)
        return EKM_FAIL(err, EKM_EINTERNAL, "blocks: expected an even bmax >= 2");
    cg_blocks *b = calloc(1, sizeof *b);
    if (!b)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    b->m = m;
    b->bmax = bmax;
    b->blocks = calloc(bmax * m, sizeof *b->blocks);
    b->cur = calloc(m, sizeof *b->cur);
    b->total = calloc(m, sizeof *b->total);
    if (!b->blocks || !b->cur || !b->total) {
        cg_blocks_free(b);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    cg_blocks_reset(b);
    *out = b;
    return EKM_OK;
}

void cg_blocks_free(cg_blocks *b)
{
    if (!b)
        return;
    free(b->blocks);
    free(b->cur);
    free(b->total);
    free(b);
}

void cg_blocks_reset(cg_blocks *b)
{
    b->bsize = 1;
    b->nblocks = b->ncur = b->nsnap = 0;
    memset(b->cur, 0, b->m * sizeof *b->cur);
    memset(b->total, 0, b->m * sizeof *b->total);
}

void cg_blocks_add(cg_blocks *b, const double *x)
{
    size_t m = b->m;
    for (size_t i = 0; i < m; i++) {
        b->cur[i] += x[i];
        b->total[i] += x[i];
    }
    b->nsnap++;
    b->ncur++;
    if (b->ncur < b->bsize)
        return;
    if (b->nblocks == b->bmax) {
        for (size_t j = 0; j < b->bmax / 2; j++) {
            double *dst = b->blocks + j * m;
            const double *a = b->blocks + 2 * j * m, *c = a + m;
            for (size_t i = 0; i < m; i++)
                dst[i] = a[i] + c[i];
        }
        b->nblocks = b->bmax / 2;
        b->bsize *= 2;
        return; /* the current block continues to the new size */
    }
    memcpy(b->blocks + b->nblocks * m, b->cur, m * sizeof *b->cur);
    b->nblocks++;
    b->ncur = 0;
    memset(b->cur, 0, m * sizeof *b->cur);
}

void cg_blocks_mean(const cg_blocks *b, double *out)
{
    double inv = b->nsnap ? 1.0 / (double)b->nsnap : 0.0;
    for (size_t i = 0; i < b->m; i++)
        out[i] = b->total[i] * inv;
}

void cg_blocks_block_mean(const cg_blocks *b, size_t j, double *out)
{
    double inv = 1.0 / (double)b->bsize;
    const double *s = b->blocks + j * b->m;
    for (size_t i = 0; i < b->m; i++)
        out[i] = s[i] * inv;
}

double cg_stats_se(const double *x, size_t n, double *work)
{
    size_t nb = 0;
    for (size_t i = 0; i < n; i++)
        work[nb++] = x[i];
    double best = NAN;
    int level = 0;
    while (nb >= 2) {
        double sum = 0.0;
        size_t nf = 0;
        for (size_t i = 0; i < nb; i++)
            if (isfinite(work[i])) {
                sum += work[i];
                nf++;
            }
        if (nf >= 2 && (level == 0 || nf >= SE_MIN_BLOCKS)) {
            double mean = sum / (double)nf, ss = 0.0;
            for (size_t i = 0; i < nb; i++)
                if (isfinite(work[i]))
                    ss += (work[i] - mean) * (work[i] - mean);
            double se = sqrt(ss / (double)(nf - 1) / (double)nf);
            if (!(se <= best))
                best = se; /* also replaces NAN */
        }
        if (nb / 2 < SE_MIN_BLOCKS)
            break;
        for (size_t i = 0; i < nb / 2; i++) {
            double a = work[2 * i], c = work[2 * i + 1];
            work[i] = isfinite(a) && isfinite(c) ? 0.5 * (a + c) : isfinite(a) ? a : c;
        }
        nb /= 2;
        level++;
    }
    return best;
}
