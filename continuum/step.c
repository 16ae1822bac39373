#include "step.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bc.h"
#include "closure.h"
#include "control.h"
#include "rates.h"
#include "regime.h"

/* The thermal relaxation limit at the end of a step: dt times the rate of
 * the new state at most this times [numerics] thermal_relax_step (1 %
 * above the limit the step was chosen by, so that a steady state, whose
 * rate does not change, is never rejected by round-off). */
#define EKM_THERMAL_END_FACTOR 1.01

ekm_stepper *ekm_step_alloc(const ekm_scenario *sc, ekm_error *err)
{
    ekm_error cerr;
    if (ekm_closure_require_ekm(sc->closure, "the EKM's 1D time stepper", &cerr) != EKM_OK) {
        EKM_FAIL(err, cerr.code, "%s: %s", sc->source, cerr.message);
        return NULL;
    }
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
    st->rhs_face0 = calloc(f, sizeof(double));
    st->dP_dphi = calloc(c, sizeof(double));
    st->phi_coupled = calloc(f, sizeof(double));
    st->g_cell = calloc(c, sizeof(double));
    st->Y_cell = calloc(c, sizeof(double));
    st->T_change = calloc(c, sizeof(double));
    st->moving = ekm_boundary_pressure_wall(&sc->top);
    if (!st->F || !st->qF || !st->phi_new || !st->rhoU || !st->rhoT || !st->T_star || !st->P || !st->eta ||
        !st->mu_n || !st->lambda || !st->u2 || !st->w2 || !st->mom_c || !st->src || !st->rho_face ||
        !st->rhs_face || !st->rhs_cell || !st->dry || !st->dry_face || !st->wk || !st->backup ||
        !st->rhs_face0 || !st->dP_dphi || !st->phi_coupled || !st->g_cell || !st->Y_cell || !st->T_change) {
        ekm_step_free(st);
        EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the stepper (%d cells)", n);
        return NULL;
    }
    if (ekm_regime_alloc(&st->regime, n, err) != EKM_OK) {
        ekm_step_free(st);
        return NULL;
    }
    st->flow = (ekm_regime_flow){.sc = sc,
                                 .dry = st->dry,
                                 .phi_new = st->phi_new,
                                 .u2 = st->u2,
                                 .P = st->P,
                                 .mu_n = st->mu_n,
                                 .lambda = st->lambda,
                                 .T_star = st->T_star,
                                 .eta = st->eta};
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
    free(st->F);
    free(st->qF);
    free(st->phi_new);
    free(st->rhoU);
    free(st->rhoT);
    free(st->T_star);
    free(st->P);
    free(st->eta);
    free(st->mu_n);
    free(st->lambda);
    free(st->u2);
    free(st->w2);
    free(st->mom_c);
    free(st->src);
    free(st->rho_face);
    free(st->rhs_face);
    free(st->rhs_cell);
    free(st->dry);
    free(st->dry_face);
    ekm_implicit_free(st->wk);
    ekm_state_free(st->backup);
    free(st->rhs_face0);
    ekm_regime_free(&st->regime);
    free(st->dP_dphi);
    free(st->phi_coupled);
    free(st->g_cell);
    free(st->Y_cell);
    free(st->T_change);
    free(st);
}

static inline double max2(double a, double b)
{
    return a > b ? a : b;
}

/* Phase 2: face fluxes and the new volume fractions; 0 = reject. */
static int mass_update(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                       double dt)
{
    const int n = s->n;
    const ekm_material *m = &st->sc->material;
    double *F = st->F;
    F[0] = s->w[0] * (s->w[0] > 0.0 ? bb->phi_in : s->phi[0]);
    F[n] = s->w[n] * (s->w[n] < 0.0 ? bt->phi_in : s->phi[n - 1]);
    if (st->moving) {
        /* fluxes relative to the stretching grid; none through the walls */
        F[0] = F[n] = 0.0;
        const double w_grid = st->gap_rate / n; /* face f moves at f w_grid */
        for (int f = 1; f < n; f++) {
            const double w_rel = s->w[f] - f * w_grid;
            F[f] = w_rel == 0.0 ? 0.0 : w_rel * ekm_flux_face_value(s->phi, n, f, w_rel > 0.0, st->psi);
        }
    } else {
        for (int f = 1; f < n; f++)
            F[f] = s->w[f] == 0.0 ? 0.0 : s->w[f] * ekm_flux_face_value(s->phi, n, f, s->w[f] > 0.0, st->psi);
    }
    const double r = dt / s->dz;
    const double inv_dz_new = st->moving ? 1.0 / st->dz_new : 0.0;
    for (int j = 0; j < n; j++) {
        const double phi = s->phi[j];
        const double phi_new =
            st->moving ? (phi * s->dz - dt * (F[j + 1] - F[j])) * inv_dz_new : phi - r * (F[j + 1] - F[j]);
        st->phi_new[j] = phi_new;
        if (!(phi_new >= 0.0) || !(phi_new - phi <= st->sc->numerics.phi_step_max * (m->phi_cp - phi))) {
            snprintf(st->reject_reason, sizeof st->reject_reason,
                     "t = %.9g s, dt = %.3g s, cell %d (z = %.6g m): phi %.9g -> %.9g "
                     "(allowed [0, %.9g)), T = %.3g m^2/s^2, w below/above = %.3g/%.3g m/s",
                     s->t, dt, j, s->z[j], phi, phi_new,
                     phi + st->sc->numerics.phi_step_max * (m->phi_cp - phi), s->T[j], s->w[j], s->w[j + 1]);
            st->rejected_phi++;
            return 0;
        }
    }
    return 1;
}

/* Phase 3: convection of rho u, rho T and the face momentum. */
static void convection(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                       double dt)
{
    const int n = s->n;
    const double rho_p = st->sc->material.rho_p;
    const double r = dt / s->dz;
    if (st->moving) {
        /* the content of each (stretching) cell, over its new height */
        const double dz = s->dz, rho_dz_new = rho_p / st->dz_new;
        ekm_flux_advect(n, st->F, s->u, bb->u_in, bt->u_in, st->psi, st->qF);
        for (int j = 0; j < n; j++)
            st->rhoU[j] = rho_dz_new * (s->phi[j] * s->u[j] * dz - dt * (st->qF[j + 1] - st->qF[j]));
        ekm_flux_advect(n, st->F, s->T, bb->T_in, bt->T_in, st->psi, st->qF);
        for (int j = 0; j < n; j++)
            st->rhoT[j] = rho_dz_new * (s->phi[j] * s->T[j] * dz - dt * (st->qF[j + 1] - st->qF[j]));
        ekm_flux_face_momentum(n, st->F, s->w, st->mom_c);
        for (int f = 1; f < n; f++) {
            const double phi_face = 0.5 * (s->phi[f - 1] + s->phi[f]);
            st->rhs_face[f] = rho_dz_new * (phi_face * s->w[f] * dz - dt * (st->mom_c[f] - st->mom_c[f - 1]));
        }
        return;
    }
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

/* A pressure-controlled wall: the grid takes its new height after the
 * transport (phases 2-3), and the walls' face data follow it. */
static void stretch_grid(ekm_stepper *st, ekm_state *s, ekm_bc_face *bb, ekm_bc_face *bt)
{
    s->dz = st->dz_new;
    for (int j = 0; j < s->n; j++)
        s->z[j] = (j + 0.5) * s->dz;
    *bb = ekm_bc_evaluate(&st->sc->bottom, EKM_SIDE_BOTTOM, s->t, s);
    *bt = ekm_bc_evaluate(&st->sc->top, EKM_SIDE_TOP, s->t, s);
    bt->w = st->gap_rate;
}

/* Phase 4: T*, dry flags and transport coefficients at (phi*, T*); g and
 * Y of each cell are kept for the temperature source (phase 7). */
static void properties(ekm_stepper *st, int n)
{
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const double phi_dry = sc->numerics.phi_dry, T_floor = sc->numerics.T_floor;
    /* without branches on the emptiness: an empty cell's values are
     * computed at phi_dry (finite: T at the floor) and replaced by 0 */
    const double *phi_new = st->phi_new, *rhoT = st->rhoT;
    double *T_star = st->T_star, *eta = st->eta, *mu_n = st->mu_n, *lambda = st->lambda, *P = st->P;
    double *g_cell = st->g_cell, *Y_cell = st->Y_cell;
    unsigned char *dry_cell = st->dry, *dry_face = st->dry_face;
    for (int j = 0; j < n; j++) {
        const int dry = phi_new[j] < phi_dry;
        const double phi = dry ? phi_dry : phi_new[j];
        const double T = max2(rhoT[j] / (m->rho_p * phi), T_floor);
        const ekm_cell_properties c = ekm_cell_properties_at(m, sc->variant, phi, T);
        dry_cell[j] = (unsigned char)dry;
        T_star[j] = dry ? 0.0 : T;
        eta[j] = dry ? 0.0 : c.eta;
        mu_n[j] = dry ? 0.0 : c.mu_n;
        lambda[j] = dry ? 0.0 : c.lambda;
        P[j] = dry ? 0.0 : c.P;
        g_cell[j] = dry ? 0.0 : c.g;
        Y_cell[j] = dry ? 0.0 : c.Y;
    }
    double *rho_face = st->rho_face;
    for (int f = 1; f < n; f++) {
        const double phi_face = 0.5 * (phi_new[f - 1] + phi_new[f]);
        dry_face[f] = phi_face < phi_dry;
        rho_face[f] = m->rho_p * phi_face;
    }
}

#define DEG (3.14159265358979323846 / 180.0)

/* Phase 1: the face data of both ends at time t, the boundary face
 * velocities and the gravity of the step. */
static void boundaries(ekm_stepper *st, ekm_state *s, double dt, ekm_bc_face *bb, ekm_bc_face *bt)
{
    const ekm_scenario *sc = st->sc;
    const int n = s->n;
    *bb = ekm_bc_evaluate(&sc->bottom, EKM_SIDE_BOTTOM, s->t, s);
    *bt = ekm_bc_evaluate(&sc->top, EKM_SIDE_TOP, s->t, s);
    if (st->moving) {
        st->gap_rate = ekm_bc_gap_rate(sc, s, dt);
        st->dz_new = s->dz + dt * st->gap_rate / n;
        bt->w = st->gap_rate;
    }
    s->w[0] = ekm_bc_face_w(bb, EKM_SIDE_BOTTOM, s);
    s->w[n] = ekm_bc_face_w(bt, EKM_SIDE_TOP, s);
    /* Gravity at the end of the step (the momentum solves are implicit):
     * with a tilting base the stresses then balance the load of the new
     * time, and the velocity of a solid under slowly growing load does not
     * depend on dt (evaluated at the start, a step shortened to hit an
     * output time carried the whole load increment of the step before). */
    const double angle = ekm_scenario_angle_at(sc, s->t + dt) * DEG;
    st->g_x = sc->gravity * sin(angle);
    st->g_z = -sc->gravity * cos(angle);
}

/* Phase 5, implicit coupling: what the next step's mass update (phase 2)
 * will do with the new w, linearised (implicit.h): the stiffness dP/dphi of
 * each flowing cell at (phi*, T*) (none in empty and solid cells: their
 * pressure is not the equilibrium P(phi) and solid cells are implicit
 * already), the upwind phi* of each face by the direction of the current
 * w relative to the face (the mean of the two cells where it is 0), the known fluxes of
 * prescribed ends.  On a stretching grid the fluxes relative to the faces
 * are linear in w with the same phi; the grid's own part is left out
 * (known, and zero once the gap holds). */
static ekm_implicit_coupling coupling_terms(ekm_stepper *st, const ekm_state *s, const ekm_bc_face *bb,
                                            const ekm_bc_face *bt)
{
    const ekm_scenario *sc = st->sc;
    const int n = s->n;
    const double *phi = st->phi_new;
    for (int j = 0; j < n; j++)
        st->dP_dphi[j] = st->dry[j] || (sc->hypo.enabled && s->solid[j])
                             ? 0.0
                             : ekm_pressure_dphi(&sc->material, phi[j], st->T_star[j]);
    /* upwind by the velocity relative to the face, as the mass update
     * (phase 2): on a stretching grid face f moves at f gap_rate / n */
    const double w_grid = st->moving ? st->gap_rate / n : 0.0;
    for (int f = 1; f < n; f++) {
        const double w_rel = s->w[f] - f * w_grid;
        st->phi_coupled[f] = w_rel > 0.0 ? phi[f - 1] : w_rel < 0.0 ? phi[f] : 0.5 * (phi[f - 1] + phi[f]);
    }
    st->phi_coupled[0] = s->w[0] > 0.0 ? bb->phi_in : phi[0];
    st->phi_coupled[n] = s->w[n] < 0.0 ? bt->phi_in : phi[n - 1];
    ekm_implicit_coupling cp = {.K = st->dP_dphi, .phi_face = st->phi_coupled};
    if (!st->moving) {
        cp.flux_bottom = s->w[0] * st->phi_coupled[0];
        cp.flux_top = s->w[n] * st->phi_coupled[n];
    }
    return cp;
}

/* Phase 5: the normal momentum solve, then the vacuum rule; 0 = reject. */
static int normal_momentum(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                           double dt)
{
    const ekm_scenario *sc = st->sc;
    const int n = s->n;
    ekm_error serr;
    for (int f = 1; f < n; f++)
        st->rhs_face[f] += dt * (st->rho_face[f] * st->g_z - (st->P[f] - st->P[f - 1]) / s->dz);
    ekm_implicit_end nb = {.follows = bb->w_follows, .value = bb->w};
    ekm_implicit_end nt = {.follows = bt->w_follows, .value = bt->w};
    ekm_implicit_coupling cp;
    const int implicit = sc->numerics.normal_coupling == EKM_COUPLING_IMPLICIT;
    if (implicit)
        cp = coupling_terms(st, s, bb, bt);
    if (ekm_implicit_normal_velocity(st->wk, n, dt, s->dz, st->rho_face, st->rhs_face, st->mu_n, st->dry_face,
                                     nb, nt, implicit ? &cp : NULL, s->w, &serr) != EKM_OK) {
        snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s: %.400s", s->t, serr.message);
        return 0;
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
    return 1;
}

/* Phase 6: the shear momentum solve (with solid cells: by face
 * coefficients, regime.h); 0 = reject. */
static int shear_momentum(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                          double dt, int n_solid)
{
    const ekm_material *m = &st->sc->material;
    const int n = s->n;
    ekm_error serr;
    ekm_implicit_end sb = {.value = bb->u_wall, .conductance = bb->wall_conductance};
    ekm_implicit_end stp = {.value = bt->u_wall, .conductance = bt->wall_conductance};
    double *rho_cell = st->qF; /* reuse: rho at cells */
    for (int j = 0; j < n; j++) {
        rho_cell[j] = m->rho_p * st->phi_new[j];
        st->rhs_cell[j] = st->rhoU[j] + dt * m->rho_p * st->phi_new[j] * st->g_x;
    }
    ekm_status shear_rc;
    if (n_solid) {
        ekm_regime_shear_faces(&st->regime, &st->flow, s, bb, bt, dt);
        shear_rc = ekm_implicit_shear_faces(st->wk, n, dt, s->dz, rho_cell, st->rhs_cell, st->regime.kface,
                                            st->regime.t0face, st->dry, bb->u_wall, bt->u_wall, s->u, &serr);
    } else {
        shear_rc = ekm_implicit_shear_velocity(st->wk, n, dt, s->dz, rho_cell, st->rhs_cell, st->eta, st->dry,
                                               sb, stp, s->u, &serr);
    }
    if (shear_rc != EKM_OK) {
        snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s: %.400s", s->t, serr.message);
        return 0;
    }
    return 1;
}

/* Phases 5-6, twice when solid cells exist: the second pass prepares the
 * rate law with ||kappa|| from the first pass's rates (a fixed-point step
 * towards backward Euler in the norm), so that a cell that starts to
 * deform within one step already deforms plastically (with the lagged
 * norm alone the first step of a sudden extension would be purely elastic
 * and overshoot the limit surface).  0 = reject. */
static int momentum(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt, double dt,
                    int n_solid)
{
    const int n = s->n;
    if (n_solid)
        memcpy(st->rhs_face0, st->rhs_face, ((size_t)n + 1) * sizeof *st->rhs_face);
    for (int pass = 0; pass < (n_solid ? 2 : 1); pass++) {
        if (pass == 1) {
            memcpy(st->rhs_face, st->rhs_face0, ((size_t)n + 1) * sizeof *st->rhs_face);
            ekm_regime_lagged_rates(&st->regime, s, bb, bt, st->dry);
            ekm_regime_properties(&st->regime, &st->flow, s, dt);
        }
        if (!normal_momentum(st, s, bb, bt, dt) || !shear_momentum(st, s, bb, bt, dt, n_solid))
            return 0;
    }
    return 1;
}

/* Phase 7: the new phi and (solid cells) stresses, then heating from the
 * new gradients with conduction and dissipation implicit (Newton); empty
 * cells lose their u, solid cells keep their T.  0 = reject. */
static int temperature(ekm_stepper *st, ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt, double dt,
                       int n_solid, int *iterations)
{
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const int n = s->n;
    ekm_error serr;
    memcpy(s->phi, st->phi_new, (size_t)n * sizeof *s->phi);
    if (n_solid)
        ekm_regime_finish(&st->regime, &st->flow, s, bb, bt);
    ekm_rates_shear(s, bb, bt, st->dry, st->u2, st->w2);
    /* The first Newton iterate: T* plus the change the last step made,
     * scaled to this dt (heating, dissipation and conduction change
     * slowly from step to step: near a steady state the guess is then
     * within Newton's tolerance and one iteration confirms it), at least
     * a tenth of T* (a step after a sudden change: Newton's safeguards
     * take it from there as from T*). */
    const double change_scale = st->dt_change > 0.0 ? dt / st->dt_change : 0.0;
    const double T_floor = sc->numerics.T_floor;
    for (int j = 0; j < n; j++) {
        st->regime.dry_T[j] = st->dry[j] || (n_solid && s->solid[j]);
        const double guess = st->T_star[j] + change_scale * st->T_change[j];
        s->T[j] = max2(max2(guess, 0.1 * st->T_star[j]), T_floor);
        if (st->dry[j]) {
            s->T[j] = 0.0;
            continue;
        }
        st->src[j] = ekm_temperature_source_coeffs_gY(m, sc->variant, s->phi[j], st->g_cell[j], st->Y_cell[j],
                                                      st->u2[j], st->w2[j]);
        ekm_implicit_vapour_heating(&st->src[j], s->phi[j], sc->numerics.phi_vacuum);
    }
    if (ekm_implicit_temperature(st->wk, n, dt, s->dz, m->rho_p, s->phi, st->rhoT, st->lambda, st->src,
                                 st->regime.dry_T, sc->numerics.phi_vacuum, sc->numerics.T_floor,
                                 sc->numerics.newton_tol, sc->numerics.newton_max, s->T, iterations,
                                 &serr) != EKM_OK) {
        snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s, dt = %.3g s: %.400s", s->t, dt,
                 serr.message);
        return 0;
    }
    for (int j = 0; j < n; j++)
        st->T_change[j] = st->regime.dry_T[j] ? 0.0 : s->T[j] - st->T_star[j];
    st->dt_change = dt;
    for (int j = 0; j < n; j++) {
        if (st->dry[j])
            s->u[j] = 0.0;
        else if (n_solid && s->solid[j])
            s->T[j] = st->regime.T_keep[j];
    }
    return 1;
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

/* A rejected step: s back to the state before it (reason in st->reject_reason). */
static ekm_status reject(ekm_stepper *st, ekm_state *s, int *accepted)
{
    ekm_state_copy_step(s, st->backup, st->moving, st->sc->hypo.enabled);
    *accepted = 0;
    return EKM_OK;
}

ekm_status ekm_step_apply(ekm_stepper *st, ekm_state *s, double dt, int *accepted, ekm_error *err)
{
    const int n = s->n;
    if (!(dt > 0.0) || !isfinite(dt))
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "%s: t = %.9g s: time step dt = %g s is not a positive finite number", st->sc->source,
                        s->t, dt);
    *accepted = 1;
    st->end_rate_valid = 0;
    ekm_state_copy_step(st->backup, s, st->moving, st->sc->hypo.enabled);

    /* 1. boundaries (and, with solid cells, their lagged rates) */
    ekm_bc_face bb, bt;
    boundaries(st, s, dt, &bb, &bt);
    const int n_solid = ekm_regime_begin(&st->regime, &st->flow, s, &bb, &bt);
    /* 2. mass */
    if (!mass_update(st, s, &bb, &bt, dt))
        return reject(st, s, accepted);
    /* 3. convection */
    convection(st, s, &bb, &bt, dt);
    if (st->moving)
        stretch_grid(st, s, &bb, &bt);
    /* 4. properties */
    properties(st, n);
    if (n_solid)
        ekm_regime_properties(&st->regime, &st->flow, s, dt);
    /* 5-6. normal and shear momentum */
    if (!momentum(st, s, &bb, &bt, dt, n_solid))
        return reject(st, s, accepted);
    /* 7. temperature */
    int iterations = 0;
    if (!temperature(st, s, &bb, &bt, dt, n_solid, &iterations))
        return reject(st, s, accepted);
    /* 8. accept */
    if (!state_finite(s)) {
        snprintf(st->reject_reason, sizeof st->reject_reason, "t = %.9g s, dt = %.3g s: non-finite state",
                 s->t, dt);
        return reject(st, s, accepted);
    }
    /* implicit coupling: the thermal relaxation limit (control.c, taken at
     * the start of the step) must hold at its end too: a step that heats a
     * cold cell (a shear start-up) is otherwise longer than the pressure's
     * relaxation time it creates (docs/model/slab.md "Implicit pressure
     * coupling") */
    int end_cell = -1;
    double end_rate = 0.0;
    const int implicit = st->sc->numerics.normal_coupling == EKM_COUPLING_IMPLICIT;
    if (implicit) {
        int cell = -1;
        const double rate = ekm_control_thermal_rate(st->sc, s, &cell);
        end_rate = rate;
        end_cell = cell;
        if (dt * rate > EKM_THERMAL_END_FACTOR * st->sc->numerics.thermal_relax_step) {
            snprintf(st->reject_reason, sizeof st->reject_reason,
                     "t = %.9g s, dt = %.3g s: the thermal relaxation rate at the end of the step, %.3g 1/s "
                     "(cell %d), exceeds %g x thermal_relax_step / dt",
                     s->t, dt, rate, cell, EKM_THERMAL_END_FACTOR);
            return reject(st, s, accepted);
        }
    }
    s->mass_in += dt * st->sc->material.rho_p * (st->F[0] - st->F[n]);
    s->t += dt;
    s->steps++;
    /* 9. regimes */
    const long switches = st->regime.to_solid + st->regime.to_flow;
    if (st->sc->hypo.enabled)
        ekm_regime_switch(&st->regime, &st->flow, s, &bb, &bt);
    st->newton_iterations = iterations;
    /* the rate of the check holds for the next step's limit unless a cell
     * switched (solid cells have none) */
    st->end_rate_valid = implicit && st->regime.to_solid + st->regime.to_flow == switches;
    st->end_rate_step = s->steps;
    st->end_rate = end_rate;
    st->end_rate_cell = end_cell;
    return EKM_OK;
}
