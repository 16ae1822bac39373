#include "local_slab.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "boundary.h"
#include "closure.h"
#include "implicit.h"
#include "progress.h"
#include "slab_takes.h"
#include "steady_stop.h"

/* Newton's line search: at most this many halvings of the update. */
#define LINE_SEARCH_MAX 12
/* The step's accuracy limit: it may change u by at most this fraction of
 * max|u| plus U_FLOOR (else it is rejected and halved). */
#define STEP_CHANGE_MAX 0.1
#define U_FLOOR         1e-3 /* [m/s] */
/* The first step (and the cap of the first one after the start) [s]. */
#define DT_FIRST 1e-4
/* The steady solve: continuation steps before giving up, the
 * verification's steps and its tolerance. */
#define STEADY_MAX_STEPS  400
#define STEADY_VERIFY     10
#define STEADY_VERIFY_TOL 1e-6
/* Newton's velocity tolerance floor: newton_tol times max(max|u|, this) [m/s]. */
#define U_SCALE_FLOOR 1e-3

struct ekm_local_slab {
    const ekm_scenario *sc;
    const ekm_closure *c;
    int n;           /* cells of the output (sc->cells) */
    int nm;          /* material cells, bottom up */
    int top_wall;    /* 1: a wall held at P_top; 0: a free surface */
    double dm;       /* mass per area of a material cell [kg/m^2] */
    double rho_p;    /* [kg/m^3] */
    double g_x;      /* gravity along the slab [m/s^2] */
    double g_n;      /* gravity into the bed, -g_z >= 0 [m/s^2] */
    double P_top;    /* pressure on the top of the layer [Pa] */
    double gdot_min; /* [1/s] */
    double *h;       /* thickness of each material cell [m], nm */
    double *delta;   /* distance across each face [m], nm + 1 */
    double *gd;      /* du/dz at each face [1/s], nm + 1 */
    double *tau;     /* shear stress at each face [Pa], nm + 1 */
    double *dtau;    /* dtau/dgdot [Pa s], nm + 1 */
    double *u_old;   /* u at the step's start [m/s], nm */
    double *u_try;   /* the line search's trial [m/s], nm */
    double *res;     /* residual [kg/(m s^2)... per area: Pa], nm */
    double *du;      /* Newton update [m/s], nm + 1 */
    double *phi;     /* the iterate's phi [-], nm */
    ekm_implicit_work *wk;
    int beyond_max;        /* most cells held at the dilatancy law's bound, any accepted step */
    int newton_iterations; /* of the last step */
    char reject_reason[sizeof(((ekm_error *)0)->message) + 64];
};

int ekm_local_slab_applies(const ekm_scenario *sc)
{
    return sc->closure->local_stress != NULL && sc->closure->local_phi != NULL;
}

/* Material cells of sc: cells times the filled fraction of the domain
 * (at least 2). */
static int material_cells(const ekm_scenario *sc)
{
    const double filled = fmin(sc->layer_height, sc->length) / sc->length;
    const int nm = (int)lround(filled * sc->cells);
    return nm < 2 ? 2 : (nm > sc->cells ? sc->cells : nm);
}

ekm_status ekm_local_slab_check(const ekm_scenario *sc, ekm_error *err)
{
    if (!ekm_local_slab_applies(sc))
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: [model] closure = %s has no local rheology", sc->source,
                        sc->closure->name);
    return ekm_scenario_slab_takes(sc, err);
}

void ekm_local_slab_free(ekm_local_slab *ls)
{
    if (!ls)
        return;
    free(ls->h);
    free(ls->delta);
    free(ls->gd);
    free(ls->tau);
    free(ls->dtau);
    free(ls->u_old);
    free(ls->u_try);
    free(ls->res);
    free(ls->du);
    free(ls->phi);
    ekm_implicit_free(ls->wk);
    free(ls);
}

ekm_local_slab *ekm_local_slab_alloc(const ekm_scenario *sc, ekm_error *err)
{
    if (ekm_local_slab_check(sc, err) != EKM_OK)
        return NULL;
    ekm_local_slab *ls = calloc(1, sizeof *ls);
    if (!ls) {
        EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the slab solver");
        return NULL;
    }
    ls->sc = sc;
    ls->c = sc->closure;
    ls->n = sc->cells;
    ls->nm = material_cells(sc);
    ls->top_wall = sc->top.kind == EKM_BC_WALL;
    ls->rho_p = sc->material.rho_p;
    ls->g_x = ekm_scenario_gravity_x(sc);
    ls->g_n = -ekm_scenario_gravity_z(sc);
    ls->P_top = ls->top_wall ? sc->top.pressure : 0.0;
    ls->gdot_min = sc->numerics.gdot_min;
    const double mass = ls->rho_p * sc->phi_init * fmin(sc->layer_height, sc->length);
    ls->dm = mass / ls->nm;
    const size_t c = (size_t)ls->nm, f = c + 1;
    ls->h = calloc(c, sizeof(double));
    ls->delta = calloc(f, sizeof(double));
    ls->gd = calloc(f, sizeof(double));
    ls->tau = calloc(f, sizeof(double));
    ls->dtau = calloc(f, sizeof(double));
    ls->u_old = calloc(c, sizeof(double));
    ls->u_try = calloc(c, sizeof(double));
    ls->res = calloc(c, sizeof(double));
    ls->du = calloc(f, sizeof(double));
    ls->phi = calloc(c, sizeof(double));
    ls->wk = ekm_implicit_alloc(ls->nm);
    if (!ls->h || !ls->delta || !ls->gd || !ls->tau || !ls->dtau || !ls->u_old || !ls->u_try || !ls->res ||
        !ls->du || !ls->phi || !ls->wk) {
        ekm_local_slab_free(ls);
        EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the slab solver (%d cells)", sc->cells);
        return NULL;
    }
    return ls;
}

int ekm_local_slab_beyond_max(const ekm_local_slab *ls)
{
    return ls->beyond_max;
}

/* Pressure at face f (0 .. nm): the top's plus the weight of the nm - f
 * cells above [Pa]. */
static double face_pressure(const ekm_local_slab *ls, int f)
{
    return ls->P_top + ls->g_n * ls->dm * (ls->nm - f);
}

/* Thickness of the material (the gap under a top wall) [m]. */
static double layer_thickness(const ekm_local_slab *ls)
{
    double b = 0.0;
    for (int j = 0; j < ls->nm; j++)
        b += ls->h[j];
    return b;
}

/* The walls' tangential speeds for a layer of thickness `gap` [m/s] (bc.h:
 * a top wall with shear_rate moves at [bottom] velocity + shear_rate L). */
static double bottom_speed(const ekm_local_slab *ls)
{
    return ls->sc->bottom.velocity;
}

static double top_speed(const ekm_local_slab *ls, double gap)
{
    const ekm_bc *top = &ls->sc->top;
    return ekm_boundary_rate_wall(top) ? top->velocity + top->shear_rate * gap : top->velocity;
}

/* h from phi, then the faces' distances, shear rates and stresses for the
 * velocities u (nm). */
static void faces(ekm_local_slab *ls, const double *phi, const double *u)
{
    const int nm = ls->nm;
    for (int j = 0; j < nm; j++)
        ls->h[j] = ls->dm / (ls->rho_p * phi[j]);
    ls->delta[0] = 0.5 * ls->h[0];
    ls->gd[0] = (u[0] - bottom_speed(ls)) / ls->delta[0];
    for (int f = 1; f < nm; f++) {
        ls->delta[f] = 0.5 * (ls->h[f - 1] + ls->h[f]);
        ls->gd[f] = (u[f] - u[f - 1]) / ls->delta[f];
    }
    ls->delta[nm] = 0.5 * ls->h[nm - 1];
    ls->gd[nm] = ls->top_wall ? (top_speed(ls, layer_thickness(ls)) - u[nm - 1]) / ls->delta[nm] : 0.0;
    const int last = ls->top_wall ? nm : nm - 1; /* a free top carries no stress */
    for (int f = 0; f <= last; f++)
        ls->tau[f] = ls->c->local_stress(ls->c, &ls->sc->material, face_pressure(ls, f), ls->gd[f],
                                         ls->gdot_min, &ls->dtau[f]);
    if (!ls->top_wall)
        ls->tau[nm] = ls->dtau[nm] = 0.0;
}

/* phi of each cell from the faces' shear rates (faces() first): the mean
 * of the dilatancy law at its two faces, each at its own P and |du/dz| (a
 * free top cell: its lower face's); the number of cells held at the law's
 * bound. (The law at the cell's centre, with the mean shear rate, misses
 * the chute's uniform I by a grid-independent 4e-4 in phi next to the
 * surface, where du/dz ~ (h - z)^(1/2).) */
static int slaved_phi(const ekm_local_slab *ls, double *phi)
{
    int beyond_cells = 0, beyond_lo = 0;
    const ekm_closure *c = ls->c;
    double phi_lo = c->local_phi(c, &ls->sc->material, face_pressure(ls, 0), fabs(ls->gd[0]), &beyond_lo);
    for (int j = 0; j < ls->nm; j++) {
        const int top_free = j == ls->nm - 1 && !ls->top_wall;
        int beyond_hi = 0;
        const double phi_hi = top_free ? phi_lo
                                       : c->local_phi(c, &ls->sc->material, face_pressure(ls, j + 1),
                                                      fabs(ls->gd[j + 1]), &beyond_hi);
        phi[j] = 0.5 * (phi_lo + phi_hi);
        beyond_cells += beyond_lo || beyond_hi;
        phi_lo = phi_hi;
        beyond_lo = beyond_hi;
    }
    return beyond_cells;
}

/* The residual of backward Euler for u (faces() at u first); its max norm. */
static double residual(ekm_local_slab *ls, const double *u, double dt)
{
    double norm = 0.0;
    for (int j = 0; j < ls->nm; j++) {
        ls->res[j] = ls->dm * (u[j] - ls->u_old[j]) / dt - (ls->tau[j + 1] - ls->tau[j]) - ls->dm * ls->g_x;
        norm = fmax(norm, fabs(ls->res[j]));
    }
    return isfinite(norm) ? norm : INFINITY;
}

/* The state's grid from the material cells' h: centres, the vacuum cells
 * above a free layer spread over the rest of the domain (at least as thick
 * as the mean material cell), dz = the grid's height over the cells. */
static void write_grid(const ekm_local_slab *ls, ekm_state *s)
{
    double b = 0.0;
    for (int j = 0; j < ls->nm; j++) {
        s->z[j] = b + 0.5 * ls->h[j];
        b += ls->h[j];
    }
    const int nv = ls->n - ls->nm;
    if (nv > 0) {
        const double hv = fmax((ls->sc->length - b) / nv, b / ls->nm);
        for (int k = 0; k < nv; k++) {
            s->z[ls->nm + k] = b + (k + 0.5) * hv;
            s->phi[ls->nm + k] = 0.0;
            s->u[ls->nm + k] = 0.0;
        }
        b += nv * hv;
    }
    s->dz = b / ls->n;
    for (int f = 0; f <= ls->n; f++)
        s->w[f] = 0.0;
    for (int j = 0; j < ls->n; j++)
        s->T[j] = NAN; /* no granular temperature */
}

ekm_status ekm_local_slab_init(ekm_local_slab *ls, ekm_state *s, ekm_error *err)
{
    const ekm_scenario *sc = ls->sc;
    if (s->n != ls->n)
        return EKM_FAIL(err, EKM_EINTERNAL, "slab solver: a state of %d cells for %d", s->n, ls->n);
    /* the initial centres at phi_init; u from [initial] velocity, shear_rate there */
    const double h0 = ls->dm / (ls->rho_p * sc->phi_init);
    for (int j = 0; j < ls->nm; j++) {
        s->u[j] = sc->u_init + sc->shear_rate_init * (j + 0.5) * h0;
        ls->phi[j] = sc->phi_init;
    }
    /* phi from the dilatancy law at that u, iterated with the geometry it sets */
    for (int it = 0; it < 50; it++) {
        faces(ls, ls->phi, s->u);
        double change = 0.0;
        for (int j = 0; j < ls->nm; j++)
            s->phi[j] = ls->phi[j];
        slaved_phi(ls, ls->phi);
        for (int j = 0; j < ls->nm; j++)
            change = fmax(change, fabs(ls->phi[j] - s->phi[j]));
        if (change <= sc->numerics.newton_tol)
            break;
    }
    faces(ls, ls->phi, s->u);
    for (int j = 0; j < ls->nm; j++)
        s->phi[j] = ls->phi[j];
    write_grid(ls, s);
    s->t = 0.0;
    s->steps = 0;
    s->mass_in = 0.0;
    for (int j = 0; j < ls->n; j++)
        if (!isfinite(s->phi[j]) || !isfinite(s->u[j]))
            return EKM_FAIL(err, EKM_ENUMERIC, "%s: the slab solver's initial state is not finite in cell %d",
                            sc->source, j);
    return EKM_OK;
}

ekm_status ekm_local_slab_step(ekm_local_slab *ls, ekm_state *s, double dt, int *accepted, ekm_error *err)
{
    const int nm = ls->nm;
    const ekm_numerics *num = &ls->sc->numerics;
    *accepted = 0;
    ls->newton_iterations = 0;
    memcpy(ls->u_old, s->u, (size_t)nm * sizeof(double));
    memcpy(ls->phi, s->phi, (size_t)nm * sizeof(double));
    double *u = ls->u_try; /* the iterate */
    memcpy(u, s->u, (size_t)nm * sizeof(double));
    double u_scale = U_SCALE_FLOOR;
    for (int j = 0; j < nm; j++)
        u_scale = fmax(u_scale, fabs(u[j]));
    u_scale = fmax(
        u_scale, fmax(fabs(bottom_speed(ls)), ls->top_wall ? fabs(top_speed(ls, layer_thickness(ls))) : 0.0));
    int converged = 0, beyond_cells = 0;
    snprintf(ls->reject_reason, sizeof ls->reject_reason, "Newton did not converge in %d iterations",
             num->newton_max);
    for (int it = 0; it < num->newton_max && !converged; it++) {
        ls->newton_iterations++;
        faces(ls, ls->phi, u);
        const double r0 = residual(ls, u, dt);
        if (!isfinite(r0)) {
            snprintf(ls->reject_reason, sizeof ls->reject_reason, "the residual is not finite");
            break;
        }
        /* J du = -R: J_jj = dm/dt + c_j + c_j+1, J_j,j+1 = J_j+1,j = -c_j+1, c_f = dtau_f / delta_f */
        ekm_implicit_work *wk = ls->wk;
        for (int j = 0; j < nm; j++) {
            const double c_lo = ls->dtau[j] / ls->delta[j], c_hi = ls->dtau[j + 1] / ls->delta[j + 1];
            wk->diag[j] = ls->dm / dt + c_lo + c_hi;
            wk->sub[j] = j > 0 ? -c_lo : 0.0;
            wk->sup[j] = j < nm - 1 ? -c_hi : 0.0;
            ls->du[j] = -ls->res[j];
        }
        ekm_status st = ekm_implicit_solve(wk, nm, 1, ls->du, "slab solver: Newton update", err);
        if (st != EKM_OK) {
            snprintf(ls->reject_reason, sizeof ls->reject_reason, "%s", err->message);
            break;
        }
        /* line search on the residual's max norm, phi held */
        double lambda = 1.0, step_norm = 0.0;
        int improved = 0;
        for (int k = 0; k < LINE_SEARCH_MAX && !improved; k++, lambda *= 0.5) {
            for (int j = 0; j < nm; j++)
                s->u[j] = u[j] + lambda * ls->du[j]; /* s->u as scratch; restored below on failure */
            faces(ls, ls->phi, s->u);
            improved = residual(ls, s->u, dt) < r0 || k == LINE_SEARCH_MAX - 1;
            if (improved)
                for (int j = 0; j < nm; j++)
                    step_norm = fmax(step_norm, fabs(lambda * ls->du[j]));
        }
        memcpy(u, s->u, (size_t)nm * sizeof(double));
        /* the new phi at the new u */
        faces(ls, ls->phi, u);
        double phi_change = 0.0;
        double *phi_new = ls->res; /* scratch: the residual is recomputed next iteration */
        beyond_cells = slaved_phi(ls, phi_new);
        for (int j = 0; j < nm; j++) {
            phi_change = fmax(phi_change, fabs(phi_new[j] - ls->phi[j]));
            ls->phi[j] = phi_new[j];
        }
        converged = step_norm <= num->newton_tol * u_scale && phi_change <= num->newton_tol;
    }
    if (!converged) {
        memcpy(s->u, ls->u_old, (size_t)nm * sizeof(double));
        return EKM_OK;
    }
    /* accuracy (a time step; the steady solve has dt = infinity): the step
     * changes u by at most a tenth of max|u| + U_FLOOR */
    double change = 0.0, umax = isfinite(dt) ? 0.0 : INFINITY;
    for (int j = 0; j < nm; j++) {
        change = fmax(change, fabs(u[j] - ls->u_old[j]));
        umax = fmax(umax, fabs(u[j]));
    }
    if (!(change <= STEP_CHANGE_MAX * umax + U_FLOOR)) {
        snprintf(ls->reject_reason, sizeof ls->reject_reason,
                 "the step changes u by %.3g m/s (at most %.3g: a tenth of max|u| + %g m/s)", change,
                 STEP_CHANGE_MAX * umax + U_FLOOR, U_FLOOR);
        memcpy(s->u, ls->u_old, (size_t)nm * sizeof(double));
        return EKM_OK;
    }
    faces(ls, ls->phi, u);
    memcpy(s->u, u, (size_t)nm * sizeof(double));
    memcpy(s->phi, ls->phi, (size_t)nm * sizeof(double));
    write_grid(ls, s);
    if (isfinite(dt)) {
        s->t += dt;
        s->steps++;
    }
    if (beyond_cells > ls->beyond_max)
        ls->beyond_max = beyond_cells;
    *accepted = 1;
    return EKM_OK;
}

void ekm_slab_fields(const ekm_scenario *sc, const ekm_state *s, double t, ekm_fields *out)
{
    if (ekm_local_slab_applies(sc))
        ekm_local_slab_fields(sc, s, t, out);
    else
        ekm_fields_compute(sc, s, t, out);
}

double ekm_local_slab_mass(const ekm_scenario *sc, const ekm_state *s)
{
    double b = 0.0, mass = 0.0;
    for (int j = 0; j < s->n; j++) {
        const double h = 2.0 * (s->z[j] - b); /* the cell's thickness from its centre */
        mass += sc->material.rho_p * s->phi[j] * h;
        b += h;
    }
    return mass;
}

void ekm_local_slab_fields(const ekm_scenario *sc, const ekm_state *s, double t, ekm_fields *out)
{
    (void)t;
    const ekm_closure *c = sc->closure;
    const int n = s->n;
    const int top_wall = sc->top.kind == EKM_BC_WALL;
    const double rho_p = sc->material.rho_p;
    const double g_n = -ekm_scenario_gravity_z(sc);
    const double P_top = top_wall ? sc->top.pressure : 0.0;
    /* the cells' bounds from their centres (b_0 = 0, b_j+1 = 2 z_j - b_j) and the material cells */
    int nm = 0;
    while (nm < n && s->phi[nm] > 0.0)
        nm++;
    double gap = 0.0;
    for (int j = 0; j < nm; j++)
        gap = 2.0 * s->z[j] - gap;
    /* pressure at the cells: the weight above, from the top down */
    double above = P_top; /* P at the upper face of cell j */
    double b_hi = gap;
    for (int j = nm - 1; j >= 0; j--) {
        const double h = 2.0 * (b_hi - s->z[j]);
        const double w = g_n * rho_p * s->phi[j] * h; /* the cell's weight [Pa] */
        out->P[j] = above + 0.5 * w;
        above += w;
        b_hi -= h;
    }
    /* face stresses, one at a time: tau below and above cell j */
    const double u_bot = sc->bottom.velocity;
    const double u_top =
        ekm_boundary_rate_wall(&sc->top) ? sc->top.velocity + sc->top.shear_rate * gap : sc->top.velocity;
    double b_lo = 0.0, tau_lo = 0.0, dtau;
    for (int j = 0; j < nm; j++) {
        const double h = 2.0 * (s->z[j] - b_lo);
        const double P_lo = out->P[j] + 0.5 * g_n * rho_p * s->phi[j] * h; /* P at the lower face */
        if (j == 0)
            tau_lo = c->local_stress(c, &sc->material, P_lo, (s->u[0] - u_bot) / s->z[0],
                                     sc->numerics.gdot_min, &dtau);
        double tau_hi;
        if (j < nm - 1)
            tau_hi = c->local_stress(c, &sc->material, out->P[j] - 0.5 * g_n * rho_p * s->phi[j] * h,
                                     (s->u[j + 1] - s->u[j]) / (s->z[j + 1] - s->z[j]), sc->numerics.gdot_min,
                                     &dtau);
        else if (top_wall)
            tau_hi = c->local_stress(c, &sc->material, P_top, (u_top - s->u[j]) / (gap - s->z[j]),
                                     sc->numerics.gdot_min, &dtau);
        else
            tau_hi = 0.0;
        out->vx[j] = s->u[j];
        out->vz[j] = 0.0;
        out->sxz[j] = 0.5 * (tau_lo + tau_hi);
        out->szz[j] = -out->P[j];
        out->regime[j] = EKM_REGIME_DENSE;
        tau_lo = tau_hi;
        b_lo += h;
    }
    for (int j = nm; j < n; j++) {
        out->vx[j] = out->vz[j] = out->P[j] = out->sxz[j] = out->szz[j] = 0.0;
        out->regime[j] = EKM_REGIME_EMPTY;
    }
}

ekm_status ekm_local_slab_run(ekm_local_slab *ls, ekm_state *s, const ekm_run_hooks *hooks,
                              ekm_run_stats *stats, ekm_error *err)
{
    const ekm_scenario *sc = ls->sc;
    *stats = (ekm_run_stats){
        .dt_min_used = INFINITY, .steady_drift = NAN, .steady_time = NAN, .fail_time = -1.0, .fail_cell = -1};
    stats->mass_initial = ekm_local_slab_mass(sc, s);
    ekm_run_watch watch;
    ekm_status rc = ekm_run_watch_start(&watch, sc, s, NULL, hooks, stats, err);
    if (rc != EKM_OK)
        return rc;
    const double started = ekm_now_s();
    ekm_progress progress;
    ekm_progress_start(&progress, hooks && hooks->progress ? stderr : NULL);
    long frame = 0;
    double dt_next = fmin(DT_FIRST, sc->output_dt);
    while (!watch.is_steady && s->t < sc->t_end * (1.0 - 1e-14)) {
        const double t_next_out = fmin(sc->t_end, (frame + 1) * sc->output_dt);
        double dt = fmin(dt_next, sc->numerics.dt_max);
        const int reaches = s->t + dt >= t_next_out * (1.0 - 1e-12);
        if (reaches)
            dt = t_next_out - s->t;
        const long rejected_before = stats->rejected;
        for (;;) {
            int accepted;
            if ((rc = ekm_local_slab_step(ls, s, dt, &accepted, err)) != EKM_OK)
                goto end;
            stats->newton_iterations += ls->newton_iterations;
            if (accepted)
                break;
            stats->rejected++;
            dt *= 0.5;
            if (dt < sc->numerics.dt_min) {
                rc = EKM_FAIL(err, EKM_ENUMERIC,
                              "%s: t = %.9g s: time step fell below dt_min = %g s; last rejected step: %s",
                              sc->source, s->t, sc->numerics.dt_min, ls->reject_reason);
                goto end;
            }
        }
        stats->dt_min_used = fmin(stats->dt_min_used, dt);
        /* a step shortened to reach an output does not throttle the growth */
        if (!(reaches && stats->rejected == rejected_before))
            dt_next = 1.5 * dt;
        if ((rc = ekm_run_watch_step(&watch, sc, s, NULL, hooks, stats, t_next_out, &frame, err)) != EKM_OK)
            goto end;
        ekm_progress_update(&progress, s->t, sc->t_end, dt, s->steps, 0);
    }
    if (progress.tty)
        ekm_progress_update(&progress, s->t, sc->t_end, dt_next, s->steps, 1);
    stats->wall_s = ekm_now_s() - started;
    stats->mass_final = ekm_local_slab_mass(sc, s);
    ekm_run_watch_verdict(&watch, sc, stats);
end:
    ekm_progress_end(&progress);
    ekm_run_watch_free(&watch);
    return rc;
}

/* The largest change of u (relative to max|u| + U_FLOOR) and phi between
 * two states of nm material cells. */
static double state_change(const double *u0, const double *phi0, const ekm_state *s, int nm)
{
    double du = 0.0, umax = 0.0, dphi = 0.0;
    for (int j = 0; j < nm; j++) {
        du = fmax(du, fabs(s->u[j] - u0[j]));
        umax = fmax(umax, fabs(s->u[j]));
        dphi = fmax(dphi, fabs(s->phi[j] - phi0[j]));
    }
    return fmax(du / (umax + U_FLOOR), dphi);
}

ekm_status ekm_local_slab_steady(ekm_local_slab *ls, ekm_state *s, ekm_local_slab_steady_report *rep,
                                 ekm_error *err)
{
    const ekm_scenario *sc = ls->sc;
    const double started = ekm_now_s(), t0 = s->t;
    const long steps0 = s->steps;
    *rep = (ekm_local_slab_steady_report){0};
    double dt = fmin(DT_FIRST, sc->output_dt);
    int solved = 0;
    ekm_status st = EKM_OK;
    for (int k = 0; k < STEADY_MAX_STEPS && !solved; k++) {
        rep->attempts++;
        if ((st = ekm_local_slab_step(ls, s, INFINITY, &solved, err)) != EKM_OK)
            return st;
        if (solved)
            break;
        int accepted;
        if ((st = ekm_local_slab_step(ls, s, dt, &accepted, err)) != EKM_OK)
            return st;
        if (accepted) {
            rep->warm_steps++;
            rep->warm_time += dt;
            dt *= 2.0;
        } else if ((dt *= 0.5) < sc->numerics.dt_min) {
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: the continuation's step fell below dt_min = %g s (%s)",
                            sc->source, sc->numerics.dt_min, ls->reject_reason);
        }
    }
    if (!solved)
        return EKM_FAIL(err, EKM_ENOTSTEADY,
                        "%s: no steady state: the steady equations' Newton solve did not converge in %d "
                        "attempts over %.3g s of continuation (the last: %s)",
                        sc->source, rep->attempts, rep->warm_time, ls->reject_reason);
    /* verification: time steps from the solution must not move it */
    const int nm = ls->nm;
    double *u0 = malloc((size_t)nm * sizeof *u0), *phi0 = malloc((size_t)nm * sizeof *phi0);
    if (!u0 || !phi0) {
        free(u0);
        free(phi0);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory verifying the steady state");
    }
    memcpy(u0, s->u, (size_t)nm * sizeof *u0);
    memcpy(phi0, s->phi, (size_t)nm * sizeof *phi0);
    for (int k = 0; k < STEADY_VERIFY && st == EKM_OK; k++) {
        int accepted;
        double h = sc->output_dt;
        while ((st = ekm_local_slab_step(ls, s, h, &accepted, err)) == EKM_OK && !accepted)
            if ((h *= 0.5) < sc->numerics.dt_min) {
                st = EKM_FAIL(err, EKM_ENOTSTEADY, "%s: no steady state: a verification step failed (%s)",
                              sc->source, ls->reject_reason);
                break;
            }
        if (st == EKM_OK) {
            rep->verify_steps++;
            rep->verify_time += h;
            rep->verify_change = fmax(rep->verify_change, state_change(u0, phi0, s, nm));
        }
    }
    if (st == EKM_OK && !(rep->verify_change < STEADY_VERIFY_TOL))
        st = EKM_FAIL(
            err, EKM_ENOTSTEADY,
            "%s: no steady state: the solution moved by %.3g (more than %g) over %d time steps of %g s",
            sc->source, rep->verify_change, STEADY_VERIFY_TOL, rep->verify_steps, sc->output_dt);
    /* the solution itself is the output (the verification's last state is within the tolerance) */
    if (st == EKM_OK) {
        memcpy(s->u, u0, (size_t)nm * sizeof *u0);
        memcpy(s->phi, phi0, (size_t)nm * sizeof *phi0);
        faces(ls, s->phi, s->u);
        write_grid(ls, s);
        s->t = t0;
        s->steps = steps0;
    }
    free(u0);
    free(phi0);
    rep->wall_s = ekm_now_s() - started;
    return st;
}
