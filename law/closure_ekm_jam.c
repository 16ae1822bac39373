/* closure_ekm_jam.c: the EKM with a density factor that diverges at a
 * jamming fraction with a fitted exponent, the closure style ekm_jam
 * (closure.h; docs/model/closures.md "ekm_jam"):
 *
 *   g(phi) = (1 - phi/phi_J)^(-beta)
 *
 * in place of the EKM's 1/(1 - phi/phi_cp) in every transport
 * coefficient and in both pressures (model.h), the full variant
 * otherwise. In the steady homogeneous shear g cancels from the
 * temperature balance (heating and dissipation both carry it), so the
 * state is the EKM's with phi_cp = phi_J and P, P_K, P_Y, |sigma_xz|
 * multiplied by g1^(beta - 1), g1 = 1/(1 - phi/phi_J); T and mu are the
 * EKM's. Under pressure control phi is the root of P(phi) (it rises with
 * phi on (0, phi_J)), found with GSL's Brent solver. */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>

#include "closure.h"

enum { PHI_J, BETA, NPARAMS };

static const ekm_closure_param PARAMS[NPARAMS] = {
    [PHI_J] = {"phi_J", "1", "volume fraction where the density factor g diverges", EKM_PARAM_PHI_ABOVE_DATA},
    [BETA] = {"beta", "1", "exponent of the density factor g = (1 - phi/phi_J)^(-beta)", EKM_PARAM_POSITIVE},
};

/* what its steady homogeneous shear reads */
static const char *const EKM_KEYS[] = {"rho_p", "phi_co", "T0", "eta0", "eps0", "nu", NULL};

/* The EKM material with phi_cp = phi_J, and beta. */
static ekm_material with_phi_J(const ekm_closure *c, const ekm_material *m, double *beta)
{
    ekm_material e = *m;
    e.phi_cp = m->law_p[ekm_closure_slot(c, PHI_J)];
    *beta = m->law_p[ekm_closure_slot(c, BETA)];
    return e;
}

static ekm_status jam_check(const ekm_closure *c, const ekm_material *m, ekm_error *err)
{
    double beta;
    const ekm_material e = with_phi_J(c, m, &beta);
    if (!(e.phi_cp > 0.0 && e.phi_cp < 1.0))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_J: expected a number in (0, 1), got %g", e.phi_cp);
    if (!(beta > 0.0 && isfinite(beta)))
        return EKM_FAIL(err, EKM_EINPUT, "[material] beta: expected a positive number, got %g", beta);
    if (!(e.phi_co > 0.0 && e.phi_co < e.phi_cp))
        return EKM_FAIL(err, EKM_EINPUT, "[material] phi_co: expected a number in (0, phi_J = %g), got %g",
                        e.phi_cp, e.phi_co);
    struct {
        const char *key;
        double value;
    } positive[] = {{"rho_p", e.rho_p}, {"T0", e.T0}, {"eta0", e.eta0}, {"eps0", e.eps0}, {"nu", e.nu}};
    for (unsigned i = 0; i < sizeof positive / sizeof positive[0]; i++)
        if (!(positive[i].value > 0.0 && isfinite(positive[i].value)))
            return EKM_FAIL(err, EKM_EINPUT, "[material] %s: expected a positive number, got %g",
                            positive[i].key, positive[i].value);
    return EKM_OK;
}

static ekm_status jam_homog(const ekm_closure *c, const ekm_material *m, double phi, double gdot,
                            ekm_homog_state *out, ekm_error *err)
{
    double beta;
    const ekm_material e = with_phi_J(c, m, &beta);
    if (!(phi > 0.0 && phi < e.phi_cp))
        return EKM_FAIL(err, EKM_EINPUT, "phi = %g: expected a volume fraction in (0, phi_J = %g)", phi,
                        e.phi_cp);
    const ekm_status st = ekm_homog_shear(&e, EKM_VARIANT_FULL, phi, gdot, out, err);
    if (st != EKM_OK)
        return st;
    const double scale = pow(1.0 - phi / e.phi_cp, 1.0 - beta); /* g1^(beta - 1) */
    out->P *= scale;
    out->P_K *= scale;
    out->P_Y *= scale;
    out->sxz *= scale;
    return EKM_OK;
}

typedef struct {
    const ekm_closure *c;
    const ekm_material *m;
    double P, gdot;
} p_root;

static double p_mismatch(double phi, void *params)
{
    const p_root *q = params;
    ekm_homog_state h;
    ekm_error e;
    if (jam_homog(q->c, q->m, phi, q->gdot, &h, &e) != EKM_OK)
        return GSL_NAN;
    return log(h.P / q->P);
}

static ekm_status jam_homog_p(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                              ekm_homog_state *out, ekm_error *err)
{
    if (!(P > 0.0 && isfinite(P)))
        return EKM_FAIL(err, EKM_EINPUT, "P = %g: expected a finite pressure > 0 [Pa]", P);
    if (!(gdot > 0.0 && isfinite(gdot)))
        return EKM_FAIL(err, EKM_EINPUT, "gdot = %g: expected a finite shear rate > 0 [1/s]", gdot);
    double beta;
    const ekm_material e = with_phi_J(c, m, &beta);
    /* P rises from rho_p 2 eta0 gdot^2/(3 eps0) at phi -> 0 to infinity at phi_J */
    const double P0 = e.rho_p * 2.0 * e.eta0 * gdot * gdot / (3.0 * e.eps0);
    if (!(P > P0))
        return EKM_FAIL(
            err, EKM_EINPUT,
            "P = %g, gdot = %g: expected P above the dilute limit rho_p 2 eta0 gdot^2 / (3 eps0) = %g "
            "Pa (no volume fraction gives a lower pressure at this rate)",
            P, gdot, P0);
    p_root q = {c, m, P, gdot};
    gsl_function f = {p_mismatch, &q};
    double lo = 1e-12 * e.phi_cp, hi = e.phi_cp * (1.0 - 1e-15);
    if (!(p_mismatch(lo, &q) < 0.0 && p_mismatch(hi, &q) > 0.0))
        return EKM_FAIL(err, EKM_ENUMERIC, "P = %g, gdot = %g: no volume fraction in (0, phi_J) brackets it",
                        P, gdot);
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!s)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (root solver)");
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    int status = gsl_root_fsolver_set(s, &f, lo, hi);
    double phi = NAN;
    for (int it = 0; status == GSL_SUCCESS && it < 200; it++) {
        status = gsl_root_fsolver_iterate(s);
        phi = gsl_root_fsolver_root(s);
        lo = gsl_root_fsolver_x_lower(s);
        hi = gsl_root_fsolver_x_upper(s);
        if (status == GSL_SUCCESS && gsl_root_test_interval(lo, hi, 0.0, 1e-15) == GSL_SUCCESS)
            break;
    }
    gsl_set_error_handler(old);
    gsl_root_fsolver_free(s);
    if (status != GSL_SUCCESS || !isfinite(phi))
        return EKM_FAIL(err, EKM_ENUMERIC, "P = %g, gdot = %g: the root of P(phi) was not found (%s)", P,
                        gdot, gsl_strerror(status));
    return jam_homog(c, m, phi, gdot, out, err);
}

const ekm_closure ekm_closure_ekm_jam = {
    .name = "ekm_jam",
    .about = "the EKM (full) with g = (1 - phi/phi_J)^(-beta) in place of 1/(1 - phi/phi_cp)",
    .is_ekm = 0,
    .has_temperature = 1,
    .ekm_keys = EKM_KEYS,
    .params = PARAMS,
    .nparams = NPARAMS,
    .check = jam_check,
    .homog = jam_homog,
    .homog_p = jam_homog_p,
};
