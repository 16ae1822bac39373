/* model.h: the EKM constitutive law in the flow regimes, as pure functions
 * of the local state (phi, T) and the velocity gradients.
 *
 * Conventions (docs/model-notes.md sections 1-3, docs/model/law.md): SI units; T is the
 * granular temperature per degree of freedom [m^2/s^2]; stress negative in
 * compression, P = -tr(sigma)/3 positive in compression.  With
 *
 *   g(phi) = (1 - phi/phi_cp)^(-g_beta)          g_beta = 1 in the EKM
 *   P_K    = rho_p phi T g                       kinetic pressure   [Pa]
 *   P_Y    = rho_p T0 (phi - phi_co)_+ g         yield pressure     [Pa]
 *   r      = P_Y / P_K = Y / T,  Y = T0 (phi - phi_co)_+ / phi    [m^2/s^2]
 *   eta    = rho_p eta0    sqrt(T) g (1 + nu r)  shear viscosity    [Pa s]
 *   zeta   = rho_p zeta0   sqrt(T) g (1 + r)     bulk viscosity     [Pa s]
 *   lambda = rho_p lambda0 sqrt(T) g (1 + r)     conductivity  [kg/(m s)]
 *   eps    = eps0          sqrt(T) g (1 + nu r)  dissipation rate   [1/s]
 *
 * the slab stresses for u = v_x(z), w = v_z(z) are
 *
 *   sigma_xz = eta u'
 *   sigma_zz = -(P_K + P_Y) + mu_n w'     mu_n = 4/3 eta + zeta (full)
 *                                          mu_n = zeta          (thesis)
 *   P        = P_K + P_Y - zeta w'        (thesis variant: same)
 *
 * and the temperature equation's local source (per unit volume) is
 *
 *   S = (2/3)(eta u'^2 + mu_n w'^2) - rho_p phi eps T          [W/m^3]
 *
 * The thesis variant (Chapter 6) keeps only the bulk viscosity in the
 * normal stress; both keep eta in the shear stress.
 */
#ifndef EKM_MODEL_H
#define EKM_MODEL_H

#include "status.h"

typedef enum { EKM_VARIANT_FULL = 0, EKM_VARIANT_THESIS = 1 } ekm_variant;

/* Slots for the parameters of the closure styles other than the EKM
 * (closure.h: one per registered parameter, in the table's order). */
#define EKM_LAW_PARAMS_MAX 32

/* Material constants, SI, rho_p factored out (docs/model-notes.md section 1). */
typedef struct {
    double rho_p;   /* particle material density [kg/m^3] */
    double phi_co;  /* cross-over volume fraction, onset of yield pressure [-] */
    double phi_cp;  /* random close packing, where g(phi) diverges [-] */
    double T0;      /* temperature scale of the yield pressure [m^2/s^2] */
    double eta0;    /* shear viscosity length [m] */
    double zeta0;   /* bulk viscosity length [m] */
    double lambda0; /* heat conductivity length [m] */
    double eps0;    /* dissipation coefficient [1/m] */
    double nu;      /* rate dependence of friction, thesis eq. 4.2.14 [-] */
    double A_h;     /* hypoplastic stiffness, volumetric part [Pa] */
    double B_h;     /* hypoplastic stiffness, shear part [Pa] */
    double alpha;   /* exponent of the hypoplastic density factor f(phi) [-] */
    double g_beta;  /* exponent of the density factor g(phi) [-]: 1 in the EKM; the
                     * ekm_jam closure's beta (closure_ekm_jam.c), not an EKM key */
    /* the other closures' parameters (closure.h: their keys and units; NAN:
     * not given; an EKM style reads none of them) */
    double law_p[EKM_LAW_PARAMS_MAX];
} ekm_material;

/* Transport coefficients at one state. */
typedef struct {
    double eta;    /* shear viscosity [Pa s] */
    double zeta;   /* bulk viscosity [Pa s] */
    double mu_n;   /* normal (longitudinal) viscosity of sigma_zz [Pa s] */
    double lambda; /* heat conductivity [kg/(m s)] */
    double eps;    /* dissipation rate [1/s] */
} ekm_transport;

/* Stresses of the slab at one state. */
typedef struct {
    double P;        /* pressure -tr(sigma)/3, positive in compression [Pa] */
    double sigma_xz; /* shear stress [Pa] */
    double sigma_zz; /* normal stress, negative in compression [Pa] */
} ekm_slab_stress;

/* Thesis default material (Sections 4.6.2, 6.5) in SI. */
ekm_material ekm_material_thesis(void);

/* The field of the EKM [material] key `key` (rho_p ... alpha: the twelve
 * keys of docs/scenario-format.md); NULL for any other name. */
const double *ekm_material_key(const ekm_material *m, const char *key);

/* Check ranges (0 < phi_co < phi_cp < 1, positive constants); names the
 * offending key in err. */
ekm_status ekm_material_check(const ekm_material *m, ekm_error *err);

/* The density factor g(phi) = (1 - phi/phi_cp)^(-g_beta), 0 <= phi < phi_cp. */
double ekm_g(const ekm_material *m, double phi);
/* dg/dphi at phi, given g = ekm_g(m, phi): g_beta g / (phi_cp - phi). */
double ekm_g_dphi(const ekm_material *m, double phi, double g);
/* The same g, as the per-cell loops of the solvers write it (model.c's
 * ekm_g to round-off): phi_cp / (phi_cp - phi) when g_beta = 1, with no
 * call, so that a loop over cells vectorises. */
static inline double ekm_g_cell(const ekm_material *m, double phi)
{
    return m->g_beta == 1.0 ? m->phi_cp / (m->phi_cp - phi)
                            : __builtin_pow(1.0 - phi / m->phi_cp, -m->g_beta);
}
double ekm_pressure_kinetic(const ekm_material *m, double phi, double T);
double ekm_pressure_yield(const ekm_material *m, double phi);
/* The volume fraction whose yield pressure is P >= 0 [Pa]: phi_co for P = 0,
 * in [phi_co, phi_cp) (P_Y rises from 0 to infinity there); a closed form
 * when g_beta = 1, else GSL's Brent root. */
double ekm_phi_of_yield_pressure(const ekm_material *m, double P);
/* Y = T0 (phi - phi_co)_+ / phi, so that r = P_Y/P_K = Y/T [m^2/s^2]. */
double ekm_yield_temperature(const ekm_material *m, double phi);

ekm_transport ekm_transport_coefficients(const ekm_material *m, ekm_variant v, double phi, double T);

/* Everything the time step needs at one flowing cell (phi, T), each
 * factor computed once: the same values as ekm_g, ekm_yield_temperature,
 * ekm_transport_coefficients and ekm_pressure_kinetic + ekm_pressure_yield
 * (equal to round-off: one division for g, one for Y, one for 1/sqrt(T)).
 * phi > 0 and T > 0 (the step's wet cells: phi >= phi_dry > 0, T >= T_floor
 * > 0); no branch on a division, so that a loop over cells vectorises. */
typedef struct {
    double g;      /* density factor g(phi) [-] */
    double Y;      /* yield temperature [m^2/s^2] */
    double eta;    /* shear viscosity [Pa s] */
    double mu_n;   /* normal viscosity of sigma_zz [Pa s] */
    double zeta;   /* bulk viscosity [Pa s] */
    double lambda; /* heat conductivity [kg/(m s)] */
    double P;      /* equilibrium pressure P_K + P_Y [Pa] */
} ekm_cell_properties;

static inline ekm_cell_properties ekm_cell_properties_at(const ekm_material *m, ekm_variant v, double phi,
                                                         double T)
{
    ekm_cell_properties c;
    const double g = ekm_g_cell(m, phi);
    const double a = __builtin_sqrt(T);
    const double above_co = phi - m->phi_co;
    const double excess = above_co > 0.0 ? above_co : 0.0;
    c.g = g;
    c.Y = m->T0 * excess / phi; /* 0 below phi_co */
    const double Ya = c.Y / a;
    const double rg = m->rho_p * g;
    c.eta = rg * m->eta0 * (a + m->nu * Ya);
    const double zeta = rg * m->zeta0 * (a + Ya);
    c.lambda = rg * m->lambda0 * (a + Ya);
    const double k_eta = v == EKM_VARIANT_THESIS ? 0.0 : 4.0 / 3.0; /* thesis: mu_n = zeta exactly */
    c.mu_n = k_eta * c.eta + zeta;
    c.zeta = zeta;
    c.P = rg * (phi * T + m->T0 * excess);
    return c;
}

/* The rate at which dissipation relaxes T at a flowing cell (phi, T > 0),
 * eps P_K / (P_K + P_Y) [1/s], with eps = eps0 g (sqrt(T) + nu Y/sqrt(T)),
 * P_K = rho_p g phi T, P_Y = rho_p g phi Y, Y = T0 (phi - phi_co)_+ / phi:
 *   eps0 sqrt(T) g (phi T + nu T0 x) / (phi T + T0 x),  x = (phi - phi_co)_+
 * (the time steps' thermal limit). With g_beta = 1, g = phi_cp/(phi_cp -
 * phi) as the solvers always wrote it: one division, no call, so that a
 * loop over cells vectorises. */
static inline double ekm_thermal_relaxation_rate(const ekm_material *m, double phi, double T)
{
    const double above_co = phi - m->phi_co;
    const double x = above_co > 0.0 ? above_co : 0.0;
    const double g_num = m->g_beta == 1.0 ? m->phi_cp : (m->phi_cp - phi) * ekm_g_cell(m, phi);
    return m->eps0 * __builtin_sqrt(T) * g_num * (phi * T + m->nu * m->T0 * x) /
           ((m->phi_cp - phi) * (phi * T + m->T0 * x));
}

/* The normal stresses of plane strain (x, z in the plane, y out of it;
 * v_y = 0) at a flowing cell with the rates exx = dvx/dx, ezz = dvz/dz
 * [1/s], div = exx + ezz:
 *   full:   sigma_ii = -(P_K + P_Y) + 2 eta (e_ii - div/3) + zeta div
 *   thesis: sigma_ii = -(P_K + P_Y) + zeta div   (no deviatoric normal part,
 *           as the 1D variant: mu_n = zeta)
 * (i = x, z, y with e_yy = 0); the shear stress is eta (dvx/dz + dvz/dx)
 * in both.  With exx = 0 this is ekm_stress_slab's sigma_zz. */
typedef struct {
    double sxx, szz, syy; /* [Pa], negative in compression */
    double P;             /* -(sxx + szz + syy)/3 = P_K + P_Y - zeta div [Pa] */
} ekm_plane_stress;

static inline ekm_plane_stress ekm_stress_plane(const ekm_cell_properties *c, ekm_variant v, double exx,
                                                double ezz)
{
    const double div = exx + ezz;
    const double two_eta = v == EKM_VARIANT_THESIS ? 0.0 : 2.0 * c->eta;
    const double iso = -c->P + (c->zeta - two_eta / 3.0) * div;
    ekm_plane_stress s;
    s.sxx = iso + two_eta * exx;
    s.szz = iso + two_eta * ezz;
    s.syy = iso;
    s.P = c->P - c->zeta * div;
    return s;
}

/* du_dz = u', dw_dz = w' [1/s]. */
ekm_slab_stress ekm_stress_slab(const ekm_material *m, ekm_variant v, double phi, double T, double du_dz,
                                double dw_dz);

/* Local temperature source S(T) [W/m^3] for squared gradients u2 = u'^2,
 * w2 = w'^2 [1/s^2], and its derivative dS/dT (may be NULL). */
double ekm_temperature_source(const ekm_material *m, ekm_variant v, double phi, double T, double u2,
                              double w2, double *dS_dT);

/* The source written as S(T) = k_heat_a sqrt(T) + k_heat_y / sqrt(T)
 * - k_diss (T^(3/2) + nu Y sqrt(T)): the coefficients depend on phi and
 * the gradients only, so an implicit solve computes them once per step. */
typedef struct {
    double k_heat_a; /* rho_p g 2/3 Ka [kg/(m^2 s^2)] */
    double k_heat_y; /* rho_p g 2/3 Kb [kg/s^4] */
    double k_diss;   /* rho_p g phi eps0 [kg/m^4] */
    double nuY;      /* nu Y [m^2/s^2] */
} ekm_source_coeffs;

ekm_source_coeffs ekm_temperature_source_coeffs(const ekm_material *m, ekm_variant v, double phi, double u2,
                                                double w2);

/* The same from the density factor g and yield temperature Y of phi
 * (ekm_cell_properties_at), which it does not recompute. */
ekm_source_coeffs ekm_temperature_source_coeffs_gY(const ekm_material *m, ekm_variant v, double phi, double g,
                                                   double Y, double u2, double w2);

/* Temperature source coefficients (ekm_source_coeffs) of plane strain at a
 * cell with density factor g and yield temperature Y of phi: the viscous
 * heating sigma_visc : kappa = eta s2 + zeta div^2 with
 *   full:   s2 = shear2 + 2 (exx^2 + ezz^2 - div^2/3)
 *   thesis: s2 = shear2
 * (shear2 = (dvx/dz + dvz/dx)^2 [1/s^2]; exx, ezz [1/s]).  With exx = 0,
 * shear2 = u'^2 and ezz = w' it equals ekm_temperature_source_coeffs_gY
 * (u2, w2) to round-off (test_model). */
ekm_source_coeffs ekm_temperature_source_coeffs_plane(const ekm_material *m, ekm_variant v, double phi,
                                                      double g, double Y, double shear2, double exx,
                                                      double ezz);

/* S(T) and dS/dT from precomputed coefficients (T > 0). */
static inline double ekm_source_eval(const ekm_source_coeffs *c, double T, double *dS_dT)
{
    const double a = __builtin_sqrt(T);
    const double inv_a = 1.0 / a;
    const double heat_y = c->k_heat_y * inv_a;
    *dS_dT = 0.5 * inv_a * (c->k_heat_a - heat_y * inv_a - c->k_diss * (3.0 * T + c->nuY));
    return c->k_heat_a * a + heat_y - c->k_diss * a * (T + c->nuY);
}

/* The root of S from precomputed coefficients (the local balance, see
 * ekm_temperature_local_balance): S sqrt(T) = 0 is the quadratic
 * k_diss T^2 + (k_diss nu Y - k_heat_a) T - k_heat_y = 0. */
static inline double ekm_source_balance(const ekm_source_coeffs *c)
{
    const double A = c->k_diss, B = c->k_diss * c->nuY - c->k_heat_a, C = -c->k_heat_y;
    if (!(A > 0.0))
        return 0.0;
    const double disc = __builtin_sqrt(B * B - 4.0 * A * C);
    if (B > 0.0)
        return disc + B > 0.0 ? -2.0 * C / (B + disc) : 0.0;
    return (-B + disc) / (2.0 * A);
}

/* The temperature at which S(T) = 0 (local balance of viscous heating and
 * dissipation): the positive root of
 *   phi eps0 T^2 + (phi eps0 nu Y - 2/3 Ka) T - 2/3 Kb = 0,
 *   Ka = eta0 u2 + c_n w2,  Kb = Y (nu eta0 u2 + c_n' w2)
 * (c_n, c_n' the normal-viscosity lengths of the variant).  For steady
 * simple shear this is T = 2 eta0 gdot^2/(3 phi eps0) (docs/model-notes.md section 7). */
double ekm_temperature_local_balance(const ekm_material *m, ekm_variant v, double phi, double u2, double w2);

/* d(P_K + P_Y)/dphi at constant T [Pa]: how the equilibrium pressure
 * follows a change of phi in one step (T is carried with the mass, rho T
 * conserved, and this model has no P div v work in the T equation): the
 * stiffness of the implicit pressure coupling (implicit.h). */
double ekm_pressure_dphi(const ekm_material *m, double phi, double T);

/* Sound speed bound sqrt(dP/drho + 2/3 T g^2) [m/s] for the CFL limit,
 * and its square [m^2/s^2]. */
double ekm_sound_speed(const ekm_material *m, double phi, double T);
double ekm_sound_speed_squared(const ekm_material *m, double phi, double T);

#endif
