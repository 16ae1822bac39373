/* homogeneous.c: steady homogeneous simple shear of the EKM (see
 * homogeneous.h and docs/model/law.md, "Steady homogeneous shear"). */
#include "homogeneous.h"

#include <math.h>

#include "root.h"

ekm_status ekm_homog_check_rate(double gdot, ekm_error *err)
{
    if (!(gdot > 0.0 && isfinite(gdot)))
        return EKM_FAIL(err, EKM_EINPUT, "gdot = %g: expected a finite shear rate > 0 [1/s]", gdot);
    return EKM_OK;
}

ekm_status ekm_homog_check_pressure(double P, double gdot, ekm_error *err)
{
    if (!(P > 0.0 && isfinite(P)))
        return EKM_FAIL(err, EKM_EINPUT, "P = %g: expected a finite pressure > 0 [Pa]", P);
    return ekm_homog_check_rate(gdot, err);
}

ekm_status ekm_homog_shear(const ekm_material *m, ekm_variant v, double phi, double gdot,
                           ekm_homog_state *out, ekm_error *err)
{
    if (!(phi > 0.0 && phi < m->phi_cp))
        return EKM_FAIL(err, EKM_EINPUT, "phi = %g: expected a volume fraction in (0, phi_cp = %g)", phi,
                        m->phi_cp);
    const ekm_status cst = ekm_homog_check_rate(gdot, err);
    if (cst != EKM_OK)
        return cst;
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

typedef struct {
    const ekm_material *m;
    ekm_variant v;
    double P, gdot; /* [Pa], [1/s] */
} pressure_target;

/* log(P(phi) / P) of the steady shear at gdot; NAN outside (0, phi_cp) */
static double pressure_mismatch(double phi, void *params)
{
    const pressure_target *q = params;
    ekm_homog_state h;
    ekm_error e;
    if (ekm_homog_shear(q->m, q->v, phi, q->gdot, &h, &e) != EKM_OK)
        return NAN;
    return log(h.P / q->P);
}

ekm_status ekm_homog_shear_at_pressure(const ekm_material *m, ekm_variant v, double P, double gdot,
                                       ekm_homog_state *out, ekm_error *err)
{
    const ekm_status cst = ekm_homog_check_pressure(P, gdot, err);
    if (cst != EKM_OK)
        return cst;
    const double rK = m->rho_p * 2.0 * m->eta0 * gdot * gdot / (3.0 * m->eps0); /* rho_p phi T [Pa] */
    if (!(P > rK))
        return EKM_FAIL(
            err, EKM_EINPUT,
            "P = %g, gdot = %g: expected P above the dilute limit rho_p 2 eta0 gdot^2 / (3 eps0) = "
            "%g Pa (no volume fraction gives a lower pressure at this rate)",
            P, gdot, rK);
    if (m->g_beta == 1.0) { /* P = rho_p g (phi T + T0 (phi - phi_co)_+), phi T = rK/rho_p */
        double phi = m->phi_cp * (1.0 - rK / P);
        if (phi > m->phi_co)
            phi = m->phi_cp * (P - rK + m->rho_p * m->T0 * m->phi_co) / (P + m->rho_p * m->phi_cp * m->T0);
        return ekm_homog_shear(m, v, phi, gdot, out, err);
    }
    /* P rises with phi from rK at phi -> 0 to infinity at phi_cp: its root */
    pressure_target q = {m, v, P, gdot};
    double lo = 1e-12 * m->phi_cp, hi = m->phi_cp * (1.0 - 1e-15);
    if (!(pressure_mismatch(lo, &q) < 0.0 && pressure_mismatch(hi, &q) > 0.0))
        return EKM_FAIL(err, EKM_ENUMERIC, "P = %g, gdot = %g: no volume fraction in (0, phi_cp) brackets it",
                        P, gdot);
    double phi;
    ekm_error rerr;
    if (ekm_root_bracketed(pressure_mismatch, &q, lo, hi, &phi, &rerr) != EKM_OK)
        return EKM_FAIL(err, rerr.code, "P = %g, gdot = %g: the volume fraction at this pressure: %s", P,
                        gdot, rerr.message);
    return ekm_homog_shear(m, v, phi, gdot, out, err);
}
