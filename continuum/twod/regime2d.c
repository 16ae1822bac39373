/* regime2d.c: the solid (hypoplastic) regime of the semi-implicit 2D step,
 * the 1D step's regime.c in plane strain (step2d.h, docs/model/twod.md "The
 * semi-implicit 2D step").
 *
 * State (grid2d.h): a solid cell carries sxx, syy, szz [Pa]; a corner
 * whose cells are all solid (a wall corner: its two cells) carries the
 * solid's sxz [Pa]; every other corner keeps in that slot the flow shear
 * stress of the last step, which a corner turning solid starts from.
 *
 * Per step with solid cells (n_solid > 0 on any rank):
 *   begin       the flags of the step's start; the rates of the start
 *               state (exx, ezz and the shear rate gxz: the root mean
 *               square of the corners that carry one at cells; its own at
 *               a corner, with the mean normal rates of its cells), on
 *               which the law lags its norm ||kappa||
 *   properties  hypo.h's linearly implicit step in plane strain:
 *                 cell:    sxx = Exx + Vzz exx + Vxx ezz,
 *                          szz = Ezz + Vzz ezz + Vxx exx,
 *                          syy = Eyy + Vxx (exx + ezz)
 *                 corner:  sxz = sxz^n xz_scale + Vxz gxz
 *               at phi* (a corner: the mean of its cells; on a wall phi
 *               extrapolated from the next cell as in 1D); a solid cell
 *               has no equilibrium pressure (K = 0, no P gradient) and
 *               exchanges no heat (lambda = 0; its T is kept); a dense
 *               solid cell that extends to phi_co in the step is
 *               stress-free.  The velocity system (velocity2d.c) takes
 *               these stresses as its rows' stresses; a corner beside
 *               solid and flowing cells takes the flowing cells'
 *               viscosity (ekm2d_corner_eta).  Momentum is solved twice:
 *               the second pass lags the norm on the first pass's rates.
 *   lag error   before finish, with the second pass's velocities: the
 *               largest change of a solid cell's normal stresses, relative
 *               to the largest of them, when its law's norm is taken at
 *               these rates instead of the lagged ones (the error of the
 *               lag, which the first pass's rates reduced but did not
 *               remove); step2d.c rejects a step whose error exceeds
 *               [numerics] solid_lag_tol and sizes the next one from it
 *   finish      the new stresses of the solid cells and corners
 *   switch      after an accepted step, switching.h's rules per cell,
 *               row after row upwards (switch_cells)
 */
#include "step2d_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hypo.h"
#include "switching.h"

static inline int owned_cell(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return i >= g->x0 && i < g->x0 + g->nxl && j >= g->z0 && j < g->z0 + g->nzl;
}

/* Corner (i, j) is this rank's (the last rank along x, not periodic, and
 * the top rank own the corners on the far walls). */
static inline int owned_corner(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    const PetscInt ie = g->x0 + g->nxl + (!g->periodic && g->x0 + g->nxl == g->nx);
    const PetscInt je = g->z0 + g->nzl + (g->z0 + g->nzl == g->nz);
    return i >= g->x0 && i < ie && j >= g->z0 && j < je;
}

static inline int solid_at(const ekm2d_step *st, PetscInt i, PetscInt j)
{
    return ekm2d_cell_exists(&st->g, i, j) && BOX(st, solid, i, j);
}

/* The cells beside corner (i, j) that exist (2 on a wall, 4 inside, 1 at
 * a box corner), into c; returns their number. */
static int corner_cells(const ekm2d_grid *g, PetscInt i, PetscInt j, PetscInt c[4][2])
{
    int n = 0;
    for (PetscInt b = j - 1; b <= j; b++)
        for (PetscInt a = i - 1; a <= i; a++)
            if (ekm2d_cell_exists(g, a, b)) {
                c[n][0] = a;
                c[n][1] = b;
                n++;
            }
    return n;
}

/* Point (i, j) lies in the box, or outside the domain (nothing to read). */
static inline int point_ok(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    const int in_domain = j >= 0 && j <= g->nz && (g->periodic || (i >= 0 && i <= g->nx));
    return !in_domain || ekm2d_in_box(g, i, j);
}

/* Corner (i, j) is in the domain and what its rate reads lies in the box. */
static inline int corner_ok(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return j >= 0 && j <= g->nz && (g->periodic || (i >= 0 && i <= g->nx)) && ekm2d_in_box(g, i, j) &&
           point_ok(g, i - 1, j) && point_ok(g, i, j - 1) && point_ok(g, i - 1, j - 1);
}

/* Cell (i, j) exists and its four corners are computable. */
static inline int cell_rates_ok(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return ekm2d_cell_exists(g, i, j) && corner_ok(g, i, j) && corner_ok(g, i + 1, j) &&
           corner_ok(g, i, j + 1) && corner_ok(g, i + 1, j + 1);
}

/* The plane rates of cell (i, j) for the velocities in u: exx, ezz its
 * own, gxz the root mean square of its corners that carry a shear rate. */
static ekm_hypo_plane_rate cell_rates(const ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j)
{
    const ekm2d_grid *g = &st->g;
    ekm_hypo_plane_rate r;
    r.exx = (u[j][i + 1][g->s_vx] - u[j][i][g->s_vx]) / g->dx;
    r.ezz = (u[j + 1][i][g->s_vz] - u[j][i][g->s_vz]) / g->dz;
    r.gxz = sqrt(ekm2d_cell_shear2(st, u, i, j));
    return r;
}

void ekm2d_regime_lagged_rates(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j < g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++)
            if (cell_rates_ok(g, i, j))
                BOX(st, rate_old, i, j) = cell_rates(st, u, i, j);
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j <= g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!corner_ok(g, i, j))
                continue;
            PetscInt c[4][2];
            const int n = corner_cells(g, i, j, c);
            ekm_hypo_plane_rate r = {0.0, 0.0, 0.0};
            int has, wet = 0;
            r.gxz = ekm2d_corner_rate(st, u, i, j, NULL, &has);
            for (int q = 0; q < n; q++) {
                if (!cell_rates_ok(g, c[q][0], c[q][1]) || BOX(st, dry, c[q][0], c[q][1]))
                    continue;
                const ekm_hypo_plane_rate rc = BOX(st, rate_old, c[q][0], c[q][1]);
                r.exx += rc.exx;
                r.ezz += rc.ezz;
                wet++;
            }
            if (wet) {
                r.exx /= wet;
                r.ezz /= wet;
            }
            BOX(st, rate_c_old, i, j) = r;
        }
}

int ekm2d_regime_begin(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    st->n_solid = 0;
    if (!st->sc->hypo.enabled)
        return 0;
    int count = 0;
    const double phi_dry = st->sc->numerics.phi_dry;
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j < g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!ekm2d_cell_exists(g, i, j))
                continue;
            const int solid = u[j][i][g->s_solid] > 0.5;
            BOX(st, solid, i, j) = (unsigned char)solid;
            BOX(st, dry, i, j) = u[j][i][g->s_phi] < phi_dry; /* the start's emptiness, for the rates */
            count += solid && owned_cell(g, i, j);
        }
    MPI_Allreduce(&count, &st->n_solid, 1, MPI_INT, MPI_SUM, g->comm);
    if (st->n_solid)
        ekm2d_regime_lagged_rates(st, u);
    return st->n_solid;
}

/* Corner (i, j) carries the solid's shear stress this step: it carries a
 * shear stress, and its cells are solid and wet. */
static int corner_solid(const ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j)
{
    PetscInt c[4][2];
    const int n = corner_cells(&st->g, i, j, c);
    if (n < 2)
        return 0;
    for (int q = 0; q < n; q++)
        if (!solid_at(st, c[q][0], c[q][1]) || BOX(st, dry, c[q][0], c[q][1]))
            return 0;
    int has;
    (void)ekm2d_corner_rate(st, u, i, j, NULL, &has);
    return has;
}

void ekm2d_regime_properties(ekm2d_step *st, PetscScalar ***u, double dt)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    memset(st->solid_c, 0, ekm2d_grid_box_size(g));
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j < g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!solid_at(st, i, j) || !cell_rates_ok(g, i, j) || BOX(st, dry, i, j))
                continue;
            const double phi_new = BOX(st, phi_new, i, j), phi_old = u[j][i][g->s_phi];
            const ekm_hypo_stress sig = {u[j][i][g->s_sxx], u[j][i][g->s_syy], u[j][i][g->s_szz], 0.0};
            ekm_hypo_implicit c = ekm_hypo_prepare_plane(m, sc->variant, ekm_scenario_law_phi(sc, phi_new),
                                                         dt, &sig, &BOX(st, rate_old, i, j));
            /* a dense cell that extends to phi_co within the step: its limit
             * surface shrinks to the point sigma = 0 (regime.c) */
            if (phi_new <= m->phi_co + sc->hypo.phi_margin && phi_old > m->phi_co + sc->hypo.phi_margin)
                c = (ekm_hypo_implicit){.xz_scale = 0.0};
            BOX(st, hyp, i, j) = c;
            const double T = u[j][i][g->s_T];
            BOX(st, T_keep, i, j) = T;
            BOX(st, T_star, i, j) = T;
            ekm_cell_properties p = ekm_cell_properties_at(m, sc->variant, phi_new, T);
            p.lambda = 0.0; /* no heat exchange */
            p.P = 0.0;      /* its normal stresses are the law's (velocity2d.c) */
            BOX(st, prop, i, j) = p;
            BOX(st, K, i, j) = 0.0;
        }
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j <= g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!corner_ok(g, i, j))
                continue;
            PetscInt c[4][2];
            const int n = corner_cells(g, i, j, c);
            int ok = n >= 2;
            for (int q = 0; q < n && ok; q++)
                ok = cell_rates_ok(g, c[q][0], c[q][1]);
            if ((j == 0 || j == g->nz) && g->nz > 1)
                for (int q = 0; q < n && ok; q++)
                    ok = ekm2d_in_box(g, c[q][0], j == 0 ? 1 : g->nz - 2);
            const int solid = ok && corner_solid(st, u, i, j);
            BOX(st, solid_c, i, j) = (unsigned char)solid;
            if (!solid)
                continue;
            double phi_c = 0.0;
            int stress_free = 0;
            for (int q = 0; q < n; q++) {
                phi_c += BOX(st, phi_new, c[q][0], c[q][1]);
                stress_free |= BOX(st, hyp, c[q][0], c[q][1]).xz_scale == 0.0;
            }
            phi_c /= n;
            /* a wall corner: phi (so P_Y) extrapolated from the next cell
             * inwards, as the stress it carries is (regime.c) */
            const int bottom = j == 0, top = j == g->nz;
            if ((bottom || top) && g->nz > 1) {
                const PetscInt jn = bottom ? 1 : g->nz - 2;
                double inner = 0.0;
                int wet = 1;
                for (int q = 0; q < n; q++) {
                    wet &= !BOX(st, dry, c[q][0], jn);
                    inner += BOX(st, phi_new, c[q][0], jn);
                }
                inner /= n;
                if (wet)
                    phi_c = fmax(fmin(1.5 * phi_c - 0.5 * inner, 0.5 * (phi_c + m->phi_cp)), 0.5 * phi_c);
            }
            const ekm_hypo_stress none = {0};
            ekm_hypo_implicit h = ekm_hypo_prepare_plane(m, sc->variant, ekm_scenario_law_phi(sc, phi_c), dt,
                                                         &none, &BOX(st, rate_c_old, i, j));
            if (stress_free)
                h.xz_scale = h.Vxz = 0.0;
            BOX(st, hyp_c, i, j) = h;
            BOX(st, t0_c, i, j) = u[j][i][g->s_sxz] * h.xz_scale;
        }
}

double ekm2d_regime_lag_error(const ekm2d_step *st, PetscScalar ***u, double dt)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    double worst = 0.0;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            if (!solid_at(st, i, j) || !cell_rates_ok(g, i, j) || BOX(st, dry, i, j))
                continue;
            const ekm_hypo_implicit *lagged = &BOX(st, hyp, i, j);
            if (lagged->xz_scale == 0.0) /* stress-free this step (properties) */
                continue;
            const ekm_hypo_plane_rate r = cell_rates(st, u, i, j);
            const ekm_hypo_stress sig = {u[j][i][g->s_sxx], u[j][i][g->s_syy], u[j][i][g->s_szz], 0.0};
            const ekm_hypo_implicit own = ekm_hypo_prepare_plane(
                &sc->material, sc->variant, ekm_scenario_law_phi(sc, BOX(st, phi_new, i, j)), dt, &sig, &r);
            const ekm_hypo_stress a = ekm_hypo_finish_plane(lagged, 0.0, &r),
                                  b = ekm_hypo_finish_plane(&own, 0.0, &r);
            const double scale = fmax(fmax(fmax(fabs(a.xx), fabs(a.yy)), fabs(a.zz)),
                                      fmax(fmax(fabs(b.xx), fabs(b.yy)), fabs(b.zz)));
            if (!(scale > 0.0))
                continue;
            const double diff = fmax(fmax(fabs(a.xx - b.xx), fabs(a.yy - b.yy)), fabs(a.zz - b.zz));
            worst = fmax(worst, diff / scale);
        }
    return worst;
}

void ekm2d_regime_finish(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            if (!BOX(st, solid, i, j) || BOX(st, dry, i, j))
                continue;
            const ekm_hypo_plane_rate r = {(u[j][i + 1][g->s_vx] - u[j][i][g->s_vx]) / g->dx,
                                           (u[j + 1][i][g->s_vz] - u[j][i][g->s_vz]) / g->dz, 0.0};
            const ekm_hypo_stress s = ekm_hypo_finish_plane(&BOX(st, hyp, i, j), 0.0, &r);
            u[j][i][g->s_sxx] = s.xx;
            u[j][i][g->s_syy] = s.yy;
            u[j][i][g->s_szz] = s.zz;
        }
    for (PetscInt j = g->z0; j <= g->nz && j < g->z0 + g->nzl + 1; j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl + 1; i++) {
            if (!owned_corner(g, i, j) || !BOX(st, solid_c, i, j))
                continue;
            int has;
            const double rate = ekm2d_corner_rate(st, u, i, j, NULL, &has);
            u[j][i][g->s_sxz] = BOX(st, t0_c, i, j) + BOX(st, hyp_c, i, j).Vxz * rate;
        }
}

void ekm2d_regime_vacuum(ekm2d_step *st, PetscScalar ***u)
{
    /* A z-face whose upwind cell is empty (phi* < max(phi_vacuum,
     * phi_dry)) carries almost no mass, and vacuum cannot push: it may not
     * compress the material cell next to it (step.c's rule, along z, the
     * faces of each column in order). */
    const ekm2d_grid *g = &st->g;
    if (!st->sc->hypo.enabled && !(st->sc->numerics.phi_vacuum > 0.0))
        return;
    const double vac = fmax(st->sc->numerics.phi_vacuum, st->sc->numerics.phi_dry);
    const PetscInt vz = g->s_vz;
    for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
        if (!ekm2d_cell_exists(g, i, 0))
            continue;
        const PetscInt jlo = g->gz0 > 1 ? g->gz0 : 1, jhi = g->gz0 + g->gnz - 1;
        for (PetscInt j = jlo; j < jhi && j < g->nz; j++) {
            if (!ekm2d_in_box(g, i, j - 1) || !ekm2d_in_box(g, i, j))
                continue;
            const double below = BOX(st, phi_new, i, j - 1), above = BOX(st, phi_new, i, j);
            if (above < vac && below >= vac && u[j][i][vz] < u[j - 1][i][vz])
                u[j][i][vz] = u[j - 1][i][vz];
            else if (below < vac && above >= vac && u[j][i][vz] > u[j + 1][i][vz])
                u[j][i][vz] = u[j + 1][i][vz];
        }
    }
}

/* ---- switching ------------------------------------------------------------------------------------ */

/* The T the quasi-static balance of cell (i, j)'s rates gives at phi. */
static double quasi_static_T(const ekm2d_step *st, double phi, const ekm_hypo_plane_rate *r)
{
    const ekm_material *m = &st->sc->material;
    const ekm_source_coeffs src =
        ekm_temperature_source_coeffs_plane(m, st->sc->variant, phi, ekm_g(m, phi),
                                            ekm_yield_temperature(m, phi), r->gxz * r->gxz, r->exx, r->ezz);
    return fmax(ekm_source_balance(&src), st->sc->numerics.T_floor);
}

/* The flow shear stress of corner (i, j) at the state u (eta_new: the
 * cells' viscosities at the state) with cell (oi, oj) taken as flowing
 * with viscosity o_eta (oi = -1: none); 0 where the corner carries none. */
static double corner_flow_stress(const ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j, PetscInt oi,
                                 PetscInt oj, double o_eta)
{
    int has;
    const double rate = ekm2d_corner_rate(st, u, i, j, NULL, &has);
    return has ? ekm2d_corner_eta(st, i, j, st->eta_new, oi, oj, o_eta) * rate : 0.0;
}

/* What the switch decides for one cell. */
typedef struct {
    int to;            /* -1: stays, 0: turns to flow, 1: turns solid */
    double T;          /* its T afterwards [m^2/s^2] */
    double xx, yy, zz; /* turning solid: its initial stress [Pa] */
} verdict_of;

/* The decision for owned cell (i, j) of the state u (rates of its
 * velocities; the flags and viscosities of the box as they stand). */
static verdict_of decide(ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    const ekm_hypo_params *h = &sc->hypo;
    PetscScalar *v = u[j][i];
    verdict_of out = {.to = -1, .T = v[g->s_T]};
    const double phi = v[g->s_phi];
    const int loose = ekm_switch_loose(m, h, phi);
    const int wet = !BOX(st, dry, i, j);
    const ekm_hypo_plane_rate r = cell_rates(st, u, i, j);
    const ekm_switch_rates sr = ekm_switch_rates_of(h, r.exx, r.ezz, r.gxz);
    const double rate_before = v[g->s_rate];
    v[g->s_rate] = sr.rate;
    const int below_solid = j > 0 && BOX(st, solid, i, j - 1);
    const double Y =
        ekm_switch_yield_temperature(m, loose, phi, below_solid, below_solid ? u[j - 1][i][g->s_phi] : 0.0);
    const double xz = 0.25 * (BOX(st, sxz_c, i, j) + BOX(st, sxz_c, i + 1, j) + BOX(st, sxz_c, i, j + 1) +
                              BOX(st, sxz_c, i + 1, j + 1));
    const PetscInt cn[4][2] = {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}};
    if (BOX(st, solid, i, j)) {
        const ekm_hypo_stress sig = {v[g->s_sxx], v[g->s_syy], v[g->s_szz], xz};
        const double fY = loose ? NAN : ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &sig);
        const double T_qs = wet ? quasi_static_T(st, phi, &r) : sc->numerics.T_floor;
        const ekm_switch_verdict verdict = ekm_switch_to_flow(h, wet, loose, Y, sig.zz, fY, &sr);
        int go = verdict == EKM_SWITCH_GO;
        if (verdict == EKM_SWITCH_CHECK) {
            /* the flow stress at T_qs (sigma_zz and sigma_xz, as in 1D) */
            const ekm_cell_properties p = ekm_cell_properties_at(m, sc->variant, phi, T_qs);
            const ekm_plane_stress e = ekm_stress_plane(&p, sc->variant, r.exx, r.ezz);
            double e_xz = 0.0;
            for (int q = 0; q < 4; q++)
                e_xz += corner_flow_stress(st, u, cn[q][0], cn[q][1], i, j, p.eta);
            e_xz *= 0.25;
            const double jump =
                fmax(fabs(e.szz - sig.zz), fabs(e_xz - sig.xz)) / fmax(fabs(sig.zz), fabs(sig.xz));
            go = ekm_switch_jump_passes(h, jump);
        }
        if (!go)
            return out;
        out.to = 0;
        if (wet && h->carry_over)
            out.T = ekm_switch_flow_temperature(m, sc->variant, loose, phi, r.ezz, sig.zz, T_qs,
                                                sc->numerics.T_floor);
        if (h->log)
            fprintf(stderr,
                    "ekm: t = %.9g s: cell (%d, %d) solid -> flow: phi %.6f, f_Y %.3e, sigma_zz %.6g Pa, "
                    "T := %.3e\n",
                    st->t, (int)i, (int)j, phi, fY, sig.zz, out.T);
        return out;
    }
    const ekm_switch_verdict verdict =
        ekm_switch_to_solid(h, wet, loose, Y, v[g->s_T], phi, &sr, rate_before);
    if (verdict == EKM_SWITCH_STAY)
        return out;
    const ekm_cell_properties p = ekm_cell_properties_at(m, sc->variant, phi, v[g->s_T]);
    const ekm_plane_stress e = ekm_stress_plane(&p, sc->variant, r.exx, r.ezz);
    ekm_hypo_stress sig = {e.sxx, e.syy, e.szz, xz};
    if (verdict == EKM_SWITCH_CHECK &&
        !ekm_switch_inside_passes(h, ekm_hypo_yield(m, sc->variant, ekm_scenario_law_phi(sc, phi), &sig)))
        return out;
    if (!h->carry_over) /* tests only (scenario.h) */
        sig.xx = sig.yy = sig.zz = -ekm_pressure_yield(m, phi);
    out.to = 1;
    out.xx = sig.xx;
    out.yy = sig.yy;
    out.zz = sig.zz;
    if (h->log)
        fprintf(stderr,
                "ekm: t = %.9g s: cell (%d, %d) flow -> solid%s: phi %.6f, T %.3e, sigma_zz %.6g Pa\n", st->t,
                (int)i, (int)j, loose ? " (loose, on a solid cell)" : "", phi, v[g->s_T], sig.zz);
    return out;
}

/* The switches of the owned cells, row after row upwards: a row's cells
 * are decided together, then take their new regime (and viscosity), so
 * that the rows above see the rows below switched, as the 1D solver's
 * cells do (regime.c), and neighbours within a row do not see each other
 * (a state uniform in x switches as the 1D one).  A rank's lowest row
 * sees the row below it (another rank's) as it was before the switch. */
static int switch_cells(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    verdict_of *row = malloc((size_t)g->nxl * sizeof *row);
    if (!row)
        return 1;
    for (PetscInt j = g->z0; j < g->z0 + g->nzl; j++) {
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++)
            row[i - g->x0] = decide(st, u, i, j);
        for (PetscInt i = g->x0; i < g->x0 + g->nxl; i++) {
            const verdict_of *d = &row[i - g->x0];
            if (d->to < 0)
                continue;
            PetscScalar *v = u[j][i];
            v[g->s_solid] = d->to;
            BOX(st, solid, i, j) = (unsigned char)d->to;
            if (d->to == 1) {
                v[g->s_sxx] = d->xx;
                v[g->s_syy] = d->yy;
                v[g->s_szz] = d->zz;
                st->to_solid++;
            } else {
                v[g->s_T] = d->T;
                if (!BOX(st, dry, i, j))
                    BOX(st, eta_new, i, j) =
                        ekm_transport_coefficients(&sc->material, sc->variant, v[g->s_phi], d->T).eta;
                st->to_flow++;
            }
        }
    }
    free(row);
    return 0;
}

static PetscErrorCode switch_all(ekm2d_step *st)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    PetscScalar ***u;
    PetscCall(DMGlobalToLocal(g->dm, st->U, INSERT_VALUES, st->Ul));
    PetscCall(DMStagVecGetArray(g->dm, st->Ul, &u));
    /* the viscosities at the new state; the emptiness of the new phi */
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j < g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!ekm2d_cell_exists(g, i, j))
                continue;
            const double phi = u[j][i][g->s_phi];
            const int dry = phi < sc->numerics.phi_dry;
            BOX(st, dry, i, j) = (unsigned char)dry;
            BOX(st, eta_new, i, j) =
                dry ? 0.0 : ekm_transport_coefficients(&sc->material, sc->variant, phi, u[j][i][g->s_T]).eta;
        }
    /* every corner's shear stress: the solid's, or the flow's (stored,
     * for a corner that turns solid) */
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz && j <= g->nz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!corner_ok(g, i, j))
                continue;
            double s = u[j][i][g->s_sxz];
            if (!BOX(st, solid_c, i, j)) {
                s = corner_flow_stress(st, u, i, j, -1, -1, 0.0);
                if (owned_corner(g, i, j))
                    u[j][i][g->s_sxz] = s;
            }
            BOX(st, sxz_c, i, j) = s;
        }
    const int fail = switch_cells(st, u);
    PetscCall(DMStagVecRestoreArray(g->dm, st->Ul, &u));
    if (fail)
        return PETSC_ERR_MEM; /* switch_cells' row buffer */
    PetscCall(DMLocalToGlobal(g->dm, st->Ul, INSERT_VALUES, st->U));
    return 0;
}

ekm_status ekm2d_regime_switch(ekm2d_step *st, ekm_error *err)
{
    if (!st->sc->hypo.enabled)
        return EKM_OK;
    if (st->n_solid == 0) /* the solid_c flags of a step without solid cells */
        for (size_t k = 0; k < ekm2d_grid_box_size(&st->g); k++)
            st->solid_c[k] = 0;
    const PetscErrorCode pe = switch_all(st);
    if (pe == PETSC_ERR_MEM)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D step, switching regimes)");
    if (pe)
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error switching regimes");
    return EKM_OK;
}
