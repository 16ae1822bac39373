/* mu_i.h: the mu(I) rheology of dense granular flow as pure functions,
 * the closure style `mu_i` (law/closure.h; docs/model/closures.md).
 *
 * Jop, Forterre and Pouliquen (2006, Nature 441, 727): with the inertial
 * number I = gdot d / sqrt(P / rho_p) [-] (gdot = |du/dz| in simple shear,
 * the norm sqrt(gdot_ij gdot_ij / 2) of the strain-rate tensor
 * gdot_ij = du_i/dx_j + du_j/dx_i in general),
 *
 *   mu(I)  = mu_s + (mu_2 - mu_s) / (I_0 / I + 1)    friction   [-]
 *   tau_ij = mu(I) P gdot_ij / |gdot|                 deviatoric stress
 *
 * and the dilatancy law (Forterre and Pouliquen 2008, Annu. Rev. Fluid
 * Mech. 40, 1; da Cruz et al. 2005, Phys. Rev. E 72, 021309)
 *
 *   phi(I) = phi_max - (phi_max - phi_min) I,
 *
 * so that at a volume fraction phi < phi_max the flow has
 * I(phi) = (phi_max - phi) / (phi_max - phi_min) and P = rho_p (d gdot / I)^2.
 * The closure has no granular temperature.
 */
#ifndef EKM_MU_I_H
#define EKM_MU_I_H

#include "status.h"

/* The parameters of the mu_i closure ([material] keys of the same names). */
typedef struct {
    double rho_p;   /* particle material density [kg/m^3] */
    double mu_s;    /* friction at I -> 0 [-] */
    double mu_2;    /* friction at I -> infinity [-] */
    double I_0;     /* inertial number of the transition [-] */
    double phi_max; /* volume fraction at I -> 0 [-] */
    double phi_min; /* volume fraction at I = 1 [-] */
    double d;       /* grain diameter [m] */
} ekm_mu_i_params;

/* Ranges: rho_p, I_0, d > 0; 0 <= mu_s < mu_2; 0 < phi_min < phi_max < 1.
 * The message names the [material] key. */
ekm_status ekm_mu_i_check(const ekm_mu_i_params *p, ekm_error *err);

/* mu(I) for I >= 0 (mu(0) = mu_s). */
double ekm_mu_i_friction(const ekm_mu_i_params *p, double I);

/* The inverse of mu(I) on (mu_s, mu_2): I = I_0 (mu - mu_s) / (mu_2 - mu);
 * NAN outside that interval (no steady flow at that stress ratio). */
double ekm_mu_i_inertial_number_of_friction(const ekm_mu_i_params *p, double mu);

/* The dilatancy law phi(I) and its inverse I(phi) = (phi_max - phi) /
 * (phi_max - phi_min), NAN for phi >= phi_max or phi <= 0 (no flow at a
 * finite pressure). */
double ekm_mu_i_phi_of_I(const ekm_mu_i_params *p, double I);
double ekm_mu_i_I_of_phi(const ekm_mu_i_params *p, double phi);

/* Pressure at inertial number I > 0 and shear rate gdot [1/s]:
 * P = rho_p (d gdot / I)^2 [Pa]. */
double ekm_mu_i_pressure(const ekm_mu_i_params *p, double I, double gdot);

/* The inertial number at pressure P > 0 [Pa] and shear rate |gdot| [1/s]:
 * I = |gdot| d / sqrt(P / rho_p). */
double ekm_mu_i_inertial_number(const ekm_mu_i_params *p, double P, double gdot);

/* The regularised shear stress of the slab solver (continuum/local_slab.h)
 * at pressure P > 0 [Pa] and shear rate gdot = du/dz [1/s]:
 *
 *   tau = mu(I) P gdot / sqrt(gdot^2 + gdot_min^2)   [Pa],  I from |gdot|,
 *
 * the viscosity mu(I) P / |gdot| with its divergence at gdot -> 0 cut at
 * gdot_min > 0 [1/s] (docs/model/closures.md, "Regularisation"); the
 * derivative dtau/dgdot [Pa s] (> 0) into *dtau. */
double ekm_mu_i_shear_stress(const ekm_mu_i_params *p, double P, double gdot, double gdot_min, double *dtau);

#endif
