/* cg.c: coarse-grained fields of one snapshot (see cg.h). */
#include "cg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const field_names[CG_NFIELD] = {"phi", "rho", "vx",  "vy", "vz", "T",
                                                   "P",   "sxz", "szz", "mu", "I"};
const char *cg_field_name(int f)
{
    return field_names[f];
}

/* Sub-grid nodes and their bin weights (CSR). */
static ekm_status build_subgrid(cg_profile *p, ekm_error *err)
{
    const cg_grid *g = &p->g;
    double c = cg_kernel_support(p->k, 0.0);
    p->h = g->dz / CG_SUBGRID;
    size_t ext = 0;
    if (g->periodic) {
        p->x0 = g->lo;
        p->nnode = g->n * CG_SUBGRID;
    } else {
        ext = (size_t)ceil(c / p->h) + 1;
        p->x0 = g->lo - (double)ext * p->h;
        p->nnode = g->n * CG_SUBGRID + 2 * ext + 1;
    }
    size_t maxw = cg_kernel_maxweights(g);
    p->noff = malloc((p->nnode + 1) * sizeof *p->noff);
    p->nbin = malloc(p->nnode * maxw * sizeof *p->nbin);
    p->nwt = malloc(p->nnode * maxw * sizeof *p->nwt);
    p->node = malloc(p->nnode * CG_NPRIM * sizeof *p->node);
    if (!p->noff || !p->nbin || !p->nwt || !p->node)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (sub-grid)");
    size_t used = 0;
    for (size_t j = 0; j < p->nnode; j++) {
        p->noff[j] = used;
        used += cg_kernel_weights(p->k, g, p->x0 + (double)j * p->h, 0.0, p->nbin + used, p->nwt + used);
    }
    p->noff[p->nnode] = used;
    return EKM_OK;
}

ekm_status cg_profile_alloc(cg_profile **out, const cg_kernel *k, const cg_grid *g, cg_tmode tmode, int exact,
                            ekm_error *err)
{
    *out = NULL;
    if (g->n < 1 || !(g->hi > g->lo))
        return EKM_FAIL(err, EKM_EUSAGE, "grid: expected at least one bin and lo < hi");
    double L = g->hi - g->lo;
    if ((g->periodic || g->reflect) && k->type != CG_KERNEL_BINS && k->cutoff > L)
        return EKM_FAIL(err, EKM_EUSAGE, "--width: kernel support %g m is longer than the box (%g m)",
                        k->cutoff, L);
    cg_profile *p = calloc(1, sizeof *p);
    if (!p)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    p->k = k;
    p->g = *g;
    p->tmode = tmode;
    p->maxw = cg_kernel_maxweights(g);
    p->cap = p->maxw;
    p->bin = malloc(p->cap * sizeof *p->bin);
    p->w = malloc(p->cap * sizeof *p->w);
    p->vel = malloc(3 * g->n * sizeof *p->vel);
    p->acc = malloc(CG_NPRIM * g->n * sizeof *p->acc);
    if (!p->bin || !p->w || !p->vel || !p->acc) {
        cg_profile_free(p);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    p->sub = !exact && k->type != CG_KERNEL_BINS;
    if (p->sub) {
        ekm_status rc = build_subgrid(p, err);
        if (rc) {
            cg_profile_free(p);
            return rc;
        }
    }
    *out = p;
    return EKM_OK;
}

void cg_profile_free(cg_profile *p)
{
    if (!p)
        return;
    free(p->bin);
    free(p->w);
    free(p->nw);
    free(p->vel);
    free(p->acc);
    free(p->noff);
    free(p->nbin);
    free(p->nwt);
    free(p->node);
    free(p);
}

/* CG velocity at coordinate s: linear between bin centres, skipping
 * empty bins, wrapped on a periodic grid, constant beyond the end centres. */
static void velocity_at(const cg_profile *p, const double *rho, double s, double out[3])
{
    const cg_grid *g = &p->g;
    size_t n = g->n;
    double u = (s - g->lo) / g->dz - 0.5;
    double fl = floor(u), a = u - fl;
    long k0 = (long)fl, k1 = k0 + 1;
    if (g->periodic) {
        k0 = ((k0 % (long)n) + (long)n) % (long)n;
        k1 = ((k1 % (long)n) + (long)n) % (long)n;
    } else {
        if (k0 < 0) {
            k0 = 0;
            a = 0.0;
        }
        if (k1 > (long)n - 1) {
            k1 = (long)n - 1;
        }
        if (k0 > (long)n - 1) {
            k0 = (long)n - 1;
            a = 0.0;
        }
        if (k1 < 0)
            k1 = 0;
    }
    double w0 = 1.0 - a, w1 = a;
    if (rho[k0] <= 0.0)
        w0 = 0.0;
    if (rho[k1] <= 0.0)
        w1 = 0.0;
    double ws = w0 + w1;
    for (int c = 0; c < 3; c++)
        out[c] = ws > 0.0 ? (w0 * p->vel[c * n + (size_t)k0] + w1 * p->vel[c * n + (size_t)k1]) / ws : 0.0;
}

/* Room for `more` weights after `used` ones (the weight store grows with
 * the largest snapshot, not with the number of snapshots). */
static ekm_status reserve_weights(cg_profile *p, size_t used, size_t more, ekm_error *err)
{
    if (used + more <= p->cap)
        return EKM_OK;
    size_t c = p->cap;
    while (c < used + more)
        c *= 2;
    size_t *b = realloc(p->bin, c * sizeof *b);
    if (!b)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (kernel weights)");
    p->bin = b;
    double *w = realloc(p->w, c * sizeof *w);
    if (!w)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (kernel weights)");
    p->w = w;
    p->cap = c;
    return EKM_OK;
}

/* Node and fraction of a particle on the sub-grid; 0 if it is too far
 * outside the grid to contribute. */
static int locate_node(const cg_profile *p, double s, size_t *j0, size_t *j1, double *a)
{
    double u = (s - p->x0) / p->h, fl = floor(u);
    *a = u - fl;
    if (p->g.periodic) {
        long N = (long)p->nnode, j = ((long)fl % N + N) % N;
        *j0 = (size_t)j;
        *j1 = (size_t)((j + 1) % N);
        return 1;
    }
    if (fl < 0 || fl + 1 >= (double)p->nnode)
        return 0;
    *j0 = (size_t)fl;
    *j1 = *j0 + 1;
    return 1;
}

/* Spread quantities q0..q0+nq-1 of the nodes into the bins (acc). */
static void spread(cg_profile *p, int q0, int nq)
{
    for (size_t j = 0; j < p->nnode; j++) {
        const double *src = p->node + j * CG_NPRIM + q0;
        int any = 0;
        for (int c = 0; c < nq; c++)
            any |= (src[c] != 0.0);
        if (!any)
            continue;
        for (size_t e = p->noff[j]; e < p->noff[j + 1]; e++) {
            double *dst = p->acc + p->nbin[e] * CG_NPRIM + q0, w = p->nwt[e];
            for (int c = 0; c < nq; c++)
                dst[c] += src[c] * w;
        }
    }
}

/* Points of the midpoint rule along a contact's branch, at most h apart. */
static size_t branch_points(const cg_profile *p, double bs)
{
    double m = ceil(fabs(bs) / p->h);
    return m < 1 ? 1 : m > 1e6 ? 1000000 : (size_t)m;
}

static void contact_tensor(const cg_particles *pt, size_t c, double out[6])
{
    const double *b = pt->cb + 3 * c, *f = pt->cf + 3 * c;
    out[0] = -f[0] * b[0];
    out[1] = -f[1] * b[1];
    out[2] = -f[2] * b[2];
    out[3] = -0.5 * (f[0] * b[1] + f[1] * b[0]);
    out[4] = -0.5 * (f[0] * b[2] + f[2] * b[0]);
    out[5] = -0.5 * (f[1] * b[2] + f[2] * b[1]);
}

/* Contact stress onto the sub-grid nodes (S part). */
static void deposit_contacts_sub(cg_profile *p, const cg_particles *pt)
{
    int ax = p->g.axis;
    for (size_t c = 0; c < pt->nc; c++) {
        double t[6], bs = pt->cb[3 * c + ax];
        contact_tensor(pt, c, t);
        size_t M = branch_points(p, bs);
        for (size_t q = 0; q < M; q++) {
            size_t j0, j1;
            double a, s = pt->cs[c] + ((double)q + 0.5) / (double)M * bs;
            if (!locate_node(p, s, &j0, &j1, &a))
                continue;
            double *d0 = p->node + j0 * CG_NPRIM + CG_P_SXX, *d1 = p->node + j1 * CG_NPRIM + CG_P_SXX;
            double w1 = a / (double)M, w0 = (1.0 - a) / (double)M;
            for (int k = 0; k < 6; k++) {
                d0[k] += t[k] * w0;
                d1[k] += t[k] * w1;
            }
        }
    }
}

/* Contact stress with the kernel evaluated at every branch point (exact path). */
static void deposit_contacts_exact(cg_profile *p, const cg_particles *pt)
{
    int ax = p->g.axis;
    double h = p->g.dz / CG_SUBGRID;
    for (size_t c = 0; c < pt->nc; c++) {
        double t[6], bs = pt->cb[3 * c + ax];
        contact_tensor(pt, c, t);
        double mm = ceil(fabs(bs) / h);
        size_t M = mm < 1 ? 1 : mm > 1e6 ? 1000000 : (size_t)mm;
        for (size_t q = 0; q < M; q++) {
            double s = pt->cs[c] + ((double)q + 0.5) / (double)M * bs;
            size_t nw = cg_kernel_weights(p->k, &p->g, s, 0.0, p->bin, p->w);
            for (size_t j = 0; j < nw; j++) {
                double *d = p->acc + p->bin[j] * CG_NPRIM + CG_P_SXX, w = p->w[j] / (double)M;
                for (int k = 0; k < 6; k++)
                    d[k] += t[k] * w;
            }
        }
    }
}

static int snapshot_subgrid(cg_profile *p, const cg_particles *pt, double *prim)
{
    size_t n = p->g.n;
    double *acc = p->acc, *node = p->node;
    memset(acc, 0, CG_NPRIM * n * sizeof *acc);
    memset(node, 0, CG_NPRIM * p->nnode * sizeof *node);
    int consistent = (p->tmode == CG_T_CONSISTENT);
    for (size_t i = 0; i < pt->n; i++) {
        size_t j0, j1;
        double a;
        if (!locate_node(p, pt->s[i], &j0, &j1, &a))
            continue;
        const double *v = pt->v + 3 * i;
        double m = pt->m[i];
        double q[CG_NPRIM];
        q[CG_P_RHO] = m;
        q[CG_P_PHI] = pt->vol[i];
        q[CG_P_PX] = m * v[0];
        q[CG_P_PY] = m * v[1];
        q[CG_P_PZ] = m * v[2];
        int nq = 5;
        if (consistent || pt->S) {
            nq = CG_NPRIM;
            double mvv[6] = {q[CG_P_PX] * v[0], q[CG_P_PY] * v[1], q[CG_P_PZ] * v[2],
                             q[CG_P_PX] * v[1], q[CG_P_PX] * v[2], q[CG_P_PY] * v[2]};
            for (int c = 0; c < 6; c++) {
                q[CG_P_KXX + c] = consistent ? mvv[c] : 0.0;
                q[CG_P_SXX + c] = pt->S ? pt->S[6 * i + c] : 0.0;
            }
        }
        double *d0 = node + j0 * CG_NPRIM, *d1 = node + j1 * CG_NPRIM, b = 1.0 - a;
        for (int c = 0; c < nq; c++) {
            d0[c] += q[c] * b;
            d1[c] += q[c] * a;
        }
    }
    if (pt->nc)
        deposit_contacts_sub(p, pt);
    spread(p, 0, (consistent || pt->S || pt->nc) ? CG_NPRIM : 5);
    double *rho = prim + CG_P_RHO * n;
    for (size_t k = 0; k < n; k++) {
        const double *q = acc + k * CG_NPRIM;
        double r = q[CG_P_RHO];
        rho[k] = r;
        p->vel[k] = r > 0 ? q[CG_P_PX] / r : 0.0;
        p->vel[n + k] = r > 0 ? q[CG_P_PY] / r : 0.0;
        p->vel[2 * n + k] = r > 0 ? q[CG_P_PZ] / r : 0.0;
    }
    if (consistent) {
        static const int ia[6] = {0, 1, 2, 0, 0, 1}, ib[6] = {0, 1, 2, 1, 2, 2};
        for (size_t k = 0; k < n; k++)
            for (int c = 0; c < 6; c++)
                acc[k * CG_NPRIM + CG_P_KXX + c] -=
                    acc[k * CG_NPRIM + CG_P_RHO] * p->vel[ia[c] * n + k] * p->vel[ib[c] * n + k];
    } else {
        for (size_t j = 0; j < p->nnode; j++)
            memset(node + j * CG_NPRIM + CG_P_KXX, 0, 6 * sizeof *node);
        for (size_t i = 0; i < pt->n; i++) {
            size_t j0, j1;
            double a;
            if (!locate_node(p, pt->s[i], &j0, &j1, &a))
                continue;
            double V[3];
            velocity_at(p, rho, pt->s[i], V);
            const double *v = pt->v + 3 * i;
            double m = pt->m[i];
            double c0 = v[0] - V[0], c1 = v[1] - V[1], c2 = v[2] - V[2];
            const double mcc[6] = {m * c0 * c0, m * c1 * c1, m * c2 * c2,
                                   m * c0 * c1, m * c0 * c2, m * c1 * c2};
            double *d0 = node + j0 * CG_NPRIM + CG_P_KXX, *d1 = node + j1 * CG_NPRIM + CG_P_KXX;
            double b = 1.0 - a;
            for (int c = 0; c < 6; c++) {
                d0[c] += mcc[c] * b;
                d1[c] += mcc[c] * a;
            }
        }
        spread(p, CG_P_KXX, 6);
    }
    double inv = 1.0 / pt->area;
    for (size_t k = 0; k < n; k++)
        for (size_t c = 0; c < CG_NPRIM; c++)
            prim[c * n + k] = acc[k * CG_NPRIM + c] * inv;
    return EKM_OK;
}

ekm_status cg_profile_snapshot(cg_profile *p, const cg_particles *pt, double *prim, ekm_error *err)
{
    size_t n = p->g.n;
    if (p->sub)
        return snapshot_subgrid(p, pt, prim);
    if (pt->n > p->ncap) {
        unsigned *nw = realloc(p->nw, pt->n * sizeof *nw);
        if (!nw)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory (kernel weights)");
        p->nw = nw;
        p->ncap = pt->n;
    }
    /* accumulate bin-major (the CG_NPRIM sums of a bin are contiguous, so a
     * particle's update of a bin touches one or two cache lines) */
    double *acc = p->acc;
    memset(acc, 0, CG_NPRIM * n * sizeof *acc);
    int consistent = (p->tmode == CG_T_CONSISTENT);
    /* pass 1: mass, volume, momentum (and m v v, contact stress); the
     * weights are kept for pass 2 */
    size_t used = 0;
    for (size_t i = 0; i < pt->n; i++) {
        ekm_status rc = reserve_weights(p, used, p->maxw, err);
        if (rc)
            return rc;
        size_t *bin = p->bin + used;
        double *wt = p->w + used;
        size_t nw = cg_kernel_weights(p->k, &p->g, pt->s[i], pt->rad[i], bin, wt);
        p->nw[i] = (unsigned)nw;
        used += nw;
        const double *v = pt->v + 3 * i;
        double m = pt->m[i];
        const double a[5] = {m, pt->vol[i], m * v[0], m * v[1], m * v[2]};
        for (size_t j = 0; j < nw; j++) {
            double *q = acc + bin[j] * CG_NPRIM, w = wt[j];
            for (int c = 0; c < 5; c++)
                q[CG_P_RHO + c] += a[c] * w;
        }
        if (consistent) {
            const double mvv[6] = {a[2] * v[0], a[3] * v[1], a[4] * v[2],
                                   a[2] * v[1], a[2] * v[2], a[3] * v[2]};
            for (size_t j = 0; j < nw; j++) {
                double *q = acc + bin[j] * CG_NPRIM + CG_P_KXX, w = wt[j];
                for (int c = 0; c < 6; c++)
                    q[c] += mvv[c] * w;
            }
        }
        if (pt->S) {
            const double *Si = pt->S + 6 * i;
            for (size_t j = 0; j < nw; j++) {
                double *q = acc + bin[j] * CG_NPRIM + CG_P_SXX, w = wt[j];
                for (int c = 0; c < 6; c++)
                    q[c] += Si[c] * w;
            }
        }
    }
    double *rho = prim + CG_P_RHO * n;
    for (size_t k = 0; k < n; k++) {
        const double *q = acc + k * CG_NPRIM;
        double r = q[CG_P_RHO];
        rho[k] = r; /* for velocity_at */
        p->vel[k] = r > 0 ? q[CG_P_PX] / r : 0.0;
        p->vel[n + k] = r > 0 ? q[CG_P_PY] / r : 0.0;
        p->vel[2 * n + k] = r > 0 ? q[CG_P_PZ] / r : 0.0;
    }
    if (consistent) {
        static const int ia[6] = {0, 1, 2, 0, 0, 1}, ib[6] = {0, 1, 2, 1, 2, 2};
        for (size_t k = 0; k < n; k++)
            for (int c = 0; c < 6; c++)
                acc[k * CG_NPRIM + CG_P_KXX + c] -=
                    acc[k * CG_NPRIM + CG_P_RHO] * p->vel[ia[c] * n + k] * p->vel[ib[c] * n + k];
    } else {
        /* pass 2: fluctuations about the CG velocity at the particle */
        used = 0;
        for (size_t i = 0; i < pt->n; i++) {
            size_t nw = p->nw[i];
            const size_t *bin = p->bin + used;
            const double *wt = p->w + used;
            used += nw;
            double V[3];
            velocity_at(p, rho, pt->s[i], V);
            const double *v = pt->v + 3 * i;
            double m = pt->m[i];
            double c0 = v[0] - V[0], c1 = v[1] - V[1], c2 = v[2] - V[2];
            const double mcc[6] = {m * c0 * c0, m * c1 * c1, m * c2 * c2,
                                   m * c0 * c1, m * c0 * c2, m * c1 * c2};
            for (size_t j = 0; j < nw; j++) {
                double *q = acc + bin[j] * CG_NPRIM + CG_P_KXX, w = wt[j];
                for (int c = 0; c < 6; c++)
                    q[c] += mcc[c] * w;
            }
        }
    }
    if (pt->nc)
        deposit_contacts_exact(p, pt);
    /* transpose to quantity-major, per unit area */
    double inv = 1.0 / pt->area;
    for (size_t k = 0; k < n; k++)
        for (size_t c = 0; c < CG_NPRIM; c++)
            prim[c * n + k] = acc[k * CG_NPRIM + c] * inv;
    return EKM_OK;
}

void cg_profile_derive(const double *prim, const cg_grid *g, double d, double rho_p, double *f)
{
    size_t n = g->n;
    const double *rho = prim + CG_P_RHO * n, *phi = prim + CG_P_PHI * n;
    for (size_t k = 0; k < n; k++) {
        double r = rho[k];
        f[CG_F_PHI * n + k] = phi[k];
        f[CG_F_RHO * n + k] = r;
        double nan = NAN;
        f[CG_F_VX * n + k] = r > 0 ? prim[CG_P_PX * n + k] / r : nan;
        f[CG_F_VY * n + k] = r > 0 ? prim[CG_P_PY * n + k] / r : nan;
        f[CG_F_VZ * n + k] = r > 0 ? prim[CG_P_PZ * n + k] / r : nan;
        double trK = prim[CG_P_KXX * n + k] + prim[CG_P_KYY * n + k] + prim[CG_P_KZZ * n + k];
        f[CG_F_T * n + k] = r > 0 ? trK / (3.0 * r) : nan;
        double sxx = -prim[CG_P_KXX * n + k] + prim[CG_P_SXX * n + k];
        double syy = -prim[CG_P_KYY * n + k] + prim[CG_P_SYY * n + k];
        double szz = -prim[CG_P_KZZ * n + k] + prim[CG_P_SZZ * n + k];
        double sxz = -prim[CG_P_KXZ * n + k] + prim[CG_P_SXZ * n + k];
        double P = -(sxx + syy + szz) / 3.0;
        f[CG_F_P * n + k] = P;
        f[CG_F_SXZ * n + k] = sxz;
        f[CG_F_SZZ * n + k] = szz;
        f[CG_F_MU * n + k] = P > 0 ? fabs(sxz) / P : nan;
    }
    for (size_t k = 0; k < n; k++) {
        const double *vx = f + CG_F_VX * n;
        size_t km, kp;
        double span;
        if (g->periodic) {
            km = (k + n - 1) % n;
            kp = (k + 1) % n;
            span = 2.0 * g->dz;
        } else {
            km = k > 0 ? k - 1 : k;
            kp = k + 1 < n ? k + 1 : k;
            span = (double)(kp - km) * g->dz;
        }
        double P = f[CG_F_P * n + k];
        double rp = rho_p > 0 ? rho_p : (phi[k] > 0 ? rho[k] / phi[k] : 0.0);
        double gd = span > 0 ? fabs(vx[kp] - vx[km]) / span : NAN;
        f[CG_F_I * n + k] = (P > 0 && rp > 0) ? gd * d / sqrt(P / rp) : NAN;
    }
}
