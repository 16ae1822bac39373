#include "step.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bc.h"
#include "fields.h"

ekm_stepper *ekm_step_alloc(const ekm_scenario *sc, ekm_error *err)
{
    ekm_stepper *st = calloc(1, sizeof *st);
    if (!st) {
        EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the stepper");
        return NULL;
    }
    const int n = sc->cells;
    const size_t c = (size_t)n, f = (size_t)n + 1;
    st->sc = sc;
    st->n = n;
    st->g_x = ekm_scenario_gravity_x(sc);
    st->g_z = ekm_scenario_gravity_z(sc);
    st->F = calloc(f, sizeof(double));
    st->qF = calloc(f, sizeof(double));
    st->phi_new = calloc(c, sizeof(double));
    st->rhoU = calloc(c, sizeof(double));
    st->rhoT = calloc(c, sizeof(double));
    st->T_star = calloc(c, sizeof(double));
    st->P = calloc(c, sizeof(double));
    st->eta = calloc(c, sizeof(double));
    st->mu_n = calloc(c, sizeof(double));
    st->lambda = calloc(c, sizeof(double));
    st->u2 = calloc(c, sizeof(double));
    st->w2 = calloc(c, sizeof(double));
    st->mom_c = calloc(c, sizeof(double));
    st->src = calloc(c, sizeof *st->src);
    st->rho_face = calloc(f, sizeof(double));
    st->rhs_face = calloc(f, sizeof(double));
    st->rhs_cell = calloc(c, sizeof(double));
    st->dry = calloc(c, 1);
    st->dry_face = calloc(f, 1);
    st->wk = ekm_implicit_alloc(n);
    st->backup = ekm_state_alloc(n, sc->length);
    st->hyp = calloc(c, sizeof *st->hyp);
    st->u2_old = calloc(c, sizeof(double));
    st->dw_old = calloc(c, sizeof(double));
    st->du_face_old = calloc(f, sizeof(double));
    st->rate_prev = calloc(c, sizeof(double));
    st->kface = calloc(f, sizeof(double));
    st->t0face = calloc(f, sizeof(double));
    st->solid_face = calloc(f, 1);
    st->dry_T = calloc(c, 1);
    st->T_keep = calloc(c, sizeof(double));
    st->rhs_face0 = calloc(f, sizeof(double));
    st->fail_time = -1.0;
    st->fail_cell = -1;
    if (!st->F || !st->qF || !st->phi_new || !st->rhoU || !st->rhoT || !st->T_star || !st->P ||
        !st->eta || !st->mu_n || !st->lambda || !st->u2 || !st->w2 || !st->mom_c || !st->src ||
        !st->rho_face || !st->rhs_face || !st->rhs_cell || !st->dry || !st->dry_face ||
        !st->wk || !st->backup || !st->hyp || !st->u2_old || !st->dw_old || !st->du_face_old || !st->rate_prev || !st->kface || !st->t0face ||
        !st->solid_face || !st->dry_T || !st->T_keep || !st->rhs_face0) {
        ekm_step_free(st);
        EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the stepper (%d cells)", n);
        return NULL;
    }
    if (sc->numerics.convection == EKM_CONVECTION_TVD) {
        const ekm_limiter *lim;
        if (ekm_limiter_find(sc->numerics.limiter, &lim, err) != EKM_OK) {
            ekm_step_free(st);
            return NULL;
        }
        st->psi = lim->psi;
    }
    return st;
}

void ekm_step_free(ekm_stepper *st)
{
    if (!st)
        return;
    free(st->F); free(st->qF); free(st->phi_new); free(st->rhoU); free(st->rhoT);
    free(st->T_star); free(st->P); free(st->eta); free(st->mu_n); free(st->lambda);
    free(st->u2); free(st->w2); free(st->mom_c); free(st->src); free(st->rho_face); free(st->rhs_face);
    free(st->rhs_cell); free(st->dry); free(st->dry_face);
    ekm_implicit_free(st->wk);
    ekm_state_free(st->backup);
    free(st->hyp); free(st->u2_old); free(st->dw_old); free(st->du_face_old); free(st->rate_prev); free(st->kface); free(st->t0face);
    free(st->solid_face); free(st->dry_T); free(st->T_keep); free(st->rhs_face0);
    free(st);
}

static inline double max2(double a, double b) { return a > b ? a : b; }

/* u' [1/s] at face f of the state (walls: through the wall's conductance). */
static double face_shear_rate(const ekm_stepper *st, const ekm_state *s, int f)
{
    const int n = s->n;
    if (f > 0 && f < n)
        return (s->u[f] - s->u[f - 1]) / s->dz;
    const ekm_bc_face bf = ekm_bc_evaluate(f == 0 ? &st->sc->bottom : &st->sc->top,
                                           f == 0 ? EKM_SIDE_BOTTOM : EKM_SIDE_TOP, s->t, s);
    return f == 0 ? (s->u[0] - bf.u_wall) * bf.wall_conductance : (bf.u_wall - s->u[n - 1]) * bf.wall_conductance;
}

/* The largest relaxation rate of the hypoplastic law [1/s] over the solid
 * cells and their faces (each at its own rates and phi, as the step
 * integrates them), from the state at the start of the step: the rates the
 * step will lag its norm on. */
static double solid_relaxation_max(const ekm_stepper *st, const ekm_state *s)
{
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const int n = s->n;
    double relax = 0.0, du_below = face_shear_rate(st, s, 0);
    for (int j = 0; j < n; j++) {
        const double du_above = face_shear_rate(st, s, j + 1);
        if (s->solid[j] && s->phi[j] >= sc->numerics.phi_dry) {
            const double dw = (s->w[j + 1] - s->w[j]) / s->dz;
            const double phi = ekm_scenario_law_phi(sc, s->phi[j]);
            relax = max2(relax, ekm_hypo_relaxation_rate(m, sc->variant, phi, 0.5 * (du_below + du_above), dw));
            relax = max2(relax, ekm_hypo_relaxation_rate(m, sc->variant, phi, du_below, dw));
            relax = max2(relax, ekm_hypo_relaxation_rate(m, sc->variant, phi, du_above, dw));
        }
        du_below = du_above;
    }
    return relax;
}

/* Largest convective speed [m/s] (faces and inflows) and the largest EKM
 * sound speeds squared [m^2/s^2] of the flowing and of the solid cells. */
static void wave_speeds(const ekm_stepper *st, const ekm_state *s, double *speed, double *c2_flow,
                        double *c2_solid)
{
    const ekm_scenario *sc = st->sc;
    double v = 0.0;
    for (int f = 0; f <= s->n; f++)
        v = max2(v, fabs(s->w[f]));
    v = max2(v, sc->bottom.kind == EKM_BC_INFLOW ? fabs(sc->bottom.w) : 0.0);
    v = max2(v, sc->top.kind == EKM_BC_INFLOW ? fabs(sc->top.w) : 0.0);
    *speed = v;
    *c2_flow = *c2_solid = 0.0;
    for (int j = 0; j < s->n; j++)
        if (s->phi[j] >= sc->numerics.phi_dry) {
            const double c2 = ekm_sound_speed_squared(&sc->material, s->phi[j], s->T[j]);
            double *c2_max = s->solid[j] ? c2_solid : c2_flow;
            *c2_max = max2(*c2_max, c2);
        }
}

/* cfl dz / (speed + sqrt(c2)), INFINITY when nothing moves. */
static double acoustic_dt(const ekm_stepper *st, const ekm_state *s, double speed, double c2)
{
    return speed + sqrt(c2) > 0.0 ? st->sc->numerics.cfl * s->dz / (speed + sqrt(c2)) : INFINITY;
}

double ekm_step_max_dt(const ekm_stepper *st, const ekm_state *s)
{
    const ekm_scenario *sc = st->sc;
    double speed, c2_max, c2_solid;
    wave_speeds(st, s, &speed, &c2_max, &c2_solid);
    /* Compression limit: predicted dphi/dt = -phi dw/dz must not close more
     * than half of phi_step_max of the gap to phi_cp in one step (the
     * step is rejected beyond phi_step_max; this avoids most rejections). */
    double rate_max = 0.0; /* largest compression rate relative to the gap [1/s] */
    const double phi_cp = sc->material.phi_cp;
    for (int j = 0; j < s->n; j++)
        if (s->phi[j] >= sc->numerics.phi_dry) {
            const double compression = -s->phi[j] * (s->w[j + 1] - s->w[j]) / s->dz;
            if (compression > 0.0)
                rate_max = max2(rate_max, compression / (phi_cp - s->phi[j]));
        }
    double dt = acoustic_dt(st, s, speed, c2_max);
    /* Solid cells: their stress is implicit in the momentum solves (hypo.h),
     * so the EKM's sound speed does not limit them; the accuracy of the law's
     * lagged norm does (solid_relax_step, solid_relaxation_max).  Never
     * below the acoustic limit they had as flow cells: at that step the
     * linearly implicit law is accurate enough (and a cell flowing
     * plastically on the limit surface relaxes fast but to its fixed point). */
    if (c2_solid > 0.0) {
        const double relax = solid_relaxation_max(st, s);
        const double dt_relax = relax > 0.0 ? sc->numerics.solid_relax_step / relax : INFINITY;
        dt = fmin(dt, fmax(dt_relax, acoustic_dt(st, s, speed, c2_solid)));
    }
    if (!isfinite(dt))
        dt = sc->numerics.dt_max;
    if (rate_max > 0.0)
        dt = fmin(dt, 0.5 * sc->numerics.phi_step_max / rate_max);
    return fmin(dt, sc->numerics.dt_max);
}

double ekm_step_restart_dt(const ekm_stepper *st, const ekm_state *s)
{
    double speed, c2_flow, c2_solid;
    wave_speeds(st, s, &speed, &c2_flow, &c2_solid);
    return fmin(acoustic_dt(st, s, speed, max2(c2_flow, c2_solid)), ekm_step_max_dt(st, s));
}

/* Phase 2: face fluxes and the new volume fractions; 0 = reject. */
static int mass_update(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb,
                       const ekm_bc_face *bt, double dt)
{
    const int n = s->n;
    const ekm_material *m = &st->sc->material;
    double *F = st->F;
    F[0] = s->w[0] * (s->w[0] > 0.0 ? bb->phi_in : s->phi[0]);
    F[n] = s->w[n] * (s->w[n] < 0.0 ? bt->phi_in : s->phi[n - 1]);
    for (int f = 1; f < n; f++)
        F[f] = s->w[f] == 0.0 ? 0.0 : s->w[f] * ekm_flux_face_value(s->phi, n, f, s->w[f] > 0.0, st->psi);
    const double r = dt / s->dz;
    for (int j = 0; j < n; j++) {
        const double phi = s->phi[j];
        const double phi_new = phi - r * (F[j + 1] - F[j]);
        st->phi_new[j] = phi_new;
        if (!(phi_new >= 0.0) || !(phi_new - phi <= st->sc->numerics.phi_step_max * (m->phi_cp - phi))) {
            snprintf(st->reject_reason, sizeof st->reject_reason,
                     "t = %.9g s, dt = %.3g s, cell %d (z = %.6g m): phi %.9g -> %.9g "
                     "(allowed [0, %.9g)), T = %.3g m^2/s^2, w below/above = %.3g/%.3g m/s",
                     s->t, dt, j, s->z[j], phi, phi_new,
                     phi + st->sc->numerics.phi_step_max * (m->phi_cp - phi), s->T[j], s->w[j],
                     s->w[j + 1]);
            return 0;
        }
    }
    return 1;
}

/* Phase 3: convection of rho u, rho T and the face momentum. */
static void convection(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb,
                       const ekm_bc_face *bt, double dt)
{
    const int n = s->n;
    const double rho_p = st->sc->material.rho_p;
    const double r = dt / s->dz;
    ekm_flux_advect(n, st->F, s->u, bb->u_in, bt->u_in, st->psi, st->qF);
    for (int j = 0; j < n; j++)
        st->rhoU[j] = rho_p * (s->phi[j] * s->u[j] - r * (st->qF[j + 1] - st->qF[j]));
    ekm_flux_advect(n, st->F, s->T, bb->T_in, bt->T_in, st->psi, st->qF);
    for (int j = 0; j < n; j++)
        st->rhoT[j] = rho_p * (s->phi[j] * s->T[j] - r * (st->qF[j + 1] - st->qF[j]));
    ekm_flux_face_momentum(n, st->F, s->w, st->mom_c);
    for (int f = 1; f < n; f++) {
        const double phi_face = 0.5 * (s->phi[f - 1] + s->phi[f]);
        st->rhs_face[f] = rho_p * (phi_face * s->w[f] - r * (st->mom_c[f] - st->mom_c[f - 1]));
    }
}

/* Phase 4: T*, dry flags and transport coefficients at (phi*, T*). */
static void properties(ekm_stepper *st, int n)
{
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    for (int j = 0; j < n; j++) {
        const double phi = st->phi_new[j];
        st->dry[j] = phi < sc->numerics.phi_dry;
        if (st->dry[j]) {
            st->T_star[j] = 0.0;
            st->P[j] = st->eta[j] = st->mu_n[j] = st->lambda[j] = 0.0;
            continue;
        }
        const double T = max2(st->rhoT[j] / (m->rho_p * phi), sc->numerics.T_floor);
        st->T_star[j] = T;
        const ekm_transport c = ekm_transport_coefficients(m, sc->variant, phi, T);
        st->eta[j] = c.eta;
        st->mu_n[j] = c.mu_n;
        st->lambda[j] = c.lambda;
        st->P[j] = ekm_pressure_kinetic(m, phi, T) + ekm_pressure_yield(m, phi);
    }
    for (int f = 1; f < n; f++) {
        const double phi_face = 0.5 * (st->phi_new[f - 1] + st->phi_new[f]);
        st->dry_face[f] = phi_face < sc->numerics.phi_dry;
        st->rho_face[f] = m->rho_p * phi_face;
    }
}

/* Squared shear rate at cells from the face gradients of u; faces next to
 * an empty cell or stress-free boundaries carry none. */
static void shear_rates(const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                        const unsigned char *dry, double *u2, double *w2)
{
    const int n = s->n;
    for (int j = 0; j < n; j++) {
        double sum = 0.0;
        int count = 0;
        if (j > 0 && !dry[j - 1]) {
            const double g = (s->u[j] - s->u[j - 1]) / s->dz;
            sum += g * g;
            count++;
        } else if (j == 0 && bb->wall_conductance > 0.0) {
            const double g = (s->u[0] - bb->u_wall) * bb->wall_conductance;
            sum += g * g;
            count++;
        }
        if (j < n - 1 && !dry[j + 1]) {
            const double g = (s->u[j + 1] - s->u[j]) / s->dz;
            sum += g * g;
            count++;
        } else if (j == n - 1 && bt->wall_conductance > 0.0) {
            const double g = (bt->u_wall - s->u[n - 1]) * bt->wall_conductance;
            sum += g * g;
            count++;
        }
        u2[j] = count ? sum / count : 0.0;
        const double dw = (s->w[j + 1] - s->w[j]) / s->dz;
        w2[j] = dw * dw;
    }
}

/* ---- solid regime (hypo.h) ---- */

#define DEG (3.14159265358979323846 / 180.0)

/* The rates the solid step lags its norm ||kappa|| on: u'^2 and w' at
 * cells, u' at faces. */
static void lagged_rates(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                         const unsigned char *dry)
{
    const int n = s->n;
    shear_rates(s, bb, bt, dry, st->u2_old, st->T_keep /* scratch */);
    for (int j = 0; j < n; j++)
        st->dw_old[j] = (s->w[j + 1] - s->w[j]) / s->dz;
    st->du_face_old[0] = (s->u[0] - bb->u_wall) * bb->wall_conductance;
    st->du_face_old[n] = (bt->u_wall - s->u[n - 1]) * bt->wall_conductance;
    for (int f = 1; f < n; f++)
        st->du_face_old[f] = (s->u[f] - s->u[f - 1]) / s->dz;
}

/* Before the step: the old state's rates (lagged ||kappa||) and which faces
 * carry a rate-law shear stress.  Returns the number of solid cells. */
static int solid_begin(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt)
{
    const int n = s->n;
    int count = 0;
    for (int j = 0; j < n; j++) {
        st->dry_T[j] = s->phi[j] < st->sc->numerics.phi_dry; /* scratch: old emptiness */
        count += s->solid[j];
    }
    if (!count) {
        memset(st->solid_face, 0, (size_t)n + 1);
        return 0;
    }
    lagged_rates(st, s, bb, bt, st->dry_T);
    st->solid_face[0] = s->solid[0] && bb->wall_conductance > 0.0;
    st->solid_face[n] = s->solid[n - 1] && bt->wall_conductance > 0.0;
    for (int f = 1; f < n; f++)
        st->solid_face[f] = s->solid[f - 1] && s->solid[f];
    return count;
}

/* Phase 4 for solid cells: the prepared rate-law step; the normal solve
 * sees the known stress as P = -E_zz and the stiffness as mu_n = V_zz. */
static void solid_properties(ekm_stepper *st, const ekm_state *s, double dt)
{
    const ekm_material *m = &st->sc->material;
    for (int j = 0; j < s->n; j++) {
        if (!s->solid[j] || st->dry[j])
            continue;
        const ekm_hypo_stress sig = {s->sxx[j], s->syy[j], s->szz[j], 0.0};
        st->hyp[j] = ekm_hypo_prepare(m, st->sc->variant, ekm_scenario_law_phi(st->sc, st->phi_new[j]), dt, &sig,
                                      sqrt(st->u2_old[j]), st->dw_old[j]);
        /* A dense solid cell that extends to phi_co within the step: its
         * limit surface shrinks to the point sigma = 0 (P_Y -> 0), so it
         * is stress-free (it switches to flow after the step). */
        if (st->phi_new[j] <= m->phi_co + st->sc->hypo.phi_margin && s->phi[j] > m->phi_co + st->sc->hypo.phi_margin)
            st->hyp[j] = (ekm_hypo_implicit){.xz_scale = 0.0};
        st->P[j] = -st->hyp[j].Ezz;
        st->mu_n[j] = st->hyp[j].Vzz;
        st->lambda[j] = 0.0;
        st->T_star[j] = st->T_keep[j] = s->T[j];
        st->eta[j] = ekm_transport_coefficients(m, st->sc->variant, st->phi_new[j], s->T[j]).eta;
    }
}

static int face_solid(const ekm_stepper *st, int n, int f)
{
    return st->solid_face[f] && (f == 0 || !st->dry[f - 1]) && (f == n || !st->dry[f]);
}

/* Phase 6 coefficients: face stress tau_f = k_f (jump of u) + t0_f. */
static void solid_shear_faces(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb,
                              const ekm_bc_face *bt, double dt)
{
    const int n = s->n;
    const double dz = s->dz;
    for (int f = 0; f <= n; f++) {
        double k = 0.0, t0 = 0.0;
        if (face_solid(st, n, f)) {
            /* The face is the material point of sigma_xz: its rate law uses
             * the face's own rate and P_Y (mean of the two cells), not the
             * cells' (at the surface cell of a layer the face stress is twice
             * the cell's, and the cell's relaxation applied to it made the
             * face yield early and creep). */
            const int a = f > 0 ? f - 1 : 0, b = f < n ? f : n - 1;
            double phi_f = 0.5 * (st->phi_new[a] + st->phi_new[b]);
            /* a wall face: phi (so P_Y) extrapolated linearly from the two
             * cells next to it, as the stress it carries is */
            const int in = f == 0 ? 1 : n - 2;
            if ((f == 0 || f == n) && in >= 0 && in < n && !st->dry[in])
                phi_f = fmax(fmin(1.5 * st->phi_new[a] - 0.5 * st->phi_new[in],
                                  0.5 * (st->phi_new[a] + st->sc->material.phi_cp)), 0.5 * st->phi_new[a]);
            const ekm_hypo_stress none = {0};
            ekm_hypo_implicit c = ekm_hypo_prepare(&st->sc->material, st->sc->variant,
                                                   ekm_scenario_law_phi(st->sc, phi_f), dt, &none,
                                                   st->du_face_old[f], 0.5 * (st->dw_old[a] + st->dw_old[b]));
            if (st->hyp[a].xz_scale == 0.0 || st->hyp[b].xz_scale == 0.0)
                c.xz_scale = c.Vxz = 0.0; /* a cell extends to phi_co: stress-free (solid_properties) */
            t0 = s->sxz[f] * c.xz_scale;
            k = f == 0 ? c.Vxz * bb->wall_conductance : f == n ? c.Vxz * bt->wall_conductance : c.Vxz / dz;
        } else if (f == 0) {
            k = !st->dry[0] ? st->eta[0] * bb->wall_conductance : 0.0;
        } else if (f == n) {
            k = !st->dry[n - 1] ? st->eta[n - 1] * bt->wall_conductance : 0.0;
        } else {
            k = ekm_face_viscosity(st->eta[f - 1], s->solid[f - 1], st->eta[f], s->solid[f]) / dz;
        }
        st->kface[f] = k;
        st->t0face[f] = t0;
    }
}

/* After the solves: the new stresses of solid cells and faces. */
static void solid_finish(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt)
{
    const int n = s->n;
    for (int j = 0; j < n; j++) {
        if (!s->solid[j] || st->dry[j])
            continue;
        const ekm_hypo_stress sig = ekm_hypo_finish(&st->hyp[j], 0.0, 0.0, (s->w[j + 1] - s->w[j]) / s->dz);
        s->sxx[j] = sig.xx;
        s->syy[j] = sig.yy;
        s->szz[j] = sig.zz;
    }
    /* Outflow ends: zero gradient of the stress too (as of phi, u, T), so
     * a solid edge cell does not act as a support for the material inside. */
    if (n > 1 && st->sc->bottom.kind == EKM_BC_OUTFLOW && s->solid[0] && s->solid[1] && !st->dry[1]) {
        s->sxx[0] = s->sxx[1]; s->syy[0] = s->syy[1]; s->szz[0] = s->szz[1];
    }
    if (n > 1 && st->sc->top.kind == EKM_BC_OUTFLOW && s->solid[n - 1] && s->solid[n - 2] && !st->dry[n - 2]) {
        s->sxx[n - 1] = s->sxx[n - 2]; s->syy[n - 1] = s->syy[n - 2]; s->szz[n - 1] = s->szz[n - 2];
    }
    for (int f = 0; f <= n; f++) {
        if (!face_solid(st, n, f))
            continue;
        const double du = f == 0 ? s->u[0] - bb->u_wall : f == n ? bt->u_wall - s->u[n - 1] : s->u[f] - s->u[f - 1];
        s->sxz[f] = st->t0face[f] + st->kface[f] * du;
    }
}

/* The shear stress cell j would have as a flowing cell with viscosity
 * eta_j: the mean of its two face stresses of the flow law (as the output,
 * fields.h, and the shear solve: next to a solid cell the face takes eta_j,
 * next to a flowing one the harmonic mean, st->eta of the neighbours). */
static double flow_cell_shear(const ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb,
                              const ekm_bc_face *bt, int j, double eta_j)
{
    const int n = s->n;
    double below = 0.0, above = 0.0;
    if (j == 0)
        below = eta_j * (s->u[0] - bb->u_wall) * bb->wall_conductance;
    else
        below = ekm_face_viscosity(st->eta[j - 1], s->solid[j - 1], eta_j, 0) * (s->u[j] - s->u[j - 1]) / s->dz;
    if (j == n - 1)
        above = eta_j * (bt->u_wall - s->u[n - 1]) * bt->wall_conductance;
    else
        above = ekm_face_viscosity(eta_j, 0, st->eta[j + 1], s->solid[j + 1]) * (s->u[j + 1] - s->u[j]) / s->dz;
    return 0.5 * (below + above);
}

/* Phase 9: the flow face stresses (the solid's initial face stress when a
 * face turns solid) and the per-cell switches (step.h). */
static void regimes(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt)
{
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const ekm_hypo_params *h = &sc->hypo;
    const int n = s->n;
    double *eta = st->eta;
    for (int j = 0; j < n; j++)
        eta[j] = st->dry[j] ? 0.0 : ekm_transport_coefficients(m, sc->variant, s->phi[j], s->T[j]).eta;
    for (int f = 0; f <= n; f++) {
        if (face_solid(st, n, f) && (f == 0 || s->solid[f - 1]) && (f == n || s->solid[f]))
            continue;
        if (f == 0)
            s->sxz[0] = !st->dry[0] ? eta[0] * bb->wall_conductance * (s->u[0] - bb->u_wall) : 0.0;
        else if (f == n)
            s->sxz[n] = !st->dry[n - 1] ? eta[n - 1] * bt->wall_conductance * (bt->u_wall - s->u[n - 1]) : 0.0;
        else
            s->sxz[f] = ekm_face_viscosity(eta[f - 1], s->solid[f - 1], eta[f], s->solid[f]) * (s->u[f] - s->u[f - 1]) / s->dz;
    }
    for (int j = 0; j < n; j++) {
        const double phi = s->phi[j];
        const double dw = (s->w[j + 1] - s->w[j]) / s->dz;
        const double du_abs = sqrt(st->u2[j]);
        const int at_rest = fabs(dw) <= h->rest_rate && du_abs <= h->rest_rate;
        const double rate = sqrt(st->u2[j] + dw * dw), rate_before = st->rate_prev[j];
        st->rate_prev[j] = rate;
        const int compress = dw < 0.0 && du_abs / sqrt(2.0) <= -dw;
        const double PY = ekm_pressure_yield(m, phi);
        const int loose = !(PY > 0.0) || phi <= m->phi_co + h->phi_margin;
        /* a loose cell rests on a solid one: it takes the yield temperature of that one */
        const double Y = loose ? (j > 0 && s->solid[j - 1] ? ekm_yield_temperature(m, s->phi[j - 1]) : 0.0)
                               : ekm_yield_temperature(m, phi);
        if (s->solid[j]) {
            const ekm_hypo_stress sig = {s->sxx[j], s->syy[j], s->szz[j], 0.5 * (s->sxz[j] + s->sxz[j + 1])};
            const double fY = loose ? NAN : ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &sig);
            /* quasi-static T of the current rates and the flow stress there */
            const double T = st->dry[j] ? 0.0
                : fmax(ekm_temperature_local_balance(m, sc->variant, phi, st->u2[j], dw * dw), sc->numerics.T_floor);
            double jump = 0.0;
            int go;
            const char *why;
            if (st->dry[j]) {
                go = 1; why = "empty";
            } else if (loose) {
                go = !(Y > 0.0) || sig.zz >= 0.0;
                why = "loose cell unloaded";
            } else {
                go = 0;
                why = "limit surface";
                if (fY >= -h->yield_tol && !compress) {
                    ekm_hypo_stress e = ekm_hypo_from_flow(m, sc->variant, phi, T, 0.0, dw);
                    e.xz = flow_cell_shear(st, s, bb, bt, j, ekm_transport_coefficients(m, sc->variant, phi, T).eta);
                    jump = fmax(fabs(e.zz - sig.zz), fabs(e.xz - sig.xz)) / fmax(fabs(sig.zz), fabs(sig.xz));
                    go = jump <= h->jump_tol || !h->carry_over;
                }
            }
            if (!go)
                continue;
            if (!st->dry[j]) {
                if (h->carry_over) {
                    /* no limit surface below phi_co: T from stress continuity */
                    const double Tm = loose ? ekm_hypo_flow_T_for_stress(m, sc->variant, phi, dw, sig.zz) : -1.0;
                    s->T[j] = Tm >= 0.0 ? fmax(Tm, sc->numerics.T_floor) : T;
                    eta[j] = ekm_transport_coefficients(m, sc->variant, phi, s->T[j]).eta;
                }
                if (!loose) {
                    st->jump_max = fmax(st->jump_max, jump);
                    if (st->fail_time < 0.0) {
                        st->fail_time = s->t;
                        st->fail_angle = ekm_scenario_angle_at(sc, s->t);
                        st->fail_fY = fY;
                        st->fail_cell = j;
                        st->fail_phi = ekm_scenario_law_phi(sc, phi); /* the phi of fY */
                        st->fail_stress = sig;
                    }
                }
            }
            s->solid[j] = 0;
            st->to_flow++;
            if (h->log)
                fprintf(stderr, "ekm: t = %.9g s: cell %d (z = %.6g m) solid -> flow (%s): phi %.6f, f_Y %.3e, "
                        "w' %.3e, |u'| %.3e 1/s, sigma_zz %.6g Pa, sigma_xz %.6g Pa, T := %.3e, jump %.2e\n",
                        s->t, j, s->z[j], why, phi, fY, dw, du_abs, sig.zz, sig.xz, s->T[j], jump);
        } else if (!st->dry[j] && Y > 0.0 && (compress || at_rest) && s->T[j] < h->T_ratio * Y &&
                   phi >= h->phi_loose) {
            ekm_hypo_stress e = ekm_hypo_from_flow(m, sc->variant, phi, s->T[j], 0.0, dw);
            /* At rest (not compressing) near the limit surface (f_Y >= -10
             * yield_tol) only while the rates do not grow: a cell that has
             * just failed under a growing load flows quasi-statically on the
             * surface at tiny, growing rates; turned solid it would fail again
             * at once, step after step.  One that comes to rest decelerates. */
            if (!compress && !loose && rate > rate_before) {
                e.xz = 0.5 * (s->sxz[j] + s->sxz[j + 1]);
                if (!(ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &e) < -10.0 * h->yield_tol))
                    continue;
            }
            if (!h->carry_over) /* tests only (scenario.h) */
                e.xx = e.yy = e.zz = -PY;
            s->sxx[j] = e.xx;
            s->syy[j] = e.yy;
            s->szz[j] = e.zz;
            s->solid[j] = 1;
            st->to_solid++;
            if (h->log)
                fprintf(stderr, "ekm: t = %.9g s: cell %d (z = %.6g m) flow -> solid%s: phi %.6f, T %.3e, w' %.3e, "
                        "|u'| %.3e 1/s, sigma_zz %.6g Pa, jump 0\n",
                        s->t, j, s->z[j], loose ? " (loose, on a solid cell)" : "", phi, s->T[j], dw, du_abs, e.zz);
        }
    }
}

static int state_finite(const ekm_state *s)
{
    for (int j = 0; j < s->n; j++)
        if (!isfinite(s->phi[j]) || !isfinite(s->T[j]) || !isfinite(s->u[j]))
            return 0;
    for (int f = 0; f <= s->n; f++)
        if (!isfinite(s->w[f]))
            return 0;
    return 1;
}

static int reject(ekm_stepper *st, ekm_state *s, int *accepted)
{
    ekm_state_copy(s, st->backup);
    *accepted = 0;
    return 0;
}

ekm_status ekm_step_apply(ekm_stepper *st, ekm_state *s, double dt, int *accepted, ekm_error *err)
{
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const int n = s->n;
    *accepted = 1;
    ekm_state_copy(st->backup, s);

    /* 1. boundaries */
    const ekm_bc_face bb = ekm_bc_evaluate(&sc->bottom, EKM_SIDE_BOTTOM, s->t, s);
    const ekm_bc_face bt = ekm_bc_evaluate(&sc->top, EKM_SIDE_TOP, s->t, s);
    s->w[0] = ekm_bc_face_w(&bb, EKM_SIDE_BOTTOM, s);
    s->w[n] = ekm_bc_face_w(&bt, EKM_SIDE_TOP, s);
    /* Gravity at the end of the step (the momentum solves are implicit):
     * with a tilting base the stresses then balance the load of the new
     * time, and the velocity of a solid under slowly growing load does not
     * depend on dt (evaluated at the start, a step shortened to hit an
     * output time carried the whole load increment of the step before). */
    const double angle = ekm_scenario_angle_at(sc, s->t + dt) * DEG;
    st->g_x = sc->gravity * sin(angle);
    st->g_z = -sc->gravity * cos(angle);
    const int n_solid = solid_begin(st, s, &bb, &bt);

    /* 2. mass */
    if (!mass_update(st, s, &bb, &bt, dt)) {
        reject(st, s, accepted);
        return EKM_OK;
    }
    /* 3. convection */
    convection(st, s, &bb, &bt, dt);
    /* 4. properties */
    properties(st, n);
    if (n_solid)
        solid_properties(st, s, dt);

    ekm_error serr;
    /* Phases 5-6 run twice when solid cells exist: the second pass
     * prepares the rate law with ||kappa|| from the first pass's rates
     * (a fixed-point step towards backward Euler in the norm), so that a
     * cell that starts to deform within one step already deforms
     * plastically (with the lagged norm alone the first step of a sudden
     * extension would be purely elastic and overshoot the limit surface). */
    memcpy(st->rhs_face0, st->rhs_face, ((size_t)n + 1) * sizeof *st->rhs_face);
    for (int pass = 0; pass < (n_solid ? 2 : 1); pass++) {
        if (pass == 1) {
            memcpy(st->rhs_face, st->rhs_face0, ((size_t)n + 1) * sizeof *st->rhs_face);
            lagged_rates(st, s, &bb, &bt, st->dry);
            solid_properties(st, s, dt);
        }
        /* 5. normal momentum */
        for (int f = 1; f < n; f++)
            st->rhs_face[f] += dt * (st->rho_face[f] * st->g_z - (st->P[f] - st->P[f - 1]) / s->dz);
        ekm_implicit_end nb = {.follows = bb.w_follows, .value = bb.w};
        ekm_implicit_end nt = {.follows = bt.w_follows, .value = bt.w};
            if (ekm_implicit_normal_velocity(st->wk, n, dt, s->dz, st->rho_face, st->rhs_face, st->mu_n,
                                         st->dry_face, nb, nt, s->w, &serr) != EKM_OK) {
            snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s: %.400s", s->t, serr.message);
            reject(st, s, accepted);
            return EKM_OK;
        }

        /* A face whose upwind cell is empty (phi < max(phi_vacuum, phi_dry))
         * carries (almost) no mass, and vacuum cannot push: it may not compress
         * the material cell next to it.  Without
         * this a resting surface cell keeps a "ghost" face velocity (gravity on
         * the face's half cell against its viscosity) that heats it forever.
         * Active with the solid regime or phi_vacuum > 0 (flow-only runs
         * are unchanged). */
        const double vac = fmax(sc->numerics.phi_vacuum, sc->numerics.phi_dry);
        const int vacuum_rule = sc->hypo.enabled || sc->numerics.phi_vacuum > 0.0;
        for (int f = 1; vacuum_rule && f < n; f++) {
            const double below = st->phi_new[f - 1], above = st->phi_new[f];
            if (above < vac && below >= vac && s->w[f] < s->w[f - 1])
                s->w[f] = s->w[f - 1];
            else if (below < vac && above >= vac && s->w[f] > s->w[f + 1])
                s->w[f] = s->w[f + 1];
        }

        /* 6. shear momentum */
        for (int j = 0; j < n; j++)
            st->rhs_cell[j] = st->rhoU[j] + dt * m->rho_p * st->phi_new[j] * st->g_x;
        ekm_implicit_end sb = {.value = bb.u_wall, .conductance = bb.wall_conductance};
        ekm_implicit_end stp = {.value = bt.u_wall, .conductance = bt.wall_conductance};
        double *rho_cell = st->qF; /* reuse: rho at cells */
        for (int j = 0; j < n; j++)
            rho_cell[j] = m->rho_p * st->phi_new[j];
        ekm_status shear_rc;
        if (n_solid) {
            solid_shear_faces(st, s, &bb, &bt, dt);
            shear_rc = ekm_implicit_shear_faces(st->wk, n, dt, s->dz, rho_cell, st->rhs_cell, st->kface, st->t0face,
                                                st->dry, bb.u_wall, bt.u_wall, s->u, &serr);
        } else {
            shear_rc = ekm_implicit_shear_velocity(st->wk, n, dt, s->dz, rho_cell, st->rhs_cell, st->eta, st->dry,
                                                   sb, stp, s->u, &serr);
        }
        if (shear_rc != EKM_OK) {
            snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s: %.400s", s->t, serr.message);
            reject(st, s, accepted);
            return EKM_OK;
        }
    }

    /* 7. temperature */
    memcpy(s->phi, st->phi_new, (size_t)n * sizeof *s->phi);
    if (n_solid)
        solid_finish(st, s, &bb, &bt);
    shear_rates(s, &bb, &bt, st->dry, st->u2, st->w2);
    for (int j = 0; j < n; j++)
        st->dry_T[j] = st->dry[j] || (n_solid && s->solid[j]);
    for (int j = 0; j < n; j++) {
        s->T[j] = st->T_star[j];
        if (st->dry[j])
            continue;
        st->src[j] = ekm_temperature_source_coeffs(m, sc->variant, s->phi[j], st->u2[j], st->w2[j]);
    }
    int iterations = 0;
    if (ekm_implicit_temperature(st->wk, n, dt, s->dz, m->rho_p, s->phi, st->rhoT, st->lambda, st->src, st->dry_T, sc->numerics.T_floor, sc->numerics.newton_tol,
                                 sc->numerics.newton_max, s->T, &iterations, &serr) != EKM_OK) {
        snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s, dt = %.3g s: %.400s", s->t, dt,
                 serr.message);
        reject(st, s, accepted);
        return EKM_OK;
    }
    for (int j = 0; j < n; j++) {
        if (st->dry[j])
            s->u[j] = 0.0;
        else if (n_solid && s->solid[j])
            s->T[j] = st->T_keep[j];
    }

    /* 8. accept */
    if (!state_finite(s)) {
        snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s, dt = %.3g s: non-finite state",
                 s->t, dt);
        reject(st, s, accepted);
        return EKM_OK;
    }
    s->mass_in += dt * m->rho_p * (st->F[0] - st->F[n]);
    s->t += dt;
    s->steps++;
    if (sc->hypo.enabled)
        regimes(st, s, &bb, &bt);
    st->newton_iterations = iterations;
    (void)err;
    return EKM_OK;
}
