#include "state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

ekm_state *ekm_state_alloc(int n, double length)
{
    ekm_state *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->n = n;
    s->dz = length / n;
    s->z = calloc((size_t)n, sizeof *s->z);
    s->phi = calloc((size_t)n, sizeof *s->phi);
    s->T = calloc((size_t)n, sizeof *s->T);
    s->u = calloc((size_t)n, sizeof *s->u);
    s->w = calloc((size_t)n + 1, sizeof *s->w);
    s->solid = calloc((size_t)n, 1);
    s->sxx = calloc((size_t)n, sizeof *s->sxx);
    s->syy = calloc((size_t)n, sizeof *s->syy);
    s->szz = calloc((size_t)n, sizeof *s->szz);
    s->sxz = calloc((size_t)n + 1, sizeof *s->sxz);
    s->rate_prev = calloc((size_t)n, sizeof *s->rate_prev);
    if (!s->z || !s->phi || !s->T || !s->u || !s->w || !s->solid || !s->sxx || !s->syy || !s->szz ||
        !s->sxz || !s->rate_prev) {
        ekm_state_free(s);
        return NULL;
    }
    for (int j = 0; j < n; j++)
        s->z[j] = (j + 0.5) * s->dz;
    return s;
}

void ekm_state_free(ekm_state *s)
{
    if (!s)
        return;
    free(s->z);
    free(s->phi);
    free(s->T);
    free(s->u);
    free(s->w);
    free(s->solid);
    free(s->sxx);
    free(s->syy);
    free(s->szz);
    free(s->sxz);
    free(s->rate_prev);
    free(s);
}

void ekm_state_copy(ekm_state *dst, const ekm_state *src)
{
    const size_t n = (size_t)src->n;
    dst->dz = src->dz; /* a pressure-controlled wall stretches the grid */
    memcpy(dst->z, src->z, n * sizeof *dst->z);
    memcpy(dst->phi, src->phi, n * sizeof *dst->phi);
    memcpy(dst->T, src->T, n * sizeof *dst->T);
    memcpy(dst->u, src->u, n * sizeof *dst->u);
    memcpy(dst->w, src->w, (n + 1) * sizeof *dst->w);
    memcpy(dst->solid, src->solid, n);
    memcpy(dst->sxx, src->sxx, n * sizeof *dst->sxx);
    memcpy(dst->syy, src->syy, n * sizeof *dst->syy);
    memcpy(dst->szz, src->szz, n * sizeof *dst->szz);
    memcpy(dst->sxz, src->sxz, (n + 1) * sizeof *dst->sxz);
    memcpy(dst->rate_prev, src->rate_prev, n * sizeof *dst->rate_prev);
    dst->t = src->t;
    dst->steps = src->steps;
    dst->mass_in = src->mass_in;
}

void ekm_state_copy_step(ekm_state *dst, const ekm_state *src, int grid, int solid)
{
    const size_t n = (size_t)src->n;
    if (grid) {
        dst->dz = src->dz;
        memcpy(dst->z, src->z, n * sizeof *dst->z);
    }
    memcpy(dst->phi, src->phi, n * sizeof *dst->phi);
    memcpy(dst->T, src->T, n * sizeof *dst->T);
    memcpy(dst->u, src->u, n * sizeof *dst->u);
    memcpy(dst->w, src->w, (n + 1) * sizeof *dst->w);
    if (solid) {
        memcpy(dst->sxx, src->sxx, n * sizeof *dst->sxx);
        memcpy(dst->syy, src->syy, n * sizeof *dst->syy);
        memcpy(dst->szz, src->szz, n * sizeof *dst->szz);
        memcpy(dst->sxz, src->sxz, (n + 1) * sizeof *dst->sxz);
    }
    dst->t = src->t;
    dst->steps = src->steps;
    dst->mass_in = src->mass_in;
}

/* [initial] settled: a solid layer at rest under the initial gravity, every
 * cell at its yield pressure (tr(sigma) = -3 P_Y, isotropic normal stress)
 * with the discrete momentum balance of the solver exactly satisfied:
 * sigma_zz(j) = sigma_zz(j+1) - rho_face G_n dz down from the top cell
 * (sigma_zz = -rho G_n dz/2 there), phi from P_Y(phi) = -sigma_zz (a fixed
 * point, rho depends on phi), face shear stresses summing the weight along
 * the slope from the free top (sxz = 0 there). */
static void settle(ekm_state *s, const ekm_scenario *sc)
{
    const ekm_material *m = &sc->material;
    const double gn = -ekm_scenario_gravity_z(sc), gt = ekm_scenario_gravity_x(sc);
    int top = s->n;
    while (top > 0 && !s->solid[top - 1])
        top--;
    if (top == 0)
        return;
    double sig_above = 0.0, phi_above = 0.0;
    for (int j = top - 1; j >= 0; j--) {
        double phi = s->phi[j];
        for (int it = 0; it < 100; it++) {
            const double load = j == top - 1 ? m->rho_p * phi * gn * s->dz / 2
                                             : -sig_above + m->rho_p * 0.5 * (phi + phi_above) * gn * s->dz;
            const double next = ekm_phi_of_yield_pressure(m, load);
            if (fabs(next - phi) < 1e-15)
                break;
            phi = next;
        }
        const double load = j == top - 1 ? m->rho_p * phi * gn * s->dz / 2
                                         : -sig_above + m->rho_p * 0.5 * (phi + phi_above) * gn * s->dz;
        s->phi[j] = phi;
        s->sxx[j] = s->syy[j] = s->szz[j] = -load;
        sig_above = -load;
        phi_above = phi;
    }
    s->sxz[top] = 0.0;
    for (int f = top - 1; f >= 0; f--)
        s->sxz[f] = s->sxz[f + 1] + m->rho_p * s->phi[f] * gt * s->dz;
}

void ekm_state_init(ekm_state *s, const ekm_scenario *sc)
{
    for (int j = 0; j < s->n; j++) {
        /* A cell cut by the layer surface gets the covered fraction. */
        double lo = j * s->dz, hi = (j + 1) * s->dz;
        double cover = sc->layer_height >= hi   ? 1.0
                       : sc->layer_height <= lo ? 0.0
                                                : (sc->layer_height - lo) / s->dz;
        s->phi[j] = sc->phi_init * cover;
        s->T[j] = s->phi[j] > sc->numerics.phi_dry ? sc->T_init : 0.0;
        s->u[j] = s->phi[j] > sc->numerics.phi_dry ? sc->u_init + sc->shear_rate_init * s->z[j] : 0.0;
        const double PY = ekm_pressure_yield(&sc->material, s->phi[j]);
        s->solid[j] = sc->hypo.enabled && sc->hypo.initial_solid && PY > 0.0;
        const double PY_law = ekm_pressure_yield(&sc->material, ekm_scenario_law_phi(sc, s->phi[j]));
        s->sxx[j] = s->syy[j] = s->szz[j] = s->solid[j] ? -sc->hypo.initial_stress_ratio * PY_law : 0.0;
        s->rate_prev[j] = 0.0;
    }
    for (int f = 0; f <= s->n; f++) {
        s->w[f] = 0.0;
        s->sxz[f] = 0.0;
    }
    s->t = 0.0;
    s->steps = 0;
    s->mass_in = 0.0;
    if (sc->hypo.initial_solid && sc->hypo.initial_settled)
        settle(s, sc);
}

double ekm_state_mass(const ekm_state *s, double rho_p)
{
    double m = 0.0;
    for (int j = 0; j < s->n; j++)
        m += s->phi[j];
    return rho_p * m * s->dz;
}
