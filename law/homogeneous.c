/* homogeneous.c: steady homogeneous simple shear of the EKM (see
 * homogeneous.h and docs/model/law.md, "Steady homogeneous shear"). */
#include "homogeneous.h"

#include <math.h>

ekm_status ekm_homog_shear(const ekm_material *m, ekm_variant v, double phi, double gdot,
                           ekm_homog_state *out, ekm_error *err)
{
    if (!(phi > 0.0 && phi < m->phi_cp))
        return EKM_FAIL(err, EKM_EINPUT, "phi = %g: expected a volume fraction in (0, phi_cp = %g)", phi,
                        m->phi_cp);
    if (!(gdot > 0.0 && isfinite(gdot)))
        return EKM_FAIL(err, EKM_EINPUT, "gdot = %g: expected a finite shear rate > 0 [1/s]", gdot);
    /* The root of the local temperature source with u'^2 = gdot^2, w' = 0:
     * the quadratic (T + nu Y)(phi eps0 T - 2/3 eta0 gdot^2) = 0 of model.c,
     * whose only non-negative root is the one returned. */
    const double T = ekm_temperature_local_balance(m, v, phi, gdot * gdot, 0.0);
    if (!(T > 0.0 && isfinite(T)))
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "phi = %g, gdot = %g: the temperature balance has no positive root (T = %g)", phi,
                        gdot, T);
    const ekm_slab_stress s = ekm_stress_slab(m, v, phi, T, gdot, 0.0);
    out->T = T;
    out->P_K = ekm_pressure_kinetic(m, phi, T);
    out->P_Y = ekm_pressure_yield(m, phi);
    out->r = out->P_Y / out->P_K;
    out->P = s.P;
    out->sxz = fabs(s.sigma_xz);
    out->mu = out->sxz / out->P;
    out->phi = phi;
    return EKM_OK;
}

ekm_status ekm_homog_shear_at_pressure(const ekm_material *m, ekm_variant v, double P, double gdot,
                                       ekm_homog_state *out, ekm_error *err)
{
    if (!(P > 0.0 && isfinite(P)))
        return EKM_FAIL(err, EKM_EINPUT, "P = %g: expected a finite pressure > 0 [Pa]", P);
    if (!(gdot > 0.0 && isfinite(gdot)))
        return EKM_FAIL(err, EKM_EINPUT, "gdot = %g: expected a finite shear rate > 0 [1/s]", gdot);
    const double rK = m->rho_p * 2.0 * m->eta0 * gdot * gdot / (3.0 * m->eps0); /* rho_p phi T [Pa] */
    if (!(P > rK))
        return EKM_FAIL(
            err, EKM_EINPUT,
            "P = %g, gdot = %g: expected P above the dilute limit rho_p 2 eta0 gdot^2 / (3 eps0) = "
            "%g Pa (no volume fraction gives a lower pressure at this rate)",
            P, gdot, rK);
    double phi = m->phi_cp * (1.0 - rK / P);
    if (phi > m->phi_co)
        phi = m->phi_cp * (P - rK + m->rho_p * m->T0 * m->phi_co) / (P + m->rho_p * m->phi_cp * m->T0);
    return ekm_homog_shear(m, v, phi, gdot, out, err);
}
