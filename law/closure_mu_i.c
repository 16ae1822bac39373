/* closure_mu_i.c: the mu(I) rheology with the linear dilatancy law as the
 * closure style mu_i (mu_i.h: the law; closure.h; docs/model/closures.md). */
#include <math.h>

#include "closure.h"
#include "mu_i.h"

enum { MU_S, MU_2, I_0, PHI_MAX, PHI_MIN, D, NPARAMS };

static const ekm_closure_param PARAMS[NPARAMS] = {
    [MU_S] = {"mu_s", "1", "friction coefficient at I -> 0", EKM_PARAM_POSITIVE},
    [MU_2] = {"mu_2", "1", "friction coefficient at I -> infinity", EKM_PARAM_ABOVE_PREVIOUS},
    [I_0] = {"I_0", "1", "inertial number of the friction's transition", EKM_PARAM_POSITIVE},
    [PHI_MAX] = {"phi_max", "1", "volume fraction of the dilatancy law at I -> 0", EKM_PARAM_PHI_ABOVE_DATA},
    [PHI_MIN] = {"phi_min", "1", "volume fraction of the dilatancy law at I = 1", EKM_PARAM_BELOW_PREVIOUS},
    [D] = {.key = "d",
           .unit = "m",
           .about = "grain diameter",
           .range = EKM_PARAM_POSITIVE,
           .grain_property = 1},
};

static const char *const EKM_KEYS[] = {"rho_p", NULL};

static ekm_mu_i_params params_of(const ekm_closure *c, const ekm_material *m)
{
    const double *p = m->law_p + ekm_closure_slot(c, 0);
    return (ekm_mu_i_params){.rho_p = m->rho_p,
                             .mu_s = p[MU_S],
                             .mu_2 = p[MU_2],
                             .I_0 = p[I_0],
                             .phi_max = p[PHI_MAX],
                             .phi_min = p[PHI_MIN],
                             .d = p[D]};
}

static ekm_status mu_i_check(const ekm_closure *c, const ekm_material *m, ekm_error *err)
{
    const ekm_mu_i_params p = params_of(c, m);
    return ekm_mu_i_check(&p, err);
}

/* Volume control: I from the dilatancy law, P = rho_p (d gdot / I)^2,
 * |sigma_xz| = mu(I) P. */
static ekm_status mu_i_homog(const ekm_closure *c, const ekm_material *m, double phi, double gdot,
                             ekm_homog_state *out, ekm_error *err)
{
    const ekm_mu_i_params p = params_of(c, m);
    const ekm_status cst = ekm_homog_check_rate(gdot, err);
    if (cst != EKM_OK)
        return cst;
    const double I = ekm_mu_i_I_of_phi(&p, phi);
    if (!(I > 0.0))
        return EKM_FAIL(err, EKM_EINPUT,
                        "phi = %g: expected a volume fraction in (0, phi_max = %g) (mu_i has no steady shear "
                        "at a finite pressure above phi_max)",
                        phi, p.phi_max);
    const double mu = ekm_mu_i_friction(&p, I);
    out->T = NAN;
    out->P_K = NAN;
    out->P_Y = NAN;
    out->r = NAN;
    out->P = ekm_mu_i_pressure(&p, I, gdot);
    out->mu = mu;
    out->sxz = mu * out->P;
    out->phi = phi;
    if (!(isfinite(out->P) && out->P > 0.0))
        return EKM_FAIL(err, EKM_ENUMERIC, "phi = %g, gdot = %g: P = %g is not a finite positive pressure",
                        phi, gdot, out->P);
    return EKM_OK;
}

/* Pressure control: I = gdot d / sqrt(P / rho_p), phi = phi(I) (> 0),
 * |sigma_xz| = mu(I) P. */
static ekm_status mu_i_homog_p(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                               ekm_homog_state *out, ekm_error *err)
{
    const ekm_mu_i_params p = params_of(c, m);
    const ekm_status cst = ekm_homog_check_pressure(P, gdot, err);
    if (cst != EKM_OK)
        return cst;
    const double I = gdot * p.d / sqrt(P / p.rho_p);
    const double phi = ekm_mu_i_phi_of_I(&p, I);
    if (!(phi > 0.0))
        return EKM_FAIL(
            err, EKM_EINPUT,
            "P = %g, gdot = %g: I = %g gives phi(I) = %g: the dilatancy law has no volume fraction "
            "there",
            P, gdot, I, phi);
    const double mu = ekm_mu_i_friction(&p, I);
    out->T = NAN;
    out->P_K = NAN;
    out->P_Y = NAN;
    out->r = NAN;
    out->P = P;
    out->mu = mu;
    out->sxz = mu * P;
    out->phi = phi;
    return EKM_OK;
}

/* The slab solver's stress: mu_i.h ekm_mu_i_shear_stress. */
static double mu_i_local_stress(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                                double gdot_min, double *dtau)
{
    const ekm_mu_i_params p = params_of(c, m);
    return ekm_mu_i_shear_stress(&p, P, gdot, gdot_min, dtau);
}

/* phi(I) at I = |gdot| d / sqrt(P / rho_p); beyond I = 1 (phi < phi_min,
 * the linear law's extrapolation, no longer the dense regime) it is held
 * at phi_min. */
static double mu_i_local_phi(const ekm_closure *c, const ekm_material *m, double P, double gdot, int *beyond)
{
    const ekm_mu_i_params p = params_of(c, m);
    const double I = ekm_mu_i_inertial_number(&p, P, gdot);
    *beyond = !(I <= 1.0);
    return *beyond ? p.phi_min : ekm_mu_i_phi_of_I(&p, I);
}

const ekm_closure ekm_closure_mu_i = {
    .name = "mu_i",
    .about = "mu(I) of Jop, Forterre and Pouliquen (2006) with phi(I) = phi_max - (phi_max - phi_min) I",
    .is_ekm = 0,
    .has_temperature = 0,
    .ekm_keys = EKM_KEYS,
    .params = PARAMS,
    .nparams = NPARAMS,
    .check = mu_i_check,
    .homog = mu_i_homog,
    .homog_p = mu_i_homog_p,
    .local_stress = mu_i_local_stress,
    .local_phi = mu_i_local_phi,
};
