/* cg2d.h: coarse-grained fields of one snapshot on a 2D grid (x, z),
 * averaged over the third axis y (`ekmcompare cg --axes x,z`).
 *
 * The 2D kernel is the product W(x - x_i) W(z - z_i) of the 1D kernels of
 * kernel.h (gauss: the 2D Gaussian, cut on the square |x|, |z| <= 3w and
 * renormalised; lucy: the product of two 1D Lucy kernels, not the radial
 * 2D Lucy kernel). A particle's weight in cell (i, k) is the kernel's
 * integral over the cell divided by its area, which for a product kernel
 * is exactly the product of the two 1D bin weights: the kernel is
 * evaluated exactly, per particle (no sub-grid), the weights sum to one
 * (mass and volume are conserved to round-off), periodic axes wrap it and
 * walls reflect it, axis by axis, as in 1D. `bins` (sphere-slab volumes)
 * has no exact product form and is refused in 2D.
 *
 * Per snapshot, with L_y the box length along the averaged axis and
 * W_i,c the weight [1/m^2] of particle i in cell c, the primaries of cg.h
 * (enum cg_prim) per cell: rho_c = sum m_i W_ic / L_y, and so on; the
 * fields (enum cg2d_field) are derived from them as in 1D: V = p/rho,
 * T = tr(K)/(3 rho), sigma = -K + S, P = -tr(sigma)/3, mu = |sxz|/P.
 * Fluctuations c_i = v_i - V(x_i, z_i), V interpolated bilinearly between
 * cell centres (empty cells skipped; CG_T_PARTICLE), or c_i = v_i - V_c
 * (CG_T_CONSISTENT: K = sum m v v W / L_y - rho V V).
 * Contact stress: per-atom S_i (as 1D), or from a pair dump the line
 * integral along each branch b = r_i - r_j, S_c = -sum sym(f b) Wbar / L_y,
 * Wbar the 2D weight averaged over the branch (midpoint rule, points at
 * most dx/16 apart along x and dz/16 along z).
 */
#ifndef CG_CG2D_H
#define CG_CG2D_H

#include <stddef.h>

#include "cg.h"
#include "kernel.h"
#include "status.h"

/* Output fields of the 2D grid, stored field-major: f * ncell + c. */
enum cg2d_field {
    CG2D_F_PHI,
    CG2D_F_RHO,
    CG2D_F_VX,
    CG2D_F_VY,
    CG2D_F_VZ,
    CG2D_F_T,
    CG2D_F_KXX, /* kinetic stress (>= 0 on the diagonal) */
    CG2D_F_KZZ,
    CG2D_F_KXZ,
    CG2D_F_P,   /* pressure -tr(sigma)/3 */
    CG2D_F_SXX, /* total stress sigma = -K + S (negative in compression) */
    CG2D_F_SZZ,
    CG2D_F_SXZ,
    CG2D_F_CXX, /* contact stress S (with --stress) */
    CG2D_F_CZZ,
    CG2D_F_CXZ,
    CG2D_F_MU, /* |sxz|/P (with --stress) */
    CG2D_NFIELD
};
#define CG2D_NFIELD_KINETIC CG2D_F_CXX /* fields without a contact stress */

/* The most blocks one averaging window keeps (cg_blocks bmax) for its
 * standard errors (cg2d_run.h). */
#define CG2D_BLOCKS 16

/* Name of 2D field f ("phi"; units in the field schema, common/schema.h). */
const char *cg2d_field_name(int f);

/* The grid: cells (ix, iz), cell index c = iz * gx.n + ix (x fastest, as
 * the HDF5 datasets [nt][nz][nx]). */
typedef struct {
    cg_grid gx; /* along x (axis 0) */
    cg_grid gz; /* along z (axis 2) */
} cg2d_grid;

static inline size_t cg2d_ncell(const cg2d_grid *g)
{
    return g->gx.n * g->gz.n;
}

/* One snapshot's particles. */
typedef struct {
    size_t n;          /* particles */
    const double *x;   /* coordinate along x [m] */
    const double *z;   /* coordinate along z [m] */
    const double *v;   /* velocities, 3 per particle [m/s] */
    const double *m;   /* masses [kg] (0: a type not kept) */
    const double *vol; /* volumes [m^3] */
    const double *S;   /* contact stress x volume, 6 per particle [Pa m^3], or NULL */
    double length_y;   /* box length along the averaged axis y [m] */
    size_t nc;         /* contacts (pair dump), or 0 */
    const double *cx;  /* partner j's coordinate along x [m] */
    const double *cz;  /* partner j's coordinate along z [m] */
    const double *cb;  /* branch vectors r_i - r_j, 3 per contact [m] */
    const double *cf;  /* forces on i by j, 3 per contact [N] */
} cg2d_particles;

typedef struct {
    const cg_kernel *k; /* (not owned) */
    cg2d_grid g;
    cg_tmode tmode;
    size_t maxw;  /* most 1D weights of one particle along x or z */
    size_t *binx; /* scratch: 1D weights of one particle */
    double *wx;   /* [1/m] */
    size_t *binz;
    double *wz;
    double *acc; /* sums, cell-major: ncell x CG_NPRIM */
    double *vel; /* V per cell, 3 x ncell [m/s] */
} cg2d_profile;

ekm_status cg2d_profile_alloc(cg2d_profile **p, const cg_kernel *k, const cg2d_grid *g, cg_tmode tmode,
                              ekm_error *err);
void cg2d_profile_free(cg2d_profile *p);

/* Primary sums of one snapshot into prim (CG_NPRIM x ncell, overwritten). */
void cg2d_profile_snapshot(cg2d_profile *p, const cg2d_particles *pt, double *prim);

/* Fields (CG2D_NFIELD x ncell) from (averaged) primaries. */
void cg2d_profile_derive(const double *prim, const cg2d_grid *g, double *fields);

/* The same for n cells of any layout q * n + c (n = 1: one cell). */
void cg2d_derive_cells(const double *prim, size_t n, double *fields);

#endif
