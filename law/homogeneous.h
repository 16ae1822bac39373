/* homogeneous.h: the EKM's steady homogeneous simple shear at a given
 * volume fraction and shear rate, evaluated with libekm's own
 * constitutive functions (model.h).
 *
 * Simple shear u(z) = gdot z, w = 0, no gradients of phi or T: the
 * temperature equation reduces to the local balance S(T) = 0,
 *
 *   2/3 eta(T) gdot^2 = rho_p phi eps(T) T,
 *
 * in which eta and eps carry the same factor (1 + nu r(T)), r = Y/T > 0;
 * it cancels for every nu and both variants (w' = 0: the normal viscosity
 * never enters), leaving T = 2 eta0 gdot^2 / (3 phi eps0) (docs/model/law.md,
 * "Steady homogeneous shear").  Then P = P_K + P_Y, |sigma_xz| = eta gdot
 * and mu = |sigma_xz| / P.  gdot = |du/dz| (docs/model-notes.md section 7), not the
 * invariant sqrt(kappa^D : kappa^D).
 */
#ifndef EKM_HOMOGENEOUS_H
#define EKM_HOMOGENEOUS_H

#include "model.h"
#include "status.h"

typedef struct {
    double T;   /* granular temperature [m^2/s^2] */
    double P;   /* pressure P_K + P_Y [Pa] */
    double P_K; /* kinetic pressure [Pa] */
    double P_Y; /* yield pressure [Pa] */
    double r;   /* P_Y / P_K [-] */
    double sxz; /* |sigma_xz| [Pa] */
    double mu;  /* |sigma_xz| / P [-] */
    double phi; /* the volume fraction [-] (given, or found at a given P) */
} ekm_homog_state;

/* The checks every closure's homogeneous shear makes of its control
 * (closure.h): a finite shear rate gdot > 0 [1/s], and a finite pressure
 * P > 0 [Pa]; EKM_EINPUT naming the value. */
ekm_status ekm_homog_check_rate(double gdot, ekm_error *err);
ekm_status ekm_homog_check_pressure(double P, double gdot, ekm_error *err);

/* The steady state at volume fraction phi in (0, phi_cp) and shear rate
 * gdot = |du/dz| > 0 [1/s].  EKM_EINPUT (naming phi or gdot) when out of
 * range; EKM_ENUMERIC if the balance has no positive finite root. */
ekm_status ekm_homog_shear(const ekm_material *m, ekm_variant v, double phi, double gdot,
                           ekm_homog_state *out, ekm_error *err);

/* The same state at a given pressure P > 0 [Pa] and shear rate gdot > 0
 * (pressure control): with K = 2 eta0 gdot^2 / (3 eps0) = phi T,
 * P = rho_p g(phi) (K + T0 (phi - phi_co)_+) rises with phi, and its
 * inverse is closed when g_beta = 1:
 *   phi = phi_cp (1 - rho_p K / P)                              if that is <= phi_co,
 *   phi = phi_cp (P - rho_p K + rho_p T0 phi_co) / (P + rho_p phi_cp T0)  otherwise;
 * else phi is the root of P(phi) on (0, phi_cp) (GSL's Brent solver;
 * EKM_ENUMERIC if not found).
 * EKM_EINPUT when P <= rho_p K (the dilute limit of P at this rate: no
 * volume fraction gives so low a pressure). */
ekm_status ekm_homog_shear_at_pressure(const ekm_material *m, ekm_variant v, double P, double gdot,
                                       ekm_homog_state *out, ekm_error *err);

#endif
