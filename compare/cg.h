/* cg.h: coarse-grained fields of one snapshot, and the derived profiles
 * (docs/model-notes.md section 8).
 *
 * Per snapshot, on the bins of a cg_grid along the profile axis s, with
 * lateral area A and bin weights W_ik of particle i in bin k [1/m]:
 *   rho_k = sum_i m_i W_ik / A                 [kg/m^3]
 *   phi_k = sum_i V_i W_ik / A                 [-]
 *   p_k   = sum_i m_i v_i W_ik / A             [kg/(m^2 s)]
 *   K_k   = sum_i m_i c_i c_i W_ik / A         [Pa] (kinetic stress, >= 0)
 *   S_k   = sum_i S_i W_ik / A                 [Pa] (contact stress)
 * with c_i = v_i - V(s_i) (CG velocity V = p/rho interpolated at the
 * particle: CG_T_PARTICLE, the default) or c_i = v_i - V_k
 * (CG_T_CONSISTENT: K = sum m v v W / A - rho V V). S_i is the per-atom
 * stress x volume of LAMMPS `compute stress/atom` [Pa m^3], sign as the
 * engine's (negative in compression, as ours). Or, from a pair dump, the
 * contact part is the line integral of the kernel along each branch vector
 * b = r_i - r_j (Goldhirsch): S_k = -sum_c sym(f_c b_c) Wbar_ck / A, with
 * Wbar the kernel weight averaged over the branch (midpoint rule with
 * points at most one sub-grid spacing apart), f_c the force on i by j.
 * These "primary" sums are linear in the particles and are averaged over
 * snapshots; the fields are derived from the averages:
 *   V = p/rho, T = tr(K)/(3 rho), sigma = -K + S, P = -tr(sigma)/3,
 *   mu = |sigma_xz|/P, I = gammadot d / sqrt(P/rho_p), gammadot = |dV_x/ds|.
 */
#ifndef CG_CG_H
#define CG_CG_H

#include <stddef.h>

#include "status.h"
#include "kernel.h"

/* Primary (snapshot-additive) quantities, stored quantity-major: q*n + k. */
enum cg_prim {
    CG_P_RHO,
    CG_P_PHI,
    CG_P_PX,
    CG_P_PY,
    CG_P_PZ,
    CG_P_KXX,
    CG_P_KYY,
    CG_P_KZZ,
    CG_P_KXY,
    CG_P_KXZ,
    CG_P_KYZ,
    CG_P_SXX,
    CG_P_SYY,
    CG_P_SZZ,
    CG_P_SXY,
    CG_P_SXZ,
    CG_P_SYZ,
    CG_NPRIM
};

/* Output fields, stored field-major: f*n + k. */
enum cg_field {
    CG_F_PHI,
    CG_F_RHO,
    CG_F_VX,
    CG_F_VY,
    CG_F_VZ,
    CG_F_T,
    CG_F_P,
    CG_F_SXZ,
    CG_F_SZZ,
    CG_F_MU,
    CG_F_I,
    CG_NFIELD
};

typedef enum { CG_T_PARTICLE, CG_T_CONSISTENT } cg_tmode;

/* Name of output field f ("phi"); its units and description are in the
 * field schema (common/schema.h). */
const char *cg_field_name(int f);

/* One snapshot's particles, already reduced to what the CG needs. */
typedef struct {
    size_t n;          /* particles */
    const double *s;   /* coordinate along the profile axis [m] */
    const double *v;   /* velocities, 3 per particle [m/s] */
    const double *m;   /* masses [kg] */
    const double *vol; /* volumes [m^3] */
    const double *rad; /* radii [m] */
    const double *S;   /* contact stress x volume, 6 per particle (xx yy zz
                          xy xz yz) [Pa m^3], or NULL */
    double area;       /* lateral area of the box normal to the axis [m^2] */
    size_t nc;         /* contacts (pair dump), or 0 */
    const double *cs;  /* coordinate of contact partner j along the axis [m] */
    const double *cb;  /* branch vectors r_i - r_j, 3 per contact [m] */
    const double *cf;  /* forces on i by j, 3 per contact [N] */
} cg_particles;

typedef struct {
    const cg_kernel *k; /* kernel (not owned) */
    cg_grid g;          /* output grid */
    cg_tmode tmode;     /* fluctuation definition for K and T */
    size_t maxw;        /* most weights of one particle */
    size_t cap;         /* capacity of bin/w (all particles of a snapshot) */
    size_t *bin;        /* bins of every particle, pass 1 -> pass 2 */
    double *w;          /* their weights [1/m] */
    size_t ncap;        /* capacity of nw */
    unsigned *nw;       /* number of weights of each particle */
    double *vel;        /* scratch: V per bin, 3 x n [m/s] */
    double *acc;        /* scratch: sums, bin-major, n x CG_NPRIM */
    /* sub-grid path (gauss, lucy; see cg_profile_alloc) */
    int sub;      /* 1: deposit on the sub-grid, then spread */
    size_t nnode; /* sub-grid nodes */
    double x0, h; /* position of node 0 and node spacing [m] */
    size_t *noff; /* node j's weights: noff[j] .. noff[j+1]-1 */
    size_t *nbin; /* their bins */
    double *nwt;  /* their weights [1/m] */
    double *node; /* scratch: sums per node, nnode x CG_NPRIM */
} cg_profile;

/* exact: 1 evaluates the kernel for every particle; 0 (the fast default
 * for gauss and lucy) deposits each particle linearly (cloud-in-cell) on a
 * sub-grid of spacing h = dz/CG_SUBGRID and spreads the nodes with the
 * kernel's exact bin weights. The sub-grid conserves mass and momentum
 * exactly and widens the kernel's variance by a(1-a) h^2 <= h^2/4 for a
 * particle at fraction a between nodes (with dz <= w/2, <= w^2/4096). The
 * bins kernel depends on each particle's radius and is always exact. */
#define CG_SUBGRID 16
ekm_status cg_profile_alloc(cg_profile **p, const cg_kernel *k, const cg_grid *g, cg_tmode tmode, int exact,
                            ekm_error *err);
void cg_profile_free(cg_profile *p);

/* Primary sums of one snapshot into prim (CG_NPRIM x n, overwritten). */
ekm_status cg_profile_snapshot(cg_profile *p, const cg_particles *pt, double *prim, ekm_error *err);

/* Fields (CG_NFIELD x n) from (averaged) primaries. d: particle diameter
 * for I [m]; rho_p: material density [kg/m^3] for I, or 0 for rho/phi. */
void cg_profile_derive(const double *prim, const cg_grid *g, double d, double rho_p, double *fields);

#endif
