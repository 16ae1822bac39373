/* model.c: the EKM constitutive law (see model.h for the equations). */
#include "model.h"

#include <math.h>
#include <string.h>

#include "root.h"

ekm_material ekm_material_thesis(void)
{
    ekm_material m = {
        .rho_p = 1600.0,
        .phi_co = 0.60,
        .phi_cp = 0.64,
        .T0 = 1.5,
        .eta0 = 3.55e-4,
        .zeta0 = 1e-4,
        .lambda0 = 3.4e-4,
        .eps0 = 500.0,
        .nu = 1.0,
        .A_h = 200e6,
        .B_h = 200e6,
        .alpha = 0.0,
        .g_beta = 1.0,
    };
    for (int i = 0; i < EKM_LAW_PARAMS_MAX; i++)
        m.law_p[i] = NAN; /* no other closure's parameters given */
    return m;
}

const double *ekm_material_key(const ekm_material *m, const char *key)
{
    const struct {
        const char *key;
        const double *field;
    } keys[] = {
        {"rho_p", &m->rho_p}, {"phi_co", &m->phi_co}, {"phi_cp", &m->phi_cp},   {"T0", &m->T0},
        {"eta0", &m->eta0},   {"zeta0", &m->zeta0},   {"lambda0", &m->lambda0}, {"eps0", &m->eps0},
        {"nu", &m->nu},       {"A_h", &m->A_h},       {"B_h", &m->B_h},         {"alpha", &m->alpha},
    };
    for (unsigned i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (strcmp(keys[i].key, key) == 0)
            return keys[i].field;
    return NULL;
}

ekm_status ekm_material_check(const ekm_material *m, ekm_error *err)
{
    struct {
        const char *key;
        double value;
    } positive[] = {
        {"rho_p", m->rho_p}, {"phi_cp", m->phi_cp}, {"T0", m->T0},   {"eta0", m->eta0}, {"zeta0", m->zeta0},
        {"eps0", m->eps0},   {"nu", m->nu},         {"A_h", m->A_h}, {"B_h", m->B_h},
    };
    for (unsigned i = 0; i < sizeof positive / sizeof positive[0]; i++)
        if (!(positive[i].value > 0.0))
            return EKM_FAIL(err, EKM_EINPUT, "[material] %s: expected a positive number, got %g",
                            positive[i].key, positive[i].value);
    if (!(m->lambda0 >= 0.0))
        return EKM_FAIL(err, EKM_EINPUT, "[material] lambda0: expected a number >= 0, got %g", m->lambda0);
    if (!(m->alpha >= 0.0))
        return EKM_FAIL(err, EKM_EINPUT, "[material] alpha: expected a number >= 0, got %g", m->alpha);
    if (!(m->g_beta > 0.0 && isfinite(m->g_beta)))
        return EKM_FAIL(err, EKM_EINPUT,
                        "the density factor's exponent g_beta (closure ekm_jam: [material] beta): expected "
                        "a positive number, got %g",
                        m->g_beta);
    if (!(m->phi_cp < 1.0))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_cp: expected a number in (0, 1), got %g", m->phi_cp);
    if (!(m->phi_co > 0.0 && m->phi_co < m->phi_cp))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_co: expected a number in (0, phi_cp = %g), got %g",
                        m->phi_cp, m->phi_co);
    return EKM_OK;
}

/* g(phi) = (1 - phi/phi_cp)^(-g_beta); the EKM's 1/(1 - phi/phi_cp) as
 * written before the exponent existed (the same bits) */
double ekm_g(const ekm_material *m, double phi)
{
    if (m->g_beta == 1.0)
        return 1.0 / (1.0 - phi / m->phi_cp);
    return pow(1.0 - phi / m->phi_cp, -m->g_beta);
}

double ekm_g_dphi(const ekm_material *m, double phi, double g)
{
    if (m->g_beta == 1.0)
        return g * g / m->phi_cp;
    return m->g_beta * g / (m->phi_cp - phi);
}

double ekm_pressure_kinetic(const ekm_material *m, double phi, double T)
{
    return m->rho_p * phi * T * ekm_g(m, phi);
}

double ekm_pressure_yield(const ekm_material *m, double phi)
{
    return phi > m->phi_co ? m->rho_p * m->T0 * (phi - m->phi_co) * ekm_g(m, phi) : 0.0;
}

typedef struct {
    const ekm_material *m;
    double P; /* [Pa] */
} yield_target;

static double yield_mismatch(double phi, void *params)
{
    const yield_target *y = params;
    return ekm_pressure_yield(y->m, phi) - y->P;
}

double ekm_phi_of_yield_pressure(const ekm_material *m, double P)
{
    if (!(P > 0.0))
        return m->phi_co;
    if (m->g_beta == 1.0) { /* P (1 - phi/phi_cp) = rho_p T0 (phi - phi_co) */
        const double K = m->rho_p * m->T0;
        return (P + K * m->phi_co) / (K + P / m->phi_cp);
    }
    /* P_Y rises from 0 at phi_co to infinity at phi_cp */
    const double hi = m->phi_cp * (1.0 - 1e-15);
    if (!(ekm_pressure_yield(m, hi) > P))
        return hi;
    yield_target y = {m, P};
    double phi;
    ekm_error err;
    (void)ekm_root_bracketed(yield_mismatch, &y, m->phi_co, hi, &phi, &err);
    return phi; /* on a (never seen) failure, the solver's last estimate, inside the bracket */
}

double ekm_yield_temperature(const ekm_material *m, double phi)
{
    return phi > m->phi_co ? m->T0 * (phi - m->phi_co) / phi : 0.0;
}

/* Y/sqrt(T), with the convention 0 when there is no yield part. */
static double yield_over_sqrtT(double Y, double a)
{
    return Y > 0.0 ? Y / a : 0.0;
}

ekm_transport ekm_transport_coefficients(const ekm_material *m, ekm_variant v, double phi, double T)
{
    const double g = ekm_g(m, phi);
    const double a = sqrt(T);
    const double Ya = yield_over_sqrtT(ekm_yield_temperature(m, phi), a);
    ekm_transport c;
    c.eta = m->rho_p * m->eta0 * g * (a + m->nu * Ya);
    c.zeta = m->rho_p * m->zeta0 * g * (a + Ya);
    c.lambda = m->rho_p * m->lambda0 * g * (a + Ya);
    c.eps = m->eps0 * g * (a + m->nu * Ya); /* eps0 sqrt(T) g (1 + nu r) */
    c.mu_n = v == EKM_VARIANT_THESIS ? c.zeta : 4.0 / 3.0 * c.eta + c.zeta;
    return c;
}

ekm_slab_stress ekm_stress_slab(const ekm_material *m, ekm_variant v, double phi, double T, double du_dz,
                                double dw_dz)
{
    const ekm_transport c = ekm_transport_coefficients(m, v, phi, T);
    const double p_eq = ekm_pressure_kinetic(m, phi, T) + ekm_pressure_yield(m, phi);
    ekm_slab_stress s;
    s.sigma_xz = c.eta * du_dz;
    s.sigma_zz = -p_eq + c.mu_n * dw_dz;
    s.P = p_eq - c.zeta * dw_dz;
    return s;
}

/* Viscosity lengths multiplying w'^2 in the heating: the regular part
 * (factor sqrt(T)) and the yield part (factor Y/sqrt(T)). */
static void normal_lengths(const ekm_material *m, ekm_variant v, double *cn, double *cn_yield)
{
    if (v == EKM_VARIANT_THESIS) {
        *cn = m->zeta0;
        *cn_yield = m->zeta0;
    } else {
        *cn = 4.0 / 3.0 * m->eta0 + m->zeta0;
        *cn_yield = 4.0 / 3.0 * m->nu * m->eta0 + m->zeta0;
    }
}

double ekm_temperature_source(const ekm_material *m, ekm_variant v, double phi, double T, double u2,
                              double w2, double *dS_dT)
{
    double cn, cny;
    normal_lengths(m, v, &cn, &cny);
    const double g = ekm_g(m, phi);
    const double Y = ekm_yield_temperature(m, phi);
    const double a = sqrt(T);
    const double Ka = m->eta0 * u2 + cn * w2;
    const double Kb = Y * (m->nu * m->eta0 * u2 + cny * w2);
    const double pe = phi * m->eps0;
    const double Kb_a = Kb > 0.0 ? Kb / a : 0.0;
    const double S = m->rho_p * g * (2.0 / 3.0 * (Ka * a + Kb_a) - pe * (a * T + m->nu * Y * a));
    if (dS_dT) {
        if (a > 0.0) {
            const double dS_da = m->rho_p * g * (2.0 / 3.0 * (Ka - Kb_a / a) - pe * (3.0 * T + m->nu * Y));
            *dS_dT = dS_da / (2.0 * a);
        } else {
            *dS_dT = 0.0;
        }
    }
    return S;
}

ekm_source_coeffs ekm_temperature_source_coeffs(const ekm_material *m, ekm_variant v, double phi, double u2,
                                                double w2)
{
    return ekm_temperature_source_coeffs_gY(m, v, phi, ekm_g(m, phi), ekm_yield_temperature(m, phi), u2, w2);
}

ekm_source_coeffs ekm_temperature_source_coeffs_gY(const ekm_material *m, ekm_variant v, double phi, double g,
                                                   double Y, double u2, double w2)
{
    double cn, cny;
    normal_lengths(m, v, &cn, &cny);
    ekm_source_coeffs c;
    c.k_heat_a = m->rho_p * g * 2.0 / 3.0 * (m->eta0 * u2 + cn * w2);
    c.k_heat_y = m->rho_p * g * 2.0 / 3.0 * Y * (m->nu * m->eta0 * u2 + cny * w2);
    c.k_diss = m->rho_p * g * phi * m->eps0;
    c.nuY = m->nu * Y;
    return c;
}

ekm_source_coeffs ekm_temperature_source_coeffs_plane(const ekm_material *m, ekm_variant v, double phi,
                                                      double g, double Y, double shear2, double exx,
                                                      double ezz)
{
    const double div = exx + ezz;
    const double d2 = div * div;
    double s2 = shear2;
    if (v != EKM_VARIANT_THESIS)
        s2 += 2.0 * (exx * exx + ezz * ezz - d2 / 3.0);
    /* eta = rho_p g eta0 (a + nu Y/a), zeta = rho_p g zeta0 (a + Y/a), a = sqrt(T) */
    ekm_source_coeffs c;
    c.k_heat_a = m->rho_p * g * 2.0 / 3.0 * (m->eta0 * s2 + m->zeta0 * d2);
    c.k_heat_y = m->rho_p * g * 2.0 / 3.0 * Y * (m->nu * m->eta0 * s2 + m->zeta0 * d2);
    c.k_diss = m->rho_p * g * phi * m->eps0;
    c.nuY = m->nu * Y;
    return c;
}

double ekm_temperature_local_balance(const ekm_material *m, ekm_variant v, double phi, double u2, double w2)
{
    if (!(phi > 0.0))
        return 0.0;
    double cn, cny;
    normal_lengths(m, v, &cn, &cny);
    const double Y = ekm_yield_temperature(m, phi);
    const double Ka = m->eta0 * u2 + cn * w2;
    const double Kb = Y * (m->nu * m->eta0 * u2 + cny * w2);
    const double A = phi * m->eps0;
    const double B = A * m->nu * Y - 2.0 / 3.0 * Ka;
    const double C = -2.0 / 3.0 * Kb;
    const double disc = sqrt(B * B - 4.0 * A * C);
    /* Cancellation-free root of A T^2 + B T + C = 0 with C <= 0. */
    if (B > 0.0)
        return disc + B > 0.0 ? -2.0 * C / (B + disc) : 0.0;
    return (-B + disc) / (2.0 * A);
}

double ekm_pressure_dphi(const ekm_material *m, double phi, double T)
{
    const double g = ekm_g(m, phi);
    const double dg = ekm_g_dphi(m, phi, g);
    double K = T * (g + phi * dg);
    if (phi > m->phi_co)
        K += m->T0 * (g + (phi - m->phi_co) * dg);
    return m->rho_p * K;
}

double ekm_sound_speed(const ekm_material *m, double phi, double T)
{
    return sqrt(ekm_sound_speed_squared(m, phi, T));
}

double ekm_sound_speed_squared(const ekm_material *m, double phi, double T)
{
    const double g = ekm_g(m, phi);
    const double dg = ekm_g_dphi(m, phi, g);
    double c2 = T * (g + phi * dg) + 2.0 / 3.0 * T * g * g;
    if (phi > m->phi_co)
        c2 += m->T0 * (g + (phi - m->phi_co) * dg);
    return c2;
}
