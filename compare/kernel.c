/* kernel.c: coarse-graining kernels (see kernel.h). */
#include "kernel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GAUSS_CUT  3.0          /* Gaussian cut at 3 standard deviations */
#define GAUSS_NTAB 601          /* points of the tabulated Gaussian F (and F') */
#define LUCY_C     3.2403703492 /* sqrt(21/2): Lucy cutoff / std. deviation */
#define SQRT2      1.41421356237309504880

/* Tabulated Gaussian F at table coordinate f in [0, ntab - 1]. */
static inline double gauss_tab(const cg_kernel *k, double f)
{
    size_t i = (size_t)f;
    if (i >= k->ntab - 1)
        return 1.0;
    double a = f - (double)i, a2 = a * a, a3 = a2 * a;
    const double *t = k->tab + 2 * i;
    return t[0] * (2 * a3 - 3 * a2 + 1) + t[1] * (a3 - 2 * a2 + a) + t[2] * (3 * a2 - 2 * a3) +
           t[3] * (a3 - a2);
}

ekm_status cg_kernel_alloc(cg_kernel **out, const char *name, double width, ekm_error *err)
{
    *out = NULL;
    cg_kernel_type type;
    if (!strcmp(name, "gauss"))
        type = CG_KERNEL_GAUSS;
    else if (!strcmp(name, "lucy"))
        type = CG_KERNEL_LUCY;
    else if (!strcmp(name, "bins"))
        type = CG_KERNEL_BINS;
    else
        return EKM_FAIL(err, EKM_EUSAGE, "--kernel: expected gauss, lucy or bins, got '%s'", name);
    if (type != CG_KERNEL_BINS && !(width > 0.0 && isfinite(width)))
        return EKM_FAIL(err, EKM_EUSAGE, "--width: expected a positive width, got %g", width);
    cg_kernel *k = calloc(1, sizeof *k);
    if (!k)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    k->type = type;
    k->width = width;
    if (type == CG_KERNEL_GAUSS) {
        k->cutoff = GAUSS_CUT * width;
        k->ntab = GAUSS_NTAB;
        k->tab = malloc(2 * k->ntab * sizeof *k->tab);
        if (!k->tab) {
            cg_kernel_free(k);
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        }
        /* pairs (F_i, h F'_i), h the table step in u: cubic Hermite
         * interpolation, error < 1e-10, 9.6 kB (stays in L1 cache) */
        double lo = 0.5 * erfc(GAUSS_CUT / SQRT2), norm = 1.0 - 2.0 * lo;
        double h = 2.0 * GAUSS_CUT / (double)(k->ntab - 1);
        for (size_t i = 0; i < k->ntab; i++) {
            double u = -GAUSS_CUT + h * (double)i;
            k->tab[2 * i] = (0.5 * erfc(-u / SQRT2) - lo) / norm;
            k->tab[2 * i + 1] = h * exp(-0.5 * u * u) / (sqrt(2.0 * 3.14159265358979323846) * norm);
        }
        k->tab[0] = 0.0;
        k->tab[2 * (k->ntab - 1)] = 1.0;
        k->tscale = (double)(k->ntab - 1) / (2.0 * GAUSS_CUT * width);
        k->toff = 0.5 * (double)(k->ntab - 1);
    } else if (type == CG_KERNEL_LUCY) {
        k->cutoff = LUCY_C * width;
    }
    *out = k;
    return EKM_OK;
}

void cg_kernel_free(cg_kernel *k)
{
    if (!k)
        return;
    free(k->tab);
    free(k);
}

const char *cg_kernel_name(const cg_kernel *k)
{
    static const char *names[] = {"gauss", "lucy", "bins"};
    return names[k->type];
}

double cg_kernel_support(const cg_kernel *k, double R)
{
    return k->type == CG_KERNEL_BINS ? R : k->cutoff;
}

double cg_kernel_cdf(const cg_kernel *k, double x, double R)
{
    switch (k->type) {
    case CG_KERNEL_GAUSS: {
        double f = x * k->tscale + k->toff; /* table coordinate */
        if (f <= 0.0)
            return 0.0;
        return gauss_tab(k, f);
    }
    case CG_KERNEL_LUCY: {
        double r = x / k->cutoff;
        if (r <= -1.0)
            return 0.0;
        if (r >= 1.0)
            return 1.0;
        double a = fabs(r), a3 = a * a * a;
        double g = 1.25 * (a - 2.0 * a3 + 2.0 * a3 * a - 0.6 * a3 * a * a);
        return r < 0 ? 0.5 - g : 0.5 + g;
    }
    case CG_KERNEL_BINS:
    default: {
        if (x <= -R)
            return 0.0;
        if (x >= R)
            return 1.0;
        double h = R + x;
        return h * h * (2.0 * R - x) / (4.0 * R * R * R);
    }
    }
}

size_t cg_kernel_maxweights(const cg_grid *g)
{
    return 3 * (g->n + 2);
}

static size_t add_image(const cg_kernel *k, const cg_grid *g, double s, double R, double c, size_t *bin,
                        double *w, size_t cnt)
{
    double a = s - c, b = s + c;
    if (b <= g->lo || a >= g->hi)
        return cnt;
    double fa = floor((a - g->lo) / g->dz), fb = floor((b - g->lo) / g->dz);
    long k0 = fa < 0 ? 0 : (long)fa;
    long k1 = fb > (double)(g->n - 1) ? (long)g->n - 1 : (long)fb;
    double inv = 1.0 / g->dz;
    if (k->type == CG_KERNEL_GAUSS) {
        /* the hot path: table coordinate advances by a constant per edge */
        double top = (double)(k->ntab - 1), df = g->dz * k->tscale;
        double f = (g->lo + (double)k0 * g->dz - s) * k->tscale + k->toff;
        double fc = f < 0.0 ? 0.0 : f > top ? top : f;
        double fprev = gauss_tab(k, fc);
        for (long kk = k0; kk <= k1; kk++) {
            f += df;
            fc = f < 0.0 ? 0.0 : f > top ? top : f;
            double fn = gauss_tab(k, fc);
            double wt = (fn - fprev) * inv;
            if (wt != 0.0) {
                bin[cnt] = (size_t)kk;
                w[cnt++] = wt;
            }
            fprev = fn;
        }
        return cnt;
    }
    double fprev = cg_kernel_cdf(k, g->lo + (double)k0 * g->dz - s, R);
    for (long kk = k0; kk <= k1; kk++) {
        double fn = cg_kernel_cdf(k, g->lo + (double)(kk + 1) * g->dz - s, R);
        double wt = (fn - fprev) * inv;
        if (wt != 0.0) {
            bin[cnt] = (size_t)kk;
            w[cnt++] = wt;
        }
        fprev = fn;
    }
    return cnt;
}

size_t cg_kernel_weights(const cg_kernel *k, const cg_grid *g, double s, double R, size_t *bin, double *w)
{
    double c = cg_kernel_support(k, R), L = g->hi - g->lo;
    size_t cnt = 0;
    if (g->periodic) {
        s = g->lo + fmod(s - g->lo, L);
        if (s < g->lo)
            s += L;
        cnt = add_image(k, g, s, R, c, bin, w, cnt);
        if (s - c < g->lo)
            cnt = add_image(k, g, s + L, R, c, bin, w, cnt);
        if (s + c > g->hi)
            cnt = add_image(k, g, s - L, R, c, bin, w, cnt);
    } else {
        cnt = add_image(k, g, s, R, c, bin, w, cnt);
        if (g->reflect) {
            if (s - c < g->lo)
                cnt = add_image(k, g, 2.0 * g->lo - s, R, c, bin, w, cnt);
            if (s + c > g->hi)
                cnt = add_image(k, g, 2.0 * g->hi - s, R, c, bin, w, cnt);
        }
    }
    return cnt;
}
