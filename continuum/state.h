/* state.h: the slab grid and the solution on it.
 *
 * Staggered finite-volume grid (thesis 6.3.14): n cells of height dz cover
 * z in [0, L]; cell j has centre z_j = (j + 1/2) dz and holds the scalars
 * phi, T and the tangential velocity u; face f (f = 0..n) at z = f dz holds
 * the normal velocity w.  Face 0 is the bottom boundary, face n the top.
 */
#ifndef EKM_STATE_H
#define EKM_STATE_H

#include "scenario.h"
#include "status.h"

typedef struct {
    int n;          /* number of cells */
    double dz;      /* cell height [m] */
    double *z;      /* cell centres [m], n */
    double *phi;    /* solid volume fraction [-], n */
    double *T;      /* granular temperature per degree of freedom [m^2/s^2], n */
    double *u;      /* tangential velocity v_x at centres [m/s], n */
    double *w;      /* normal velocity v_z at faces [m/s], n + 1 */
    double t;       /* time [s] */
    long steps;     /* accepted time steps */
    double mass_in; /* net mass entered through the boundaries per area [kg/m^2] */
    /* Solid (hypoplastic) regime, hypo.h: */
    unsigned char *solid;    /* 1: the cell is solid, n */
    double *sxx, *syy, *szz; /* stress of solid cells [Pa], n (flow cells: unused) */
    double *sxz;             /* shear stress at faces [Pa], n + 1: the rate law's state on faces
                              * between two solid cells (or a solid cell and a wall), the
                              * flow's face stress elsewhere */
    double *rate_prev;       /* sqrt(u'^2 + w'^2) of each cell after the previous accepted step [1/s], n
                              * (the regime switching's test for growing rates, regime.h) */
} ekm_state;

ekm_state *ekm_state_alloc(int n, double length);
void ekm_state_free(ekm_state *s);
/* Copy values (same n) from src to dst. */
void ekm_state_copy(ekm_state *dst, const ekm_state *src);
/* Copy only what a time step changes before it is accepted (the backup of
 * a step, step.h): phi, T, u, w, t, steps, mass_in; with grid != 0 also
 * dz and z (a stretching grid); with solid != 0 the solid stresses sxx,
 * syy, szz, sxz ([hypo] enabled).  solid and rate_prev change only after
 * a step is accepted (regime.h). */
void ekm_state_copy_step(ekm_state *dst, const ekm_state *src, int grid, int solid);

/* Initial condition of a scenario (phi, T, u below layer_height, w = 0;
 * [initial] solid = 1: material cells start solid with the isotropic stress
 * -stress_ratio P_Y). */
void ekm_state_init(ekm_state *s, const ekm_scenario *sc);

/* Mass per lateral area, sum rho_p phi dz [kg/m^2]. */
double ekm_state_mass(const ekm_state *s, double rho_p);

#endif
