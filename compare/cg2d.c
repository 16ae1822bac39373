/* cg2d.c: coarse-grained fields of one snapshot on a 2D grid (see cg2d.h). */
#include "cg2d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const field_names[CG2D_NFIELD] = {"phi", "rho", "vx",  "vy",  "vz",  "T",
                                                     "kxx", "kzz", "kxz", "P",   "sxx", "szz",
                                                     "sxz", "cxx", "czz", "cxz", "mu"};

const char *cg2d_field_name(int f)
{
    return field_names[f];
}

ekm_status cg2d_profile_alloc(cg2d_profile **out, const cg_kernel *k, const cg2d_grid *g, cg_tmode tmode,
                              ekm_error *err)
{
    *out = NULL;
    const cg_grid *axes[2] = {&g->gx, &g->gz};
    for (int a = 0; a < 2; a++) {
        const cg_grid *ga = axes[a];
        if (ga->n < 1 || !(ga->hi > ga->lo))
            return EKM_FAIL(err, EKM_EUSAGE, "grid: expected at least one cell and lo < hi along %c",
                            a ? 'z' : 'x');
        if ((ga->periodic || ga->reflect) && k->cutoff > ga->hi - ga->lo)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "--width: kernel support %g m is longer than the box along %c (%g m)", k->cutoff,
                            a ? 'z' : 'x', ga->hi - ga->lo);
    }
    if (k->type == CG_KERNEL_BINS)
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--kernel: bins (sphere-slab volumes) has no exact 2D form: expected gauss or lucy "
                        "with --axes x,z");
    cg2d_profile *p = calloc(1, sizeof *p);
    if (!p)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    p->k = k;
    p->g = *g;
    p->tmode = tmode;
    size_t mx = cg_kernel_maxweights(&g->gx), mz = cg_kernel_maxweights(&g->gz);
    p->maxw = mx > mz ? mx : mz;
    size_t nc = cg2d_ncell(g);
    p->binx = malloc(p->maxw * sizeof *p->binx);
    p->wx = malloc(p->maxw * sizeof *p->wx);
    p->binz = malloc(p->maxw * sizeof *p->binz);
    p->wz = malloc(p->maxw * sizeof *p->wz);
    p->acc = malloc(nc * CG_NPRIM * sizeof *p->acc);
    p->vel = malloc(3 * nc * sizeof *p->vel);
    if (!p->binx || !p->wx || !p->binz || !p->wz || !p->acc || !p->vel) {
        cg2d_profile_free(p);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D grid of %zu cells)", nc);
    }
    *out = p;
    return EKM_OK;
}

void cg2d_profile_free(cg2d_profile *p)
{
    if (!p)
        return;
    free(p->binx);
    free(p->wx);
    free(p->binz);
    free(p->wz);
    free(p->acc);
    free(p->vel);
    free(p);
}

/* Neighbouring cell centres k0, k1 of coordinate s along grid g and the
 * fraction a of the way from k0 to k1: wrapped on a periodic axis,
 * constant beyond the end centres otherwise (as cg.c's velocity_at). */
static void bracket(const cg_grid *g, double s, size_t *k0_out, size_t *k1_out, double *a_out)
{
    long n = (long)g->n;
    double u = (s - g->lo) / g->dz - 0.5, fl = floor(u), a = u - fl;
    long k0 = (long)fl, k1 = k0 + 1;
    if (g->periodic) {
        k0 = ((k0 % n) + n) % n;
        k1 = ((k1 % n) + n) % n;
    } else {
        if (k0 < 0) {
            k0 = 0;
            a = 0.0;
        }
        if (k1 > n - 1)
            k1 = n - 1;
        if (k0 > n - 1) {
            k0 = n - 1;
            a = 0.0;
        }
        if (k1 < 0)
            k1 = 0;
    }
    *k0_out = (size_t)k0;
    *k1_out = (size_t)k1;
    *a_out = a;
}

/* CG velocity at (x, z): bilinear between cell centres, empty cells
 * skipped. */
static void velocity_at(const cg2d_profile *p, const double *rho, double x, double z, double out[3])
{
    size_t nx = p->g.gx.n, nc = cg2d_ncell(&p->g);
    size_t x0, x1, z0, z1;
    double ax, az;
    bracket(&p->g.gx, x, &x0, &x1, &ax);
    bracket(&p->g.gz, z, &z0, &z1, &az);
    const size_t cell[4] = {z0 * nx + x0, z0 * nx + x1, z1 * nx + x0, z1 * nx + x1};
    double w[4] = {(1 - ax) * (1 - az), ax * (1 - az), (1 - ax) * az, ax * az}, ws = 0.0;
    for (int j = 0; j < 4; j++) {
        if (rho[cell[j]] <= 0.0)
            w[j] = 0.0;
        ws += w[j];
    }
    for (int c = 0; c < 3; c++) {
        double v = 0.0;
        for (int j = 0; j < 4; j++)
            v += w[j] * p->vel[(size_t)c * nc + cell[j]];
        out[c] = ws > 0.0 ? v / ws : 0.0;
    }
}

/* Contact stress of the pair dump's contacts: the kernel averaged along
 * each branch (midpoint rule). */
static void deposit_contacts(cg2d_profile *p, const cg2d_particles *pt)
{
    const cg2d_grid *g = &p->g;
    size_t nx = g->gx.n;
    double hx = g->gx.dz / CG_SUBGRID, hz = g->gz.dz / CG_SUBGRID;
    for (size_t c = 0; c < pt->nc; c++) {
        const double *b = pt->cb + 3 * c, *f = pt->cf + 3 * c;
        const double t[6] = {-f[0] * b[0],
                             -f[1] * b[1],
                             -f[2] * b[2],
                             -0.5 * (f[0] * b[1] + f[1] * b[0]),
                             -0.5 * (f[0] * b[2] + f[2] * b[0]),
                             -0.5 * (f[1] * b[2] + f[2] * b[1])};
        double mm = fmax(ceil(fabs(b[0]) / hx), ceil(fabs(b[2]) / hz));
        size_t M = mm < 1 ? 1 : mm > 1e6 ? 1000000 : (size_t)mm;
        for (size_t q = 0; q < M; q++) {
            double u = ((double)q + 0.5) / (double)M;
            size_t nwx = cg_kernel_weights(p->k, &g->gx, pt->cx[c] + u * b[0], 0.0, p->binx, p->wx);
            size_t nwz = cg_kernel_weights(p->k, &g->gz, pt->cz[c] + u * b[2], 0.0, p->binz, p->wz);
            for (size_t jz = 0; jz < nwz; jz++) {
                double *row = p->acc + p->binz[jz] * nx * CG_NPRIM;
                for (size_t jx = 0; jx < nwx; jx++) {
                    double *d = row + p->binx[jx] * CG_NPRIM + CG_P_SXX,
                           w = p->wz[jz] * p->wx[jx] / (double)M;
                    for (int e = 0; e < 6; e++)
                        d[e] += t[e] * w;
                }
            }
        }
    }
}

void cg2d_profile_snapshot(cg2d_profile *p, const cg2d_particles *pt, double *prim)
{
    const cg2d_grid *g = &p->g;
    size_t nx = g->gx.n, nc = cg2d_ncell(g);
    double *acc = p->acc;
    memset(acc, 0, nc * CG_NPRIM * sizeof *acc);
    int consistent = (p->tmode == CG_T_CONSISTENT);
    /* pass 1: mass, volume, momentum (and m v v, contact stress) */
    for (size_t i = 0; i < pt->n; i++) {
        const double *v = pt->v + 3 * i;
        double m = pt->m[i];
        if (m == 0.0 && pt->vol[i] == 0.0)
            continue; /* a type not kept: adds nothing */
        size_t nwx = cg_kernel_weights(p->k, &g->gx, pt->x[i], 0.0, p->binx, p->wx);
        size_t nwz = cg_kernel_weights(p->k, &g->gz, pt->z[i], 0.0, p->binz, p->wz);
        const double a[5] = {m, pt->vol[i], m * v[0], m * v[1], m * v[2]};
        const double mvv[6] = {a[2] * v[0], a[3] * v[1], a[4] * v[2], a[2] * v[1], a[2] * v[2], a[3] * v[2]};
        const double *Si = pt->S ? pt->S + 6 * i : NULL;
        for (size_t jz = 0; jz < nwz; jz++) {
            double *row = acc + p->binz[jz] * nx * CG_NPRIM;
            for (size_t jx = 0; jx < nwx; jx++) {
                double *q = row + p->binx[jx] * CG_NPRIM, w = p->wz[jz] * p->wx[jx];
                for (int c = 0; c < 5; c++)
                    q[CG_P_RHO + c] += a[c] * w;
                if (consistent)
                    for (int c = 0; c < 6; c++)
                        q[CG_P_KXX + c] += mvv[c] * w;
                if (Si)
                    for (int c = 0; c < 6; c++)
                        q[CG_P_SXX + c] += Si[c] * w;
            }
        }
    }
    deposit_contacts(p, pt);
    double *rho = prim + CG_P_RHO * nc;
    for (size_t c = 0; c < nc; c++) {
        const double *q = acc + c * CG_NPRIM;
        double r = q[CG_P_RHO];
        rho[c] = r; /* for velocity_at */
        p->vel[c] = r > 0 ? q[CG_P_PX] / r : 0.0;
        p->vel[nc + c] = r > 0 ? q[CG_P_PY] / r : 0.0;
        p->vel[2 * nc + c] = r > 0 ? q[CG_P_PZ] / r : 0.0;
    }
    if (consistent) {
        static const int ia[6] = {0, 1, 2, 0, 0, 1}, ib[6] = {0, 1, 2, 1, 2, 2};
        for (size_t c = 0; c < nc; c++)
            for (int e = 0; e < 6; e++)
                acc[c * CG_NPRIM + CG_P_KXX + e] -= acc[c * CG_NPRIM + CG_P_RHO] *
                                                    p->vel[(size_t)ia[e] * nc + c] *
                                                    p->vel[(size_t)ib[e] * nc + c];
    } else {
        /* pass 2: fluctuations about the CG velocity at the particle */
        for (size_t i = 0; i < pt->n; i++) {
            double m = pt->m[i];
            if (m == 0.0)
                continue;
            double V[3];
            velocity_at(p, rho, pt->x[i], pt->z[i], V);
            const double *v = pt->v + 3 * i;
            double c0 = v[0] - V[0], c1 = v[1] - V[1], c2 = v[2] - V[2];
            const double mcc[6] = {m * c0 * c0, m * c1 * c1, m * c2 * c2,
                                   m * c0 * c1, m * c0 * c2, m * c1 * c2};
            size_t nwx = cg_kernel_weights(p->k, &g->gx, pt->x[i], 0.0, p->binx, p->wx);
            size_t nwz = cg_kernel_weights(p->k, &g->gz, pt->z[i], 0.0, p->binz, p->wz);
            for (size_t jz = 0; jz < nwz; jz++) {
                double *row = acc + p->binz[jz] * nx * CG_NPRIM;
                for (size_t jx = 0; jx < nwx; jx++) {
                    double *q = row + p->binx[jx] * CG_NPRIM + CG_P_KXX, w = p->wz[jz] * p->wx[jx];
                    for (int e = 0; e < 6; e++)
                        q[e] += mcc[e] * w;
                }
            }
        }
    }
    /* quantity-major, per unit length along y */
    double inv = 1.0 / pt->length_y;
    for (size_t c = 0; c < nc; c++)
        for (size_t q = 0; q < CG_NPRIM; q++)
            prim[q * nc + c] = acc[c * CG_NPRIM + q] * inv;
}

void cg2d_profile_derive(const double *prim, const cg2d_grid *g, double *f)
{
    cg2d_derive_cells(prim, cg2d_ncell(g), f);
}

void cg2d_derive_cells(const double *prim, size_t n, double *f)
{
#define PRIM(q) prim[(size_t)(q)*n + c]
#define FLD(q)  f[(size_t)(q)*n + c]
    for (size_t c = 0; c < n; c++) {
        double r = PRIM(CG_P_RHO), nan = NAN;
        FLD(CG2D_F_PHI) = PRIM(CG_P_PHI);
        FLD(CG2D_F_RHO) = r;
        FLD(CG2D_F_VX) = r > 0 ? PRIM(CG_P_PX) / r : nan;
        FLD(CG2D_F_VY) = r > 0 ? PRIM(CG_P_PY) / r : nan;
        FLD(CG2D_F_VZ) = r > 0 ? PRIM(CG_P_PZ) / r : nan;
        double trK = PRIM(CG_P_KXX) + PRIM(CG_P_KYY) + PRIM(CG_P_KZZ);
        FLD(CG2D_F_T) = r > 0 ? trK / (3.0 * r) : nan;
        FLD(CG2D_F_KXX) = PRIM(CG_P_KXX);
        FLD(CG2D_F_KZZ) = PRIM(CG_P_KZZ);
        FLD(CG2D_F_KXZ) = PRIM(CG_P_KXZ);
        double sxx = -PRIM(CG_P_KXX) + PRIM(CG_P_SXX);
        double syy = -PRIM(CG_P_KYY) + PRIM(CG_P_SYY);
        double szz = -PRIM(CG_P_KZZ) + PRIM(CG_P_SZZ);
        double sxz = -PRIM(CG_P_KXZ) + PRIM(CG_P_SXZ);
        double P = -(sxx + syy + szz) / 3.0;
        FLD(CG2D_F_P) = P;
        FLD(CG2D_F_SXX) = sxx;
        FLD(CG2D_F_SZZ) = szz;
        FLD(CG2D_F_SXZ) = sxz;
        FLD(CG2D_F_CXX) = PRIM(CG_P_SXX);
        FLD(CG2D_F_CZZ) = PRIM(CG_P_SZZ);
        FLD(CG2D_F_CXZ) = PRIM(CG_P_SXZ);
        FLD(CG2D_F_MU) = P > 0 ? fabs(sxz) / P : nan;
    }
#undef PRIM
#undef FLD
}
