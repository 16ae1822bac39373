#include "fields.h"

#include "bc.h"
#include "model.h"

static double harmonic(double a, double b)
{
    return a > 0.0 && b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
}

double ekm_face_viscosity(double eta_a, int solid_a, double eta_b, int solid_b)
{
    if (!(eta_a > 0.0) || !(eta_b > 0.0))
        return 0.0;
    if (solid_a && !solid_b)
        return eta_b;
    if (solid_b && !solid_a)
        return eta_a;
    return harmonic(eta_a, eta_b);
}

void ekm_fields_compute(const ekm_scenario *sc, const ekm_state *s, double t, ekm_fields *out)
{
    const ekm_material *m = &sc->material;
    const int n = s->n;
    const double dry = sc->numerics.phi_dry;
    const ekm_bc_face bb = ekm_bc_evaluate(&sc->bottom, EKM_SIDE_BOTTOM, t, s);
    const ekm_bc_face bt = ekm_bc_evaluate(&sc->top, EKM_SIDE_TOP, t, s);
    double eta_prev = 0.0; /* eta of cell j-1 */
    for (int j = 0; j < n; j++) {
        const double phi = s->phi[j];
        out->vx[j] = s->u[j];
        out->vz[j] = 0.5 * (s->w[j] + s->w[j + 1]);
        if (phi < dry) {
            out->P[j] = out->sxz[j] = out->szz[j] = 0.0;
            out->regime[j] = EKM_REGIME_EMPTY;
            eta_prev = 0.0;
            continue;
        }
        const ekm_transport c = ekm_transport_coefficients(m, sc->variant, phi, s->T[j]);
        double eta_next = 0.0;
        if (j < n - 1 && s->phi[j + 1] >= dry)
            eta_next = ekm_transport_coefficients(m, sc->variant, s->phi[j + 1], s->T[j + 1]).eta;
        double tau_below, tau_above;
        if (j == 0)
            tau_below = bb.wall_conductance > 0.0 ? c.eta * (s->u[0] - bb.u_wall) * bb.wall_conductance : 0.0;
        else
            tau_below = ekm_face_viscosity(eta_prev, s->solid[j - 1], c.eta, s->solid[j]) *
                        (s->u[j] - s->u[j - 1]) / s->dz;
        if (j == n - 1)
            tau_above = bt.wall_conductance > 0.0 ? c.eta * (bt.u_wall - s->u[j]) * bt.wall_conductance : 0.0;
        else
            tau_above = ekm_face_viscosity(c.eta, s->solid[j], eta_next, s->solid[j + 1]) *
                        (s->u[j + 1] - s->u[j]) / s->dz;
        const double dw = (s->w[j + 1] - s->w[j]) / s->dz;
        const double p_eq = ekm_pressure_kinetic(m, phi, s->T[j]) + ekm_pressure_yield(m, phi);
        out->sxz[j] = 0.5 * (tau_below + tau_above);
        out->szz[j] = -p_eq + c.mu_n * dw;
        out->P[j] = p_eq - c.zeta * dw;
        out->regime[j] = phi <= m->phi_co ? EKM_REGIME_KINETIC : EKM_REGIME_DENSE;
        if (s->solid[j]) { /* the rate law's stress (hypo.h); shear stress on faces */
            out->sxz[j] = 0.5 * (s->sxz[j] + s->sxz[j + 1]);
            out->szz[j] = s->szz[j];
            out->P[j] = -(s->sxx[j] + s->syy[j] + s->szz[j]) / 3.0;
            out->regime[j] = EKM_REGIME_SOLID;
        }
        eta_prev = c.eta;
    }
}
