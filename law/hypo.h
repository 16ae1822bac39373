/* hypo.h: the hypoplastic (solid-like) regime of the EKM in the slab, as
 * pure functions (docs/model-notes.md section 4, docs/model/solid.md "Solid regime").
 *
 * Full variant (cleaned tensor form of thesis 5.4.8-5.4.11), stress state
 * sigma_xx, sigma_yy, sigma_zz, sigma_xz [Pa] (negative in compression),
 * strain rate kappa_xz = u'/2, kappa_zz = w', tr(kappa) = w':
 *
 *   d(sigma)/dt = f(phi) ( L : kappa - N ||kappa|| )
 *   L : kappa   = A_h tr(kappa) I + 2 B_h kappa
 *   ||kappa||   = sqrt(gdot^2 + zeta0/(2 eta0) tr(kappa)^2),
 *                 gdot^2 = u'^2/2 + (2/3) w'^2                     [1/s]
 *   N           = (3 A_h + 2 B_h) a1 q I + 2 B_h a2 sigma^D / P_Y,
 *                 q = (tr(sigma) + 3 P_Y) / P_Y
 *   a1 = (2/(9 zeta0)) sqrt(phi eta0/(3 eps0)),  a2 = sqrt(phi/(3 eta0 eps0))
 *   f(phi) = ((phi - phi_co)/(phi_cp - phi))^alpha                 [-]
 *
 * Its stationary states lie on the EKM limit surface
 *
 *   f_Y = [(tr sigma + 3 P_Y)^2 + (9 zeta0/(2 eta0)) sigma_s^2]
 *         / [(27 zeta0 eps0/(2 phi)) P_Y^2] - 1 = 0
 *
 * (normalised: dimensionless, 0 on the surface, < 0 inside), with the
 * EKM's quasi-static flow rule.  Uniaxial compression (u' = 0, w' < 0)
 * saturates at sigma_zz = -P_Y (1 + R), R = sqrt(3 eps0 (4/3 eta0 + zeta0)
 * / (2 phi)).
 *
 * Thesis variant (1D law 6.2.31, bulk viscosity only): one scalar stress
 * sigma = sigma_xx = sigma_yy = sigma_zz,
 *
 *   d(sigma)/dt = f(phi) A_h ( w' - (sigma + P_Y)/(R P_Y) |w'| ),
 *   R = sqrt(3 eps0 zeta0 / (2 phi)),  f_Y = ((sigma + P_Y)/(R P_Y))^2 - 1;
 *
 * the shear stress follows the deviatoric part of the full law (the thesis
 * has none).  The thesis's Chapter 5 typos (docs/model-notes.md section 10) are not copied:
 * L^-1 is never needed, N is derived afresh from the flow rule, and f
 * scales the stiffness.
 *
 * Loose cells (phi <= phi_co, P_Y = 0: the partially filled surface cell
 * of a bed) have no limit surface; for them the law is its elastic part
 * f L : kappa alone, and the stepper lets them be solid only on top of a
 * solid cell and while in compression.
 *
 * Time integration (the stepper): backward Euler in kappa with ||kappa||
 * lagged and N linear in sigma taken implicitly ("linearly implicit"):
 * every stress component is then sigma^{n+1} = E + V * (velocity gradient
 * at n+1), which the momentum solves take as a known stress E and a
 * viscosity V.  The scheme is unconditionally stable and its fixed point
 * under a constant rate is exactly the limit state.
 */
#ifndef EKM_HYPO_H
#define EKM_HYPO_H

#include "model.h"

/* Slab stress state of a solid cell [Pa]. */
typedef struct {
    double xx, yy, zz, xz;
} ekm_hypo_stress;

/* Density factor f(phi) of the stiffness (0 at phi <= phi_co). */
double ekm_hypo_density_factor(const ekm_material *m, double phi);

/* R of the variant at phi (docs/model-notes.md section 4). */
double ekm_hypo_R(const ekm_material *m, ekm_variant v, double phi);

/* ||kappa|| [1/s] for u' = du_dz, w' = dw_dz (thesis variant: |w'|). */
double ekm_hypo_rate_norm(const ekm_material *m, ekm_variant v, double du_dz, double dw_dz);

/* d(sigma)/dt [Pa/s] of the rate law at phi for the given gradients. */
ekm_hypo_stress ekm_hypo_rate(const ekm_material *m, ekm_variant v, double phi, const ekm_hypo_stress *s,
                              double du_dz, double dw_dz);

/* Plane-strain rates (x, z in the plane, v_y = 0) [1/s]: exx = dvx/dx,
 * ezz = dvz/dz, gxz = dvx/dz + dvz/dx (= 2 kappa_xz); the slab's are
 * exx = 0, ezz = w', gxz = u'. */
typedef struct {
    double exx, ezz, gxz;
} ekm_hypo_plane_rate;

/* ||kappa|| [1/s] of the full variant for plane rates r:
 * sqrt(kappa^D : kappa^D + zeta0/(2 eta0) tr(kappa)^2). */
double ekm_hypo_rate_norm_plane(const ekm_material *m, const ekm_hypo_plane_rate *r);

/* d(sigma)/dt [Pa/s] of the rate law in plane strain (the 2D solver), with
 * the norms of its plastic part given: knorm = ||kappa|| (full norm, both
 * variants' shear part and the full variant's normal part) and ktr =
 * |tr kappa| (the thesis variant's normal part), so that a stepper may lag
 * them; L : kappa takes the rates r.  ekm_hypo_rate is this with r =
 * {0, w', u'} and its own norms. */
ekm_hypo_stress ekm_hypo_rate_plane(const ekm_material *m, ekm_variant v, double phi,
                                    const ekm_hypo_stress *s, const ekm_hypo_plane_rate *r, double knorm,
                                    double ktr);

/* The sum of the magnitudes of the terms of ekm_hypo_rate_plane, per
 * component [Pa/s] (same arguments): the scale of a stepper's residual of
 * the law, whose terms cancel where the stress is in equilibrium with the
 * rates (a bed at rest), so that |d(sigma)/dt| is no scale there. */
ekm_hypo_stress ekm_hypo_rate_plane_magnitude(const ekm_material *m, ekm_variant v, double phi,
                                              const ekm_hypo_stress *s, const ekm_hypo_plane_rate *r,
                                              double knorm, double ktr);

/* Normalised limit-surface function f_Y (0 on the surface, < 0 inside);
 * +inf when P_Y = 0 (no solid state below phi_co). */
double ekm_hypo_yield(const ekm_material *m, ekm_variant v, double phi, const ekm_hypo_stress *s);

/* The EKM (flow) stress at (phi, T) and the gradients, in the solid's
 * components: the initial solid stress at a flow -> solid switch and the
 * comparison stress at solid -> flow. */
ekm_hypo_stress ekm_hypo_from_flow(const ekm_material *m, ekm_variant v, double phi, double T, double du_dz,
                                   double dw_dz);

/* Below phi_co (no yield part, Y = 0) the EKM normal stress is
 * -P_K0 T + mu_n0 sqrt(T) w' (P_K, mu_n at T = 1 times T, sqrt(T)): the
 * temperature T >= 0 at which it equals sigma_zz (the larger root), or -1
 * if there is none (or phi > phi_co).  A solid cell that leaves the solid
 * state below phi_co (it has no limit surface there) restarts its flow
 * with this T, so that its normal stress is continuous. */
double ekm_hypo_flow_T_for_stress(const ekm_material *m, ekm_variant v, double phi, double dw_dz,
                                  double sigma_zz);

/* One linearly implicit step of length dt: with ||kappa^n|| from the
 * gradients at the start of the step (lagged), the new stress is
 *   zz = Ezz + Vzz w',  xx = Exx + Vxx w',  yy = Exx + Vxx w',
 *   xz = Exz + Vxz u'      (Exz = sigma_xz^n * xz_scale)
 * with w', u' the gradients at the end of the step. */
typedef struct {
    double Ezz, Vzz;      /* [Pa], [Pa s] */
    double Exx, Vxx, Eyy; /* [Pa], [Pa s], [Pa] */
    double xz_scale;      /* 1/(1 + c_d) [-] */
    double Vxz;           /* [Pa s] */
} ekm_hypo_implicit;

ekm_hypo_implicit ekm_hypo_prepare(const ekm_material *m, ekm_variant v, double phi, double dt,
                                   const ekm_hypo_stress *s, double du_dz_old, double dw_dz_old);

/* Relaxation rate [1/s] of the law's plastic part N ||kappa|| at phi for
 * the gradients (the largest of its volumetric and deviatoric parts, per
 * unit stress): dt times it is the relaxation of one step, which the
 * lagged ||kappa|| makes first-order accurate only while it is small (the
 * stepper's accuracy limit for solid cells).  0 for a loose cell. */
double ekm_hypo_relaxation_rate(const ekm_material *m, ekm_variant v, double phi, double du_dz, double dw_dz);
/* ... for the plane rates r (the slab's: {0, w', u'}). */
double ekm_hypo_relaxation_rate_plane(const ekm_material *m, ekm_variant v, double phi,
                                      const ekm_hypo_plane_rate *r);

/* Apply a prepared step: the new stress for the end-of-step gradients. */
ekm_hypo_stress ekm_hypo_finish(const ekm_hypo_implicit *c, double sigma_xz_old, double du_dz, double dw_dz);

/* The same step in plane strain (the 2D step), the norms lagged on the
 * plane rates r_old at the start of the step (the slab's: {0, w', u'};
 * ekm_hypo_prepare is this).  The backward-Euler step of the law splits
 * into its trace and its deviator, each linear in the new rates:
 *   zz = Ezz + Vzz ezz + Vxx exx,  xx = Exx + Vzz exx + Vxx ezz,
 *   yy = Eyy + Vxx (exx + ezz),    xz = Exz + Vxz gxz
 * (thesis variant: Vxx = Vzz, one normal stress of tr kappa). */
ekm_hypo_implicit ekm_hypo_prepare_plane(const ekm_material *m, ekm_variant v, double phi, double dt,
                                         const ekm_hypo_stress *s, const ekm_hypo_plane_rate *r_old);

/* Apply a prepared plane step for the end-of-step rates r. */
ekm_hypo_stress ekm_hypo_finish_plane(const ekm_hypo_implicit *c, double sigma_xz_old,
                                      const ekm_hypo_plane_rate *r);

#endif
