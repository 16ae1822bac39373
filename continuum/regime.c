#include "regime.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fields.h"
#include "rates.h"
#include "hypo.h"
#include "switching.h"

/* The rates the solid step lags its norm ||kappa|| on: u'^2 and w' at
 * cells, u' at faces. */
void ekm_regime_lagged_rates(ekm_regime_work *rw, const ekm_state *s, const ekm_bc_face *bb,
                             const ekm_bc_face *bt, const unsigned char *dry)
{
    const int n = s->n;
    ekm_rates_shear(s, bb, bt, dry, rw->u2_old, rw->T_keep /* scratch */);
    for (int j = 0; j < n; j++)
        rw->dw_old[j] = (s->w[j + 1] - s->w[j]) / s->dz;
    rw->du_face_old[0] = (s->u[0] - bb->u_wall) * bb->wall_conductance;
    rw->du_face_old[n] = (bt->u_wall - s->u[n - 1]) * bt->wall_conductance;
    for (int f = 1; f < n; f++)
        rw->du_face_old[f] = (s->u[f] - s->u[f - 1]) / s->dz;
}

/* Before the step: the old state's rates (lagged ||kappa||) and which faces
 * carry a rate-law shear stress.  Returns the number of solid cells. */
int ekm_regime_begin(ekm_regime_work *rw, const ekm_regime_flow *fl, const ekm_state *s,
                     const ekm_bc_face *bb, const ekm_bc_face *bt)
{
    const int n = s->n;
    int count = 0;
    if (!fl->sc->hypo.enabled)
        return 0; /* no cell is ever solid (solid_face stays zero) */
    for (int j = 0; j < n; j++) {
        rw->dry_T[j] = s->phi[j] < fl->sc->numerics.phi_dry; /* scratch: old emptiness */
        count += s->solid[j];
    }
    if (!count) {
        memset(rw->solid_face, 0, (size_t)n + 1);
        return 0;
    }
    ekm_regime_lagged_rates(rw, s, bb, bt, rw->dry_T);
    rw->solid_face[0] = s->solid[0] && bb->wall_conductance > 0.0;
    rw->solid_face[n] = s->solid[n - 1] && bt->wall_conductance > 0.0;
    for (int f = 1; f < n; f++)
        rw->solid_face[f] = s->solid[f - 1] && s->solid[f];
    return count;
}

/* Phase 4 for solid cells: the prepared rate-law step; the normal solve
 * sees the known stress as P = -E_zz and the stiffness as mu_n = V_zz. */
void ekm_regime_properties(ekm_regime_work *rw, const ekm_regime_flow *fl, const ekm_state *s, double dt)
{
    const ekm_material *m = &fl->sc->material;
    for (int j = 0; j < s->n; j++) {
        if (!s->solid[j] || fl->dry[j])
            continue;
        const ekm_hypo_stress sig = {s->sxx[j], s->syy[j], s->szz[j], 0.0};
        rw->hyp[j] = ekm_hypo_prepare(m, fl->sc->variant, ekm_scenario_law_phi(fl->sc, fl->phi_new[j]), dt,
                                      &sig, sqrt(rw->u2_old[j]), rw->dw_old[j]);
        /* A dense solid cell that extends to phi_co within the step: its
         * limit surface shrinks to the point sigma = 0 (P_Y -> 0), so it
         * is stress-free (it switches to flow after the step). */
        if (fl->phi_new[j] <= m->phi_co + fl->sc->hypo.phi_margin &&
            s->phi[j] > m->phi_co + fl->sc->hypo.phi_margin)
            rw->hyp[j] = (ekm_hypo_implicit){.xz_scale = 0.0};
        fl->P[j] = -rw->hyp[j].Ezz;
        fl->mu_n[j] = rw->hyp[j].Vzz;
        fl->lambda[j] = 0.0;
        fl->T_star[j] = rw->T_keep[j] = s->T[j];
        fl->eta[j] = ekm_transport_coefficients(m, fl->sc->variant, fl->phi_new[j], s->T[j]).eta;
    }
}

static int face_solid(const ekm_regime_work *rw, const ekm_regime_flow *fl, int n, int f)
{
    return rw->solid_face[f] && (f == 0 || !fl->dry[f - 1]) && (f == n || !fl->dry[f]);
}

/* Phase 6 coefficients: face stress tau_f = k_f (jump of u) + t0_f. */
void ekm_regime_shear_faces(ekm_regime_work *rw, const ekm_regime_flow *fl, const ekm_state *s,
                            const ekm_bc_face *bb, const ekm_bc_face *bt, double dt)
{
    const int n = s->n;
    const double dz = s->dz;
    for (int f = 0; f <= n; f++) {
        double k = 0.0, t0 = 0.0;
        if (face_solid(rw, fl, n, f)) {
            /* The face is the material point of sigma_xz: its rate law uses
             * the face's own rate and P_Y (mean of the two cells), not the
             * cells' (at the surface cell of a layer the face stress is twice
             * the cell's, and the cell's relaxation applied to it made the
             * face yield early and creep). */
            const int a = f > 0 ? f - 1 : 0, b = f < n ? f : n - 1;
            double phi_f = 0.5 * (fl->phi_new[a] + fl->phi_new[b]);
            /* a wall face: phi (so P_Y) extrapolated linearly from the two
             * cells next to it, as the stress it carries is */
            const int in = f == 0 ? 1 : n - 2;
            if ((f == 0 || f == n) && in >= 0 && in < n && !fl->dry[in])
                phi_f = fmax(fmin(1.5 * fl->phi_new[a] - 0.5 * fl->phi_new[in],
                                  0.5 * (fl->phi_new[a] + fl->sc->material.phi_cp)),
                             0.5 * fl->phi_new[a]);
            const ekm_hypo_stress none = {0};
            ekm_hypo_implicit c =
                ekm_hypo_prepare(&fl->sc->material, fl->sc->variant, ekm_scenario_law_phi(fl->sc, phi_f), dt,
                                 &none, rw->du_face_old[f], 0.5 * (rw->dw_old[a] + rw->dw_old[b]));
            if (rw->hyp[a].xz_scale == 0.0 || rw->hyp[b].xz_scale == 0.0)
                c.xz_scale = c.Vxz = 0.0; /* a cell extends to phi_co: stress-free (solid_properties) */
            t0 = s->sxz[f] * c.xz_scale;
            k = f == 0 ? c.Vxz * bb->wall_conductance : f == n ? c.Vxz * bt->wall_conductance : c.Vxz / dz;
        } else if (f == 0) {
            k = !fl->dry[0] ? fl->eta[0] * bb->wall_conductance : 0.0;
        } else if (f == n) {
            k = !fl->dry[n - 1] ? fl->eta[n - 1] * bt->wall_conductance : 0.0;
        } else {
            k = ekm_face_viscosity(fl->eta[f - 1], s->solid[f - 1], fl->eta[f], s->solid[f]) / dz;
        }
        rw->kface[f] = k;
        rw->t0face[f] = t0;
    }
}

/* After the solves: the new stresses of solid cells and faces. */
void ekm_regime_finish(ekm_regime_work *rw, const ekm_regime_flow *fl, ekm_state *s, const ekm_bc_face *bb,
                       const ekm_bc_face *bt)
{
    const int n = s->n;
    for (int j = 0; j < n; j++) {
        if (!s->solid[j] || fl->dry[j])
            continue;
        const ekm_hypo_stress sig = ekm_hypo_finish(&rw->hyp[j], 0.0, 0.0, (s->w[j + 1] - s->w[j]) / s->dz);
        s->sxx[j] = sig.xx;
        s->syy[j] = sig.yy;
        s->szz[j] = sig.zz;
    }
    /* Outflow ends: zero gradient of the stress too (as of phi, u, T), so
     * a solid edge cell does not act as a support for the material inside. */
    if (n > 1 && fl->sc->bottom.kind == EKM_BC_OUTFLOW && s->solid[0] && s->solid[1] && !fl->dry[1]) {
        s->sxx[0] = s->sxx[1];
        s->syy[0] = s->syy[1];
        s->szz[0] = s->szz[1];
    }
    if (n > 1 && fl->sc->top.kind == EKM_BC_OUTFLOW && s->solid[n - 1] && s->solid[n - 2] &&
        !fl->dry[n - 2]) {
        s->sxx[n - 1] = s->sxx[n - 2];
        s->syy[n - 1] = s->syy[n - 2];
        s->szz[n - 1] = s->szz[n - 2];
    }
    for (int f = 0; f <= n; f++) {
        if (!face_solid(rw, fl, n, f))
            continue;
        const double du = f == 0   ? s->u[0] - bb->u_wall
                          : f == n ? bt->u_wall - s->u[n - 1]
                                   : s->u[f] - s->u[f - 1];
        s->sxz[f] = rw->t0face[f] + rw->kface[f] * du;
    }
}

/* The shear stress cell j would have as a flowing cell with viscosity
 * eta_j: the mean of its two face stresses of the flow law (as the output,
 * fields.h, and the shear solve: next to a solid cell the face takes eta_j,
 * next to a flowing one the harmonic mean, fl->eta of the neighbours). */
static double flow_cell_shear(const ekm_regime_flow *fl, const ekm_state *s, const ekm_bc_face *bb,
                              const ekm_bc_face *bt, int j, double eta_j)
{
    const int n = s->n;
    double below = 0.0, above = 0.0;
    if (j == 0)
        below = eta_j * (s->u[0] - bb->u_wall) * bb->wall_conductance;
    else
        below =
            ekm_face_viscosity(fl->eta[j - 1], s->solid[j - 1], eta_j, 0) * (s->u[j] - s->u[j - 1]) / s->dz;
    if (j == n - 1)
        above = eta_j * (bt->u_wall - s->u[n - 1]) * bt->wall_conductance;
    else
        above =
            ekm_face_viscosity(eta_j, 0, fl->eta[j + 1], s->solid[j + 1]) * (s->u[j + 1] - s->u[j]) / s->dz;
    return 0.5 * (below + above);
}

/* Phase 9: the flow face stresses (the solid's initial face stress when a
 * face turns solid) and the per-cell switches (regime.h). */
void ekm_regime_switch(ekm_regime_work *rw, const ekm_regime_flow *fl, ekm_state *s, const ekm_bc_face *bb,
                       const ekm_bc_face *bt)
{
    const ekm_scenario *sc = fl->sc;
    const ekm_material *m = &sc->material;
    const ekm_hypo_params *h = &sc->hypo;
    const int n = s->n;
    double *eta = fl->eta;
    for (int j = 0; j < n; j++)
        eta[j] = fl->dry[j] ? 0.0 : ekm_transport_coefficients(m, sc->variant, s->phi[j], s->T[j]).eta;
    for (int f = 0; f <= n; f++) {
        if (face_solid(rw, fl, n, f) && (f == 0 || s->solid[f - 1]) && (f == n || s->solid[f]))
            continue;
        if (f == 0)
            s->sxz[0] = !fl->dry[0] ? eta[0] * bb->wall_conductance * (s->u[0] - bb->u_wall) : 0.0;
        else if (f == n)
            s->sxz[n] =
                !fl->dry[n - 1] ? eta[n - 1] * bt->wall_conductance * (bt->u_wall - s->u[n - 1]) : 0.0;
        else
            s->sxz[f] = ekm_face_viscosity(eta[f - 1], s->solid[f - 1], eta[f], s->solid[f]) *
                        (s->u[f] - s->u[f - 1]) / s->dz;
    }
    for (int j = 0; j < n; j++) {
        const double phi = s->phi[j];
        const double dw = (s->w[j + 1] - s->w[j]) / s->dz;
        const double du_abs = sqrt(fl->u2[j]);
        const ekm_switch_rates r = ekm_switch_rates_of(h, 0.0, dw, du_abs);
        const double rate_before = s->rate_prev[j];
        s->rate_prev[j] = r.rate;
        const double PY = ekm_pressure_yield(m, phi);
        const int loose = ekm_switch_loose(m, h, phi);
        const double Y = ekm_switch_yield_temperature(m, loose, phi, j > 0 && s->solid[j - 1],
                                                      j > 0 ? s->phi[j - 1] : 0.0);
        if (s->solid[j]) {
            const ekm_hypo_stress sig = {s->sxx[j], s->syy[j], s->szz[j], 0.5 * (s->sxz[j] + s->sxz[j + 1])};
            const double fY =
                loose ? NAN : ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &sig);
            /* quasi-static T of the current rates and the flow stress there */
            const double T =
                fl->dry[j] ? 0.0
                           : fmax(ekm_temperature_local_balance(m, sc->variant, phi, fl->u2[j], dw * dw),
                                  sc->numerics.T_floor);
            double jump = 0.0;
            const ekm_switch_verdict verdict = ekm_switch_to_flow(h, !fl->dry[j], loose, Y, sig.zz, fY, &r);
            const char *why = fl->dry[j] ? "empty" : loose ? "loose cell unloaded" : "limit surface";
            int go = verdict == EKM_SWITCH_GO;
            if (verdict == EKM_SWITCH_CHECK) {
                ekm_hypo_stress e = ekm_hypo_from_flow(m, sc->variant, phi, T, 0.0, dw);
                e.xz =
                    flow_cell_shear(fl, s, bb, bt, j, ekm_transport_coefficients(m, sc->variant, phi, T).eta);
                jump = fmax(fabs(e.zz - sig.zz), fabs(e.xz - sig.xz)) / fmax(fabs(sig.zz), fabs(sig.xz));
                go = ekm_switch_jump_passes(h, jump);
            }
            if (!go)
                continue;
            if (!fl->dry[j]) {
                if (h->carry_over) {
                    /* no limit surface below phi_co: T from stress continuity */
                    s->T[j] = ekm_switch_flow_temperature(m, sc->variant, loose, phi, dw, sig.zz, T,
                                                          sc->numerics.T_floor);
                    eta[j] = ekm_transport_coefficients(m, sc->variant, phi, s->T[j]).eta;
                }
                if (!loose) {
                    rw->jump_max = fmax(rw->jump_max, jump);
                    if (rw->fail_time < 0.0) {
                        rw->fail_time = s->t;
                        rw->fail_angle = ekm_scenario_angle_at(sc, s->t);
                        rw->fail_fY = fY;
                        rw->fail_cell = j;
                        rw->fail_phi = ekm_scenario_law_phi(sc, phi); /* the phi of fY */
                        rw->fail_stress = sig;
                    }
                }
            }
            s->solid[j] = 0;
            rw->to_flow++;
            if (h->log)
                fprintf(stderr,
                        "ekm: t = %.9g s: cell %d (z = %.6g m) solid -> flow (%s): phi %.6f, f_Y %.3e, "
                        "w' %.3e, |u'| %.3e 1/s, sigma_zz %.6g Pa, sigma_xz %.6g Pa, T := %.3e, jump %.2e\n",
                        s->t, j, s->z[j], why, phi, fY, dw, du_abs, sig.zz, sig.xz, s->T[j], jump);
        } else {
            const ekm_switch_verdict verdict =
                ekm_switch_to_solid(h, !fl->dry[j], loose, Y, s->T[j], phi, &r, rate_before);
            if (verdict == EKM_SWITCH_STAY)
                continue;
            ekm_hypo_stress e = ekm_hypo_from_flow(m, sc->variant, phi, s->T[j], 0.0, dw);
            if (verdict == EKM_SWITCH_CHECK) {
                e.xz = 0.5 * (s->sxz[j] + s->sxz[j + 1]);
                if (!ekm_switch_inside_passes(
                        h, ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &e)))
                    continue;
            }
            if (!h->carry_over) /* tests only (scenario.h) */
                e.xx = e.yy = e.zz = -PY;
            s->sxx[j] = e.xx;
            s->syy[j] = e.yy;
            s->szz[j] = e.zz;
            s->solid[j] = 1;
            rw->to_solid++;
            if (h->log)
                fprintf(stderr,
                        "ekm: t = %.9g s: cell %d (z = %.6g m) flow -> solid%s: phi %.6f, T %.3e, w' %.3e, "
                        "|u'| %.3e 1/s, sigma_zz %.6g Pa, jump 0\n",
                        s->t, j, s->z[j], loose ? " (loose, on a solid cell)" : "", phi, s->T[j], dw, du_abs,
                        e.zz);
        }
    }
}

ekm_status ekm_regime_alloc(ekm_regime_work *rw, int n, ekm_error *err)
{
    const size_t c = (size_t)n, f = (size_t)n + 1;
    *rw = (ekm_regime_work){0};
    rw->hyp = calloc(c, sizeof *rw->hyp);
    rw->u2_old = calloc(c, sizeof(double));
    rw->dw_old = calloc(c, sizeof(double));
    rw->du_face_old = calloc(f, sizeof(double));
    rw->kface = calloc(f, sizeof(double));
    rw->t0face = calloc(f, sizeof(double));
    rw->solid_face = calloc(f, 1);
    rw->dry_T = calloc(c, 1);
    rw->T_keep = calloc(c, sizeof(double));
    rw->fail_time = -1.0;
    rw->fail_cell = -1;
    if (!rw->hyp || !rw->u2_old || !rw->dw_old || !rw->du_face_old || !rw->kface || !rw->t0face ||
        !rw->solid_face || !rw->dry_T || !rw->T_keep) {
        ekm_regime_free(rw);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the solid regime (%d cells)", n);
    }
    return EKM_OK;
}

void ekm_regime_free(ekm_regime_work *rw)
{
    free(rw->hyp);
    free(rw->u2_old);
    free(rw->dw_old);
    free(rw->du_face_old);
    free(rw->kface);
    free(rw->t0face);
    free(rw->solid_face);
    free(rw->dry_T);
    free(rw->T_keep);
    *rw = (ekm_regime_work){0};
}
