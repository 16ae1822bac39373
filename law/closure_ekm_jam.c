/* closure_ekm_jam.c: the EKM with a density factor that diverges at a
 * jamming fraction with a fitted exponent, the closure style ekm_jam
 * (closure.h; docs/model/closures.md "ekm_jam"):
 *
 *   g(phi) = (1 - phi/phi_J)^(-beta)
 *
 * in place of the EKM's 1/(1 - phi/phi_cp) in every transport
 * coefficient and in both pressures, the full variant otherwise. It is
 * the EKM's transport law (model.h) with phi_cp = phi_J and g_beta = beta:
 * its two keys are those material fields under their own names, so every
 * solver runs it (phi_J also bounds the hypoplastic density factor f(phi)
 * of the solid regime, hypo.h). In the steady homogeneous shear g cancels
 * from the temperature balance (heating and dissipation both carry it):
 * T and mu are the EKM's with phi_cp = phi_J, and P, P_K, P_Y and
 * |sigma_xz| are its values times g1^(beta - 1), g1 = 1/(1 - phi/phi_J).
 * Under pressure control phi is the root of P(phi) (homogeneous.c). */
#include <math.h>

#include "closure.h"

static double *phi_J_field(ekm_material *m)
{
    return &m->phi_cp;
}

static double *beta_field(ekm_material *m)
{
    return &m->g_beta;
}

static const ekm_closure_param PARAMS[] = {
    {.key = "phi_J",
     .unit = "1",
     .about = "volume fraction where the density factor g diverges",
     .range = EKM_PARAM_PHI_ABOVE_DATA,
     .field = phi_J_field},
    {.key = "beta",
     .unit = "1",
     .about = "exponent of the density factor g = (1 - phi/phi_J)^(-beta)",
     .range = EKM_PARAM_POSITIVE,
     .field = beta_field},
};

/* every EKM key but phi_cp (phi_J takes its place) */
static const char *const EKM_KEYS[] = {"rho_p", "phi_co", "T0",  "eta0", "zeta0", "lambda0",
                                       "eps0",  "nu",     "A_h", "B_h",  "alpha", NULL};

static ekm_status jam_check(const ekm_closure *c, const ekm_material *m, ekm_error *err)
{
    (void)c;
    if (!(m->phi_cp > 0.0 && m->phi_cp < 1.0))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_J: expected a number in (0, 1), got %g", m->phi_cp);
    if (!(m->g_beta > 0.0 && isfinite(m->g_beta)))
        return EKM_FAIL(err, EKM_EINPUT, "[material] beta: expected a positive number, got %g", m->g_beta);
    if (!(m->phi_co > 0.0 && m->phi_co < m->phi_cp))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_co: expected a number in (0, phi_J = %g), got %g",
                        m->phi_cp, m->phi_co);
    return ekm_material_check(m, err);
}

static ekm_status jam_homog(const ekm_closure *c, const ekm_material *m, double phi, double gdot,
                            ekm_homog_state *out, ekm_error *err)
{
    if (!(phi > 0.0 && phi < m->phi_cp))
        return EKM_FAIL(err, EKM_EINPUT, "phi = %g: expected a volume fraction in (0, phi_J = %g)", phi,
                        m->phi_cp);
    return ekm_homog_shear(m, c->variant, phi, gdot, out, err);
}

static ekm_status jam_homog_p(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                              ekm_homog_state *out, ekm_error *err)
{
    return ekm_homog_shear_at_pressure(m, c->variant, P, gdot, out, err);
}

const ekm_closure ekm_closure_ekm_jam = {
    .name = "ekm_jam",
    .about = "the EKM (full) with g = (1 - phi/phi_J)^(-beta) in place of 1/(1 - phi/phi_cp)",
    .is_ekm = 0,
    .ekm_transport = 1,
    .variant = EKM_VARIANT_FULL,
    .has_temperature = 1,
    .ekm_keys = EKM_KEYS,
    .params = PARAMS,
    .nparams = sizeof PARAMS / sizeof PARAMS[0],
    .check = jam_check,
    .homog = jam_homog,
    .homog_p = jam_homog_p,
};
