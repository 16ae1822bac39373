/* mu_i.c: the mu(I) rheology and its dilatancy law (see mu_i.h). */
#include "mu_i.h"

#include <math.h>

ekm_status ekm_mu_i_check(const ekm_mu_i_params *p, ekm_error *err)
{
    struct {
        const char *key;
        double value;
    } positive[] = {{"rho_p", p->rho_p}, {"I_0", p->I_0}, {"d", p->d}};
    for (unsigned i = 0; i < sizeof positive / sizeof positive[0]; i++)
        if (!(positive[i].value > 0.0 && isfinite(positive[i].value)))
            return EKM_FAIL(err, EKM_EINPUT, "[material] %s: expected a positive number, got %g",
                            positive[i].key, positive[i].value);
    if (!(p->mu_s >= 0.0 && isfinite(p->mu_s)))
        return EKM_FAIL(err, EKM_EINPUT, "[material] mu_s: expected a number >= 0, got %g", p->mu_s);
    if (!(p->mu_2 > p->mu_s && isfinite(p->mu_2)))
        return EKM_FAIL(err, EKM_EINPUT, "[material] mu_2: expected a number > mu_s = %g, got %g", p->mu_s,
                        p->mu_2);
    if (!(p->phi_max > 0.0 && p->phi_max < 1.0))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_max: expected a number in (0, 1), got %g",
                        p->phi_max);
    if (!(p->phi_min > 0.0 && p->phi_min < p->phi_max))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_min: expected a number in (0, phi_max = %g), got %g",
                        p->phi_max, p->phi_min);
    return EKM_OK;
}

double ekm_mu_i_friction(const ekm_mu_i_params *p, double I)
{
    /* (mu_2 - mu_s) I / (I_0 + I): the form without 1/I, finite at I = 0 */
    return p->mu_s + (p->mu_2 - p->mu_s) * I / (p->I_0 + I);
}

double ekm_mu_i_inertial_number_of_friction(const ekm_mu_i_params *p, double mu)
{
    if (!(mu > p->mu_s && mu < p->mu_2))
        return NAN;
    return p->I_0 * (mu - p->mu_s) / (p->mu_2 - mu);
}

double ekm_mu_i_phi_of_I(const ekm_mu_i_params *p, double I)
{
    return p->phi_max - (p->phi_max - p->phi_min) * I;
}

double ekm_mu_i_I_of_phi(const ekm_mu_i_params *p, double phi)
{
    if (!(phi > 0.0 && phi < p->phi_max))
        return NAN;
    return (p->phi_max - phi) / (p->phi_max - p->phi_min);
}

double ekm_mu_i_pressure(const ekm_mu_i_params *p, double I, double gdot)
{
    const double s = p->d * gdot / I;
    return p->rho_p * s * s;
}

double ekm_mu_i_inertial_number(const ekm_mu_i_params *p, double P, double gdot)
{
    return fabs(gdot) * p->d / sqrt(P / p->rho_p);
}

double ekm_mu_i_shear_stress(const ekm_mu_i_params *p, double P, double gdot, double gdot_min, double *dtau)
{
    const double I = ekm_mu_i_inertial_number(p, P, gdot);
    const double mu = ekm_mu_i_friction(p, I);
    /* dmu/dI = (mu_2 - mu_s) I_0 / (I_0 + I)^2; dI/d|gdot| = I / |gdot| = d / sqrt(P / rho_p) */
    const double dmu_dI = (p->mu_2 - p->mu_s) * p->I_0 / ((p->I_0 + I) * (p->I_0 + I));
    const double dI_dg = p->d / sqrt(P / p->rho_p);
    const double s = sqrt(gdot * gdot + gdot_min * gdot_min);
    const double ramp = gdot / s; /* in (-1, 1) */
    /* d(ramp)/dgdot = gdot_min^2 / s^3; d(mu)/dgdot = dmu_dI dI_dg sign(gdot) */
    *dtau = P * (dmu_dI * dI_dg * fabs(ramp) + mu * gdot_min * gdot_min / (s * s * s));
    return mu * P * ramp;
}
