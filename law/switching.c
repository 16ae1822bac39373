/* switching.c: the flow <-> solid switching rules (switching.h). */
#include "switching.h"

#include <math.h>

#include "hypo.h"

ekm_switch_rates ekm_switch_rates_of(const ekm_hypo_params *h, double exx, double ezz, double gamma)
{
    const double tr = exx + ezz;
    ekm_switch_rates r;
    r.compress = tr < 0.0 && gamma / sqrt(2.0) <= -tr;
    r.at_rest = fabs(exx) <= h->rest_rate && fabs(ezz) <= h->rest_rate && gamma <= h->rest_rate;
    r.rate = sqrt(exx * exx + ezz * ezz + gamma * gamma);
    return r;
}

int ekm_switch_loose(const ekm_material *m, const ekm_hypo_params *h, double phi)
{
    return !(ekm_pressure_yield(m, phi) > 0.0) || phi <= m->phi_co + h->phi_margin;
}

double ekm_switch_yield_temperature(const ekm_material *m, int loose, double phi, int below_solid,
                                    double phi_below)
{
    if (!loose)
        return ekm_yield_temperature(m, phi);
    return below_solid ? ekm_yield_temperature(m, phi_below) : 0.0;
}

ekm_switch_verdict ekm_switch_to_flow(const ekm_hypo_params *h, int wet, int loose, double Y, double szz,
                                      double fY, const ekm_switch_rates *r)
{
    if (!wet)
        return EKM_SWITCH_GO;
    if (loose)
        return !(Y > 0.0) || szz >= 0.0 ? EKM_SWITCH_GO : EKM_SWITCH_STAY;
    return fY >= -h->yield_tol && !r->compress ? EKM_SWITCH_CHECK : EKM_SWITCH_STAY;
}

int ekm_switch_jump_passes(const ekm_hypo_params *h, double jump)
{
    return jump <= h->jump_tol || !h->carry_over;
}

ekm_switch_verdict ekm_switch_to_solid(const ekm_hypo_params *h, int wet, int loose, double Y, double T,
                                       double phi, const ekm_switch_rates *r, double rate_before)
{
    if (!(wet && Y > 0.0 && (r->compress || r->at_rest) && T < h->T_ratio * Y && phi >= h->phi_loose))
        return EKM_SWITCH_STAY;
    return !r->compress && !loose && r->rate > rate_before ? EKM_SWITCH_CHECK : EKM_SWITCH_GO;
}

int ekm_switch_inside_passes(const ekm_hypo_params *h, double fY)
{
    return fY < -10.0 * h->yield_tol;
}

double ekm_switch_flow_temperature(const ekm_material *m, ekm_variant variant, int loose, double phi,
                                   double ezz, double szz, double T_qs, double T_floor)
{
    const double T_stress = loose ? ekm_hypo_flow_T_for_stress(m, variant, phi, ezz, szz) : -1.0;
    return T_stress >= 0.0 ? fmax(T_stress, T_floor) : T_qs;
}
