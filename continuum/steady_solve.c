#include "steady_solve.h"

#include "closure.h"

#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bc.h"
#include "control.h"
#include "homogeneous.h"
#include "model.h"
#include "progress.h"
#include "run.h"
#include "rates.h"
#include "step.h"

#define MAX_RESOLVES       60   /* new solves after the empty set changed */
#define FD_EPS             1e-8 /* relative finite-difference step of the Jacobian */
#define DELTA0             1e-4 /* first pseudo-time step [s] */
#define DELTA_MAX          1e20 /* [s]: beyond it the iteration is Newton's */
#define W_TYP              1e-4 /* velocity scale of a sealed face's w [m/s] */
#define LNT_STEP_MAX       2.0  /* largest change of ln T per iteration */
#define STEP_CHANGE_MAX    2.0  /* largest relative change of a pseudo-time step */
#define PHI_SCALE          0.2  /* phi change that counts as 1 in it [-] */
#define SEED_FRACTION      1e-2 /* of a surface cell's material given to the empty cell it pushes into [-] */
#define POLISH_FACTOR      1e-2 /* a converged residual above this times the tolerance gets one more iteration */
#define PHI_FRINGE         1e-6 /* the dilute fringe: its empty set changes are left (topology_changed) [-] */
#define STALL_ITER         8    /* a stall: this many iterations ... */
#define STALL_RES          1.01 /* ... within this factor of scaled residual ... */
#define STALL_DELTA        64.0 /* ... while the pseudo-time step grew by at least this factor; or ... */
#define STALL_NEWTON_DELTA 1e6  /* ... with every pseudo-time step above this [s] ... */
#define STALL_PROGRESS     0.9 /* ... the residual fell by less than this factor over STALL_ITER iterations */

/* Slots of the unknowns of cell j: U[j nv + slot]. */
enum { SLOT_C = 0, SLOT_U = 1, SLOT_T = 2, SLOT_DZ = 3 };

typedef struct {
    const ekm_scenario *sc;
    int n, nv, moving, N;
    int kl, ku, ldab;
    double g_x, g_z, dz0;
    double u_ref;       /* the u unknowns and the scratch state's u are u - u_ref (the top wet cell's u of the
                         * guess: a dilute tail's tiny differences keep their digits) [m/s] */
    unsigned char *dry; /* frozen empty cells, n */
    unsigned char *dry_face; /* frozen empty faces, n + 1 */
    unsigned char
        *sealed; /* faces with a wet cell below and an empty one above whose w is an unknown, n + 1 */
    unsigned char *joined;    /* faces forced into their run (a sealed w pushed upwards), n + 1 */
    unsigned char *algebraic; /* rows without pseudo-mass, N */
    int from_top;             /* 1: the cumulative phi is summed from the top (free or fixed ends), 0: from
                               * the base (a pressure wall: its pressure row needs the top cell's) */
    double *c0;               /* cumulative phi of the guess (sum_{i>=j} or sum_{i<=j} phi_i), n */
    ekm_state *s;             /* scratch state for bc.c and the shear rates */
    double *dz, *P, *eta, *mu_n, *lambda, *u2, *w2; /* n each */
    double *R, *mag, *mag1, *pmass, *R1, *U, *U1, *dU, *typ, *h, *ab;
    lapack_int *ipiv;
} ss_problem;

static double harmonic(double a, double b)
{
    return a > 0.0 && b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
}

static void problem_free(ss_problem *p)
{
    free(p->dry);
    free(p->dry_face);
    free(p->sealed);
    free(p->joined);
    free(p->algebraic);
    free(p->c0);
    ekm_state_free(p->s);
    free(p->dz);
    free(p->P);
    free(p->eta);
    free(p->mu_n);
    free(p->lambda);
    free(p->u2);
    free(p->w2);
    free(p->R);
    free(p->mag);
    free(p->R1);
    free(p->mag1);
    free(p->pmass);
    free(p->U);
    free(p->U1);
    free(p->dU);
    free(p->typ);
    free(p->h);
    free(p->ab);
    free(p->ipiv);
}

static ekm_status problem_alloc(ss_problem *p, const ekm_scenario *sc, ekm_error *err)
{
    memset(p, 0, sizeof *p);
    p->sc = sc;
    p->n = sc->cells;
    p->moving = ekm_boundary_pressure_wall(&sc->top);
    p->nv = p->moving ? 4 : 3;
    p->from_top = !p->moving;
    p->N = p->n * p->nv;
    /* rows of cell j reach cells j-2..j+2 (face rows: the w of a sealed
     * face above the next cell) */
    p->kl = p->ku = 3 * p->nv - 1;
    p->ldab = 2 * p->kl + p->ku + 1;
    p->g_x = ekm_scenario_gravity_x(sc);
    p->g_z = ekm_scenario_gravity_z(sc);
    const size_t n = (size_t)p->n, N = (size_t)p->N;
    p->dry = calloc(n, 1);
    p->dry_face = calloc(n + 1, 1);
    p->sealed = calloc(n + 1, 1);
    p->joined = calloc(n + 1, 1);
    p->algebraic = calloc(N, 1);
    p->c0 = calloc(n, sizeof(double));
    p->s = ekm_state_alloc(p->n, sc->length);
    p->dz = calloc(n, sizeof(double));
    p->P = calloc(n, sizeof(double));
    p->eta = calloc(n, sizeof(double));
    p->mu_n = calloc(n, sizeof(double));
    p->lambda = calloc(n, sizeof(double));
    p->u2 = calloc(n, sizeof(double));
    p->w2 = calloc(n, sizeof(double));
    p->R = calloc(N, sizeof(double));
    p->mag = calloc(N, sizeof(double));
    p->R1 = calloc(N, sizeof(double));
    p->mag1 = calloc(N, sizeof(double));
    p->pmass = calloc(N, sizeof(double));
    p->U = calloc(N, sizeof(double));
    p->U1 = calloc(N, sizeof(double));
    p->dU = calloc(N, sizeof(double));
    p->typ = calloc(N, sizeof(double));
    p->h = calloc(N, sizeof(double));
    p->ab = calloc((size_t)p->ldab * N, sizeof(double));
    p->ipiv = calloc(N, sizeof(lapack_int));
    if (!p->dry || !p->dry_face || !p->sealed || !p->joined || !p->algebraic || !p->c0 || !p->s || !p->dz ||
        !p->P || !p->eta || !p->mu_n || !p->lambda || !p->u2 || !p->w2 || !p->R || !p->mag || !p->mag1 ||
        !p->pmass || !p->R1 || !p->U || !p->U1 || !p->dU || !p->typ || !p->h || !p->ab || !p->ipiv) {
        problem_free(p);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the steady solver (%d cells)", sc->cells);
    }
    return EKM_OK;
}

ekm_status ekm_steady_supported(const ekm_scenario *sc, ekm_error *err)
{
    ekm_error cerr;
    if (ekm_closure_require_ekm(sc->closure, "ekm steady", &cerr) != EKM_OK)
        return EKM_FAIL(err, cerr.code, "%s: %s", sc->source, cerr.message);
    if (sc->hypo.enabled)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [hypo] enabled = 1: the solid regime's stress depends on its history, "
                        "ekm steady solves the flow regimes only (use ekm run)",
                        sc->source);
    if (sc->angle_rate != 0.0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [gravity] angle_rate = %g: a tilting base has no steady state (use ekm run)",
                        sc->source, sc->angle_rate);
    const ekm_bc *ends[2] = {&sc->bottom, &sc->top};
    const char *names[2] = {"bottom", "top"};
    for (int k = 0; k < 2; k++) {
        const ekm_bc_kind kind = ends[k]->kind;
        if (kind == EKM_BC_INFLOW || kind == EKM_BC_OUTFLOW || kind == EKM_BC_PISTON)
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [%s] type = %s: its mass changes with time, ekm steady needs wall or "
                            "free ends (use ekm run)",
                            sc->source, names[k], ekm_boundary_kind_name(kind));
    }
    if (sc->bottom.kind == EKM_BC_FREE && ekm_scenario_gravity_z(sc) < 0.0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [bottom] type = free under normal gravity: the material falls out "
                        "(no steady state)",
                        sc->source);
    return EKM_OK;
}

/* Face data at both ends and the squared rates at cell height dz (the
 * unknown w set in the scratch state). */
static void rates_at(ss_problem *p, double dz, ekm_bc_face *bb, ekm_bc_face *bt)
{
    ekm_state *s = p->s;
    s->dz = dz;
    *bb = ekm_bc_evaluate(&p->sc->bottom, EKM_SIDE_BOTTOM, 0.0, s);
    *bt = ekm_bc_evaluate(&p->sc->top, EKM_SIDE_TOP, 0.0, s);
    bb->u_wall -= p->u_ref;
    bt->u_wall -= p->u_ref;
    ekm_rates_shear(s, bb, bt, p->dry, p->u2, p->w2);
}

/* The cumulative phi the one of cell j sums on from (the next cell's; 0
 * past the end), so that phi_j = c_j - cumulative_next. */
static double cumulative_next(const ss_problem *p, const double *U, int j)
{
    const int k = p->from_top ? j + 1 : j - 1;
    return k >= 0 && k < p->n ? U[(size_t)k * p->nv + SLOT_C] : 0.0;
}

/* Unpack U into the scratch state and the properties; 0: U is outside the
 * domain (phi of a wet cell outside (0, phi_cp), phi < 0, dz <= 0, not finite). */
static int unpack(ss_problem *p, const double *U)
{
    const ekm_material *m = &p->sc->material;
    ekm_state *s = p->s;
    const int n = p->n, nv = p->nv;
    for (int j = 0; j < n; j++) {
        const double *x = U + (size_t)j * nv;
        const double phi = x[SLOT_C] - cumulative_next(p, U, j);
        p->dz[j] = p->moving ? x[SLOT_DZ] : p->dz0;
        if (!isfinite(phi) || !isfinite(x[SLOT_U]) || !isfinite(x[SLOT_T]) || !(p->dz[j] > 0.0))
            return 0;
        s->phi[j] = phi;
        if (p->dry[j]) {
            /* its phi is fixed by its mass row or (joined to a run) checked at the end */
            s->u[j] = s->T[j] = 0.0;
            p->P[j] = p->eta[j] = p->mu_n[j] = p->lambda[j] = 0.0;
            continue;
        }
        if (!(phi > 0.0 && phi < m->phi_cp))
            return 0;
        const double T = exp(x[SLOT_T]);
        if (!(T > 0.0) || !isfinite(T))
            return 0;
        s->u[j] = x[SLOT_U];
        s->T[j] = T;
        const ekm_transport c = ekm_transport_coefficients(m, p->sc->variant, phi, T);
        p->eta[j] = c.eta;
        p->mu_n[j] = c.mu_n;
        p->lambda[j] = c.lambda;
        p->P[j] = ekm_pressure_kinetic(m, phi, T) + ekm_pressure_yield(m, phi);
    }
    for (int f = 1; f < n; f++)
        s->w[f] = p->sealed[f] ? U[(size_t)f * nv + SLOT_T] : 0.0;
    s->w[0] = p->sc->bottom.kind == EKM_BC_FREE ? s->w[1] : 0.0;
    s->w[n] = p->sc->top.kind == EKM_BC_FREE ? s->w[n - 1] : 0.0;
    return 1;
}

/* The face whose normal momentum is cell j's slot-C row: the one below it
 * (summed from the top) or above it (from the base), if it is an interior
 * face with material that is not a sealed surface; 0: none, the row is
 * the mass of its run (the cumulative phi from the cell on is kept). */
static int joined_face(const ss_problem *p, int j)
{
    const int f = p->from_top ? j : j + 1;
    return f > 0 && f < p->n && !p->dry_face[f] && !p->sealed[f] ? f : 0;
}

/* The steady normal momentum of interior face f (w = 0 but on sealed faces). */
static double face_row(const ss_problem *p, int f, double dz, double *mag)
{
    const double rho_face = p->sc->material.rho_p * 0.5 * (p->s->phi[f - 1] + p->s->phi[f]);
    const double *w = p->s->w;
    const double v_above = p->mu_n[f] * (w[f + 1] - w[f]) / (dz * dz);
    const double v_below = p->mu_n[f - 1] * (w[f] - w[f - 1]) / (dz * dz);
    *mag = fabs(rho_face * p->g_z) + (fabs(p->P[f]) + fabs(p->P[f - 1])) / dz + fabs(v_above) + fabs(v_below);
    return rho_face * p->g_z - (p->P[f] - p->P[f - 1]) / dz + v_above - v_below;
}

/* R(U) and (mag != NULL) each row's sum of term magnitudes; 0: U outside
 * the domain. */
static int residual(ss_problem *p, const double *U, double *R, double *mag)
{
    if (!unpack(p, U))
        return 0;
    const ekm_scenario *sc = p->sc;
    const ekm_material *m = &sc->material;
    const int n = p->n, nv = p->nv;
    const ekm_state *s = p->s;
    double mg_local[4];
    ekm_bc_face bb, bt;
    double dz_rates = NAN;
    for (int j = 0; j < n; j++) {
        const size_t i = (size_t)j * nv;
        double *r = R + i, *mg = mag ? mag + i : mg_local;
        const double dz = p->dz[j];
        const double *x = U + i;
        if (!(dz == dz_rates)) {
            rates_at(p, dz, &bb, &bt);
            dz_rates = dz;
        }
        /* slot C: a face's normal momentum, the wall pressure or the mass
         * from this cell on */
        const int f_row = joined_face(p, j);
        if (f_row) {
            r[SLOT_C] = face_row(p, f_row, dz, &mg[SLOT_C]);
        } else if (j == n - 1 && p->moving) {
            r[SLOT_C] = p->P[j] - sc->top.pressure;
            mg[SLOT_C] = fabs(p->P[j]) + sc->top.pressure;
        } else if (p->moving) {
            r[SLOT_C] = dz * x[SLOT_C] - p->dz0 * p->c0[j];
            mg[SLOT_C] = p->dz0 * (p->c0[j] + m->phi_cp);
        } else {
            r[SLOT_C] = x[SLOT_C] - p->c0[j];
            mg[SLOT_C] = p->c0[j] + m->phi_cp;
        }
        /* slot U: the shear solve's operator with rho g_x */
        if (p->dry[j]) {
            r[SLOT_U] = x[SLOT_U];
            mg[SLOT_U] = 1.0;
        } else {
            const double e_below = j > 0 ? harmonic(p->eta[j - 1], p->eta[j]) : 0.0;
            const double e_above = j < n - 1 ? harmonic(p->eta[j], p->eta[j + 1]) : 0.0;
            const double t_above = j < n - 1 ? e_above * (s->u[j + 1] - s->u[j]) / (dz * dz) : 0.0;
            const double t_below = j > 0 ? e_below * (s->u[j] - s->u[j - 1]) / (dz * dz) : 0.0;
            double t_wall = 0.0, t_wall_mag = 0.0;
            if (j == 0 && bb.wall_conductance > 0.0) {
                t_wall += p->eta[j] * bb.wall_conductance * (bb.u_wall - s->u[j]) / dz;
                t_wall_mag += fabs(t_wall);
            }
            if (j == n - 1 && bt.wall_conductance > 0.0) {
                const double t = p->eta[j] * bt.wall_conductance * (bt.u_wall - s->u[j]) / dz;
                t_wall += t;
                t_wall_mag += fabs(t);
            }
            const double grav = m->rho_p * s->phi[j] * p->g_x;
            r[SLOT_U] = t_above - t_below + t_wall + grav;
            mg[SLOT_U] = fabs(t_above) + fabs(t_below) + t_wall_mag + fabs(grav);
        }
        /* slot T: the temperature residual, a sealed face's momentum, or a dummy */
        if (j > 0 && p->sealed[j]) {
            r[SLOT_T] = face_row(p, j, p->dz[j - 1], &mg[SLOT_T]);
        } else if (p->dry[j]) {
            r[SLOT_T] = x[SLOT_T];
            mg[SLOT_T] = 1.0;
        } else {
            const double a = 2.0 / 3.0 / (dz * dz);
            const double l_below = j > 0 ? harmonic(p->lambda[j - 1], p->lambda[j]) : 0.0;
            const double l_above = j < n - 1 ? harmonic(p->lambda[j], p->lambda[j + 1]) : 0.0;
            const double c_above = j < n - 1 ? a * l_above * (s->T[j + 1] - s->T[j]) : 0.0;
            const double c_below = j > 0 ? a * l_below * (s->T[j] - s->T[j - 1]) : 0.0;
            ekm_source_coeffs src =
                ekm_temperature_source_coeffs(m, sc->variant, s->phi[j], p->u2[j], p->w2[j]);
            double dS;
            const double S = ekm_source_eval(&src, s->T[j], &dS);
            src.k_diss = 0.0;
            const double heat = ekm_source_eval(&src, s->T[j], &dS);
            r[SLOT_T] = c_above - c_below + S;
            mg[SLOT_T] = fabs(c_above) + fabs(c_below) + fabs(heat) + fabs(heat - S);
        }
        if (p->moving) {
            if (j < n - 1) {
                r[SLOT_DZ] = x[SLOT_DZ] - U[i + nv + SLOT_DZ];
                mg[SLOT_DZ] = p->dz0;
            } else {
                r[SLOT_DZ] = dz * x[SLOT_C] - p->dz0 * p->c0[j];
                mg[SLOT_DZ] = p->dz0 * (p->c0[j] + m->phi_cp);
            }
        }
    }
    if (mag) {
        /* a row whose terms all vanish (a uniform guess) is scaled by the
         * largest of its kind */
        double top[4] = {0.0, 0.0, 0.0, 0.0};
        for (int i = 0; i < p->N; i++)
            top[i % nv] = fmax(top[i % nv], mag[i]);
        for (int i = 0; i < p->N; i++)
            mag[i] = fmax(mag[i], top[i % nv] > 0.0 ? 1e-8 * top[i % nv] : 1.0);
    }
    for (int i = 0; i < p->N; i++)
        if (!isfinite(R[i]) || (mag && !(isfinite(mag[i]) && mag[i] > 0.0)))
            return 0;
    return 1;
}

/* Freeze the empty set of the state and build the unknowns from it. */
static void classify(ss_problem *p, const ekm_state *s)
{
    const ekm_scenario *sc = p->sc;
    const int n = p->n, nv = p->nv;
    const double phi_dry = sc->numerics.phi_dry;
    p->dz0 = s->dz;
    double c = 0.0, u_scale = fmax(fabs(sc->bottom.velocity), fabs(sc->top.velocity));
    if (ekm_boundary_rate_wall(&sc->top))
        u_scale = fmax(u_scale, fabs(sc->top.velocity + sc->top.shear_rate * n * s->dz));
    for (int j = 0; j < n; j++) {
        p->dry[j] = s->phi[j] < phi_dry;
        /* the top of a dilute tail: a cell with some material above a
         * thinner one joined by a face with material is filled by the
         * stepper (it creeps up, docs/model/steady.md): it has material */
        if (p->dry[j] && j > 0 && s->phi[j] > 0.0 && !p->dry[j - 1] && s->phi[j - 1] < PHI_FRINGE &&
            0.5 * (s->phi[j - 1] + s->phi[j]) >= phi_dry)
            p->dry[j] = 0;
    }
    p->u_ref = 0.0;
    for (int k = 0; k < n; k++) {
        const int j = p->from_top ? n - 1 - k : k;
        c += s->phi[j];
        p->c0[j] = c;
        if (!p->dry[j])
            u_scale = fmax(u_scale, fabs(s->u[j]));
    }
    for (int j = n - 1; j >= 0; j--)
        if (!p->dry[j] && s->phi[j] >= phi_dry) {
            p->u_ref = s->u[j];
            break;
        }
    /* the speed gravity along the slab gives over the height */
    u_scale = fmax(u_scale, sqrt(fabs(p->g_x) * n * s->dz));
    u_scale = fmax(u_scale, 1e-3);
    p->dry_face[0] = p->dry_face[n] = 0;
    for (int f = 1; f < n; f++) {
        p->dry_face[f] = 0.5 * (s->phi[f - 1] + s->phi[f]) < phi_dry;
        p->sealed[f] = !p->dry_face[f] && !p->dry[f - 1] && p->dry[f] && !p->joined[f];
    }
    for (int j = 0; j < n; j++) {
        double *x = p->U + (size_t)j * nv, *t = p->typ + (size_t)j * nv;
        unsigned char *alg = p->algebraic + (size_t)j * nv;
        x[SLOT_C] = p->c0[j];
        t[SLOT_C] = 1.0;
        alg[SLOT_C] = !joined_face(p, j);
        /* a cell that just became wet starts at its wet neighbour's u, T */
        const int fresh = !p->dry[j] && s->phi[j] < phi_dry && j > 0;
        x[SLOT_U] = p->dry[j] ? 0.0 : (fresh ? s->u[j - 1] : s->u[j]) - p->u_ref;
        t[SLOT_U] = u_scale;
        alg[SLOT_U] = p->dry[j];
        if (j > 0 && p->sealed[j]) {
            x[SLOT_T] = s->w[j] < 0.0 ? s->w[j] : 0.0;
            t[SLOT_T] = W_TYP;
            alg[SLOT_T] = 1; /* a local balance: no pseudo-time */
        } else if (p->dry[j]) {
            x[SLOT_T] = 0.0;
            t[SLOT_T] = 1.0;
            alg[SLOT_T] = 1;
        } else {
            double T = fresh ? s->T[j - 1] : s->T[j];
            if (!(T > 0.0))
                T = j > 0 && s->T[j - 1] > 0.0 ? s->T[j - 1] : fmax(sc->T_init, sc->numerics.T_floor);
            x[SLOT_T] = log(fmax(T, sc->numerics.T_floor));
            t[SLOT_T] = 1.0;
            alg[SLOT_T] = 0;
        }
        if (p->moving) {
            x[SLOT_DZ] = s->dz;
            t[SLOT_DZ] = s->dz;
            alg[SLOT_DZ] = 1;
        }
    }
}

static double norm2_scaled(const ss_problem *p, const double *R, const double *mag)
{
    double sum = 0.0;
    for (int i = 0; i < p->N; i++)
        sum += (R[i] / mag[i]) * (R[i] / mag[i]);
    return sqrt(sum / p->N);
}

static double norm_max_scaled(const ss_problem *p, const double *R, const double *mag, int *where)
{
    double mx = 0.0;
    *where = 0;
    for (int i = 0; i < p->N; i++)
        if (fabs(R[i] / mag[i]) > mx) {
            mx = fabs(R[i] / mag[i]);
            *where = i;
        }
    return mx;
}

static const char *row_name(const ss_problem *p, int i)
{
    const int j = i / p->nv, slot = i % p->nv;
    switch (slot) {
    case SLOT_C:
        return p->algebraic[i] ? (j == p->n - 1 && p->moving ? "wall pressure" : "mass") : "normal momentum";
    case SLOT_U: return "shear momentum";
    case SLOT_T: return j > 0 && p->sealed[j] ? "surface normal momentum" : "temperature";
    default: return "gap";
    }
}

/* The pseudo-mass of each row at p->U, the physical inertia of its
 * equation written as M dU/dt = -R (so that backward Euler in the pseudo
 * time is (J + M / delta) dU = -R): rho (shear), rho T (temperature in
 * ln T), and for a face's normal momentum the creep of the cumulative phi
 * through it, dc/dt = -phi dz R / (2 mu_n) (the face velocity a viscous
 * balance of the force R gives); a sealed face's w: its rho. */
static void pseudo_mass(ss_problem *p)
{
    unpack(p, p->U);
    const int n = p->n, nv = p->nv;
    const double rho_p = p->sc->material.rho_p;
    const ekm_state *s = p->s;
    for (int j = 0; j < n; j++) {
        const size_t i = (size_t)j * nv;
        const double dz = p->dz[j];
        const int f = joined_face(p, j);
        if (f) {
            /* the cumulative from the top grows with an upward flux, the
             * one from the base falls */
            const double phi_face = 0.5 * (s->phi[f - 1] + s->phi[f]);
            const double mu = 0.5 * (p->mu_n[f - 1] + p->mu_n[f]);
            p->pmass[i + SLOT_C] = (p->from_top ? -2.0 : 2.0) * mu / (fmax(phi_face, 1e-3) * dz);
        }
        p->pmass[i + SLOT_U] = -rho_p * s->phi[j];
        if (j > 0 && p->sealed[j])
            p->pmass[i + SLOT_T] = rho_p * 0.5 * (s->phi[j - 1] + s->phi[j]);
        else
            p->pmass[i + SLOT_T] = -rho_p * s->phi[j] * s->T[j];
    }
}

/* The size of a finite-difference step's column: a cumulative phi moves
 * phi of its cell and of the one it is summed from by it, so it is their
 * distance to the ends of (0, phi_cp) (wet cells; 1 phi-cell at most). */
static double fd_scale(const ss_problem *p, int c)
{
    if (c % p->nv != SLOT_C)
        return fmax(fabs(p->U[c]), p->typ[c]);
    const int j = c / p->nv;
    const double phi_cp = p->sc->material.phi_cp;
    double room = 1.0;
    const int cells[2] = {j, p->from_top ? j - 1 : j + 1};
    for (int i = 0; i < 2; i++) {
        const int k = cells[i];
        if (k < 0 || k >= p->n || p->dry[k])
            continue;
        const double phi = p->U[(size_t)k * p->nv] - cumulative_next(p, p->U, k);
        room = fmin(room, fmin(phi, phi_cp - phi));
    }
    return fmax(room, 1e-12);
}

/* The banded Jacobian of the scaled residual at p->U (R, mag there) by
 * finite differences, columns kl + ku + 1 apart perturbed together, with
 * the pseudo-mass J_ii / delta on the rows that have one. */
static ekm_status jacobian(ss_problem *p, double delta, ekm_error *err)
{
    const int N = p->N, kl = p->kl, ku = p->ku, ldab = p->ldab, stride = kl + ku + 1;
    memset(p->ab, 0, (size_t)ldab * N * sizeof *p->ab);
    pseudo_mass(p);
    for (int g = 0; g < stride && g < N; g++) {
        int valid = 0;
        for (int sign = 1; sign >= -1 && !valid; sign -= 2) {
            memcpy(p->U1, p->U, (size_t)N * sizeof *p->U1);
            for (int c = g; c < N; c += stride) {
                p->h[c] = sign * FD_EPS * fd_scale(p, c);
                /* at least a few ulps of the value itself */
                if (fabs(p->h[c]) < 64.0 * DBL_EPSILON * fabs(p->U[c]))
                    p->h[c] = sign * 64.0 * DBL_EPSILON * fabs(p->U[c]);
                p->U1[c] = p->U[c] + p->h[c];
                p->h[c] = p->U1[c] - p->U[c];
            }
            valid = residual(p, p->U1, p->R1, NULL);
        }
        if (!valid)
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: the Jacobian cannot be evaluated (the iterate is at the "
                            "edge of phi in (0, phi_cp))",
                            p->sc->source);
        for (int c = g; c < N; c += stride)
            if (!(p->h[c] != 0.0))
                return EKM_FAIL(err, EKM_ENOTSTEADY, "%s: no steady state: the Jacobian cannot be evaluated",
                                p->sc->source);
        for (int c = g; c < N; c += stride) {
            const int r_lo = c - ku > 0 ? c - ku : 0, r_hi = c + kl < N - 1 ? c + kl : N - 1;
            for (int r = r_lo; r <= r_hi; r++)
                p->ab[(size_t)c * ldab + kl + ku + r - c] = (p->R1[r] - p->R[r]) / p->h[c] / p->mag[r];
        }
    }
    for (int i = 0; i < N; i++)
        if (!p->algebraic[i])
            p->ab[(size_t)i * ldab + kl + ku] += p->pmass[i] / p->mag[i] / delta;
    return EKM_OK;
}

/* At the accepted iterate p->U (unpacked): a surface face pushed upwards
 * (w > 0: the layer grows into the empty cell, which joins the run), or a
 * cell with material thinned below phi_dry (the stepper's emptiness rule:
 * it is empty from now on, keeping its mass), but the top of a dilute
 * tail (the cell below it thinner than PHI_FRINGE, see classify).  1: the
 * frozen empty set no longer fits. */
static int surface_moves(ss_problem *p)
{
    int moves = 0;
    const ekm_state *s = p->s;
    for (int f = 1; f < p->n; f++)
        if (p->sealed[f] && s->w[f] > 0.0)
            moves = p->joined[f] = 1;
    for (int j = 0; j < p->n; j++)
        if (!p->dry[j] && s->phi[j] < p->sc->numerics.phi_dry && !(j > 0 && s->phi[j - 1] < PHI_FRINGE))
            moves = 1;
    return moves;
}

/* Newton with pseudo-transient continuation on the frozen empty set;
 * p->U holds the guess and on success the solution. */
static ekm_status newton(ss_problem *p, ekm_steady_report *rep, int budget, ekm_error *err)
{
    const int N = p->N;
    if (!residual(p, p->U, p->R, p->mag))
        return EKM_FAIL(err, EKM_ENOTSTEADY,
                        "%s: no steady state: the guess is outside the domain (phi of a cell with material "
                        "outside (0, phi_cp), or not finite)",
                        p->sc->source);
    double delta = DELTA0;
    double res = norm2_scaled(p, p->R, p->mag);
    int polished = 0;
    const int first = rep->iterations;
    for (;;) {
        /* A stall: the continuation marches (the pseudo-time step grows:
         * the steps change the state little) but the residual stays where
         * it is, a stationary point of the continuation that is no root;
         * or the pseudo-time step is past every relaxation time (Newton's
         * own iteration) and the residual does not fall by STALL_PROGRESS
         * in STALL_ITER iterations (the chute with the fit's set at 26
         * degrees wandered between 0.515 and 0.529 from iteration 25 to
         * 60 with delta from 1e3 to 6e12 s).  The attempt ends now rather
         * than at its budget, the time steps take over. */
        const int last = rep->iterations - 1;
        if (last - first >= STALL_ITER) {
            const int from = last - STALL_ITER;
            double lo = rep->residual[last], hi = lo, delta_lo = rep->delta[last];
            for (int k = from; k < last; k++) {
                lo = fmin(lo, rep->residual[k]);
                hi = fmax(hi, rep->residual[k]);
                delta_lo = fmin(delta_lo, rep->delta[k]);
            }
            const int flat = hi < STALL_RES * lo && rep->delta[last] >= STALL_DELTA * rep->delta[from];
            const int no_progress =
                delta_lo >= STALL_NEWTON_DELTA && rep->residual[last] > STALL_PROGRESS * rep->residual[from];
            if (flat || no_progress)
                return EKM_FAIL(
                    err, EKM_ENOTSTEADY,
                    "%s: no steady state: Newton stalled at scaled residual %.3g (from %.3g over %d "
                    "iterations, the pseudo-time step from %.3g s to %.3g s)",
                    p->sc->source, res, rep->residual[from], STALL_ITER, rep->delta[from], rep->delta[last]);
        }
        if (rep->iterations >= budget || rep->iterations >= EKM_STEADY_MAX_ITER) {
            /* converged already (polished = 1: the next one would have
             * been the polishing iteration): no budget left for it */
            if (polished)
                return EKM_OK;
            int where;
            const double mx = norm_max_scaled(p, p->R, p->mag, &where);
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: Newton did not converge in %d iterations (scaled residual "
                            "%.3g, largest %.3g in the %s of cell %d, last update %.3g)",
                            p->sc->source, rep->iterations, res, mx, row_name(p, where), where / p->nv,
                            rep->update_final);
        }
        const int it = rep->iterations++;
        rep->residual[it] = res;
        rep->delta[it] = delta;
        if (rep->progress)
            fprintf(rep->progress,
                    "ekm steady: %s: attempt %d iteration %3d  scaled residual %.3e  delta %.3g s\n",
                    p->sc->name, rep->attempts, it + 1, res, delta);
        ekm_status st = jacobian(p, delta, err);
        if (st != EKM_OK)
            return st;
        for (int i = 0; i < N; i++)
            p->dU[i] = -p->R[i] / p->mag[i];
        lapack_int info = LAPACKE_dgbtrf(LAPACK_COL_MAJOR, N, N, p->kl, p->ku, p->ab, p->ldab, p->ipiv);
        if (info == 0)
            info =
                LAPACKE_dgbtrs(LAPACK_COL_MAJOR, 'N', N, p->kl, p->ku, 1, p->ab, p->ldab, p->ipiv, p->dU, N);
        if (info > 0) {
            if (delta > DELTA0 * 1e-6) {
                delta *= 0.01;
                continue;
            }
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: singular Jacobian (pivot %d: the %s of cell %d) at scaled "
                            "residual %.3g",
                            p->sc->source, (int)info, row_name(p, (int)info - 1), ((int)info - 1) / p->nv,
                            res);
        }
        if (info < 0)
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: the Jacobian is not finite (LAPACK argument %d) at scaled "
                            "residual %.3g",
                            p->sc->source, (int)-info, res);
        /* stay in the domain (halve the step until it is) and change
         * ln T by at most LNT_STEP_MAX per iteration */
        double alpha = 1.0;
        for (int i = SLOT_T; i < N; i += p->nv)
            if (!(p->dry[i / p->nv] || (i / p->nv > 0 && p->sealed[i / p->nv])) &&
                fabs(p->dU[i]) * alpha > LNT_STEP_MAX)
                alpha = LNT_STEP_MAX / fabs(p->dU[i]);
        int ok = 0;
        for (int k = 0; k < 40 && !ok; k++, alpha *= 0.5) {
            for (int i = 0; i < N; i++)
                p->U1[i] = p->U[i] + alpha * p->dU[i];
            ok = residual(p, p->U1, p->R1, NULL);
        }
        if (!ok) {
            if (delta > DELTA0 * 1e-6) {
                delta *= 0.01;
                continue;
            }
            return EKM_FAIL(
                err, EKM_ENOTSTEADY,
                "%s: no steady state: no step stays in the domain (phi of a cell with material in "
                "(0, phi_cp)) at scaled residual %.3g after %d iterations",
                p->sc->source, res, rep->iterations);
        }
        alpha *= 2.0;
        double update = 0.0;
        for (int i = 0; i < N; i++)
            update = fmax(update, fabs(alpha * p->dU[i]) / fmax(fabs(p->U[i]), p->typ[i]));
        /* the pseudo-time step control: a step that changes a cell by
         * more than STEP_CHANGE_MAX (relative; phi over PHI_SCALE) is
         * retaken with a shorter delta, a small one lets delta grow */
        double change = 0.0;
        for (int i = 0; i < N; i++)
            if (!p->algebraic[i])
                change = fmax(change, fabs(alpha * p->dU[i]) / fmax(fabs(p->U[i]), p->typ[i]));
        for (int j = 0; j < p->n; j++) {
            const double dphi = alpha * (p->dU[(size_t)j * p->nv + SLOT_C] - cumulative_next(p, p->dU, j));
            change = fmax(change, fabs(dphi) / PHI_SCALE);
        }
        if (change > STEP_CHANGE_MAX && delta > DELTA0 * 1e-6 && delta < DELTA_MAX) {
            delta *= 0.25;
            continue;
        }
        memcpy(p->U, p->U1, (size_t)N * sizeof *p->U);
        if (!residual(p, p->U, p->R, p->mag))
            return EKM_FAIL(err, EKM_EINTERNAL, "steady solver: the accepted iterate is outside the domain");
        const double res_new = norm2_scaled(p, p->R, p->mag);
        /* grows by the step's change, shrinks with a rising residual (SER) */
        delta = fmin(DELTA_MAX, delta * fmin(4.0, fmax(0.5, 0.5 * STEP_CHANGE_MAX / fmax(change, 1e-300))) *
                                    fmin(1.0, res / fmax(res_new, 1e-300)));
        if (alpha < 1.0)
            delta *= 0.5;
        res = res_new;
        rep->update_final = update;
        int where;
        rep->residual_final = norm_max_scaled(p, p->R, p->mag, &where);
        /* converged; one more iteration (Newton's: quadratic) when the
         * residual is not yet far below the tolerance, so that the stepper
         * does not see it */
        if (rep->residual_final < EKM_STEADY_RES_TOL && update < EKM_STEADY_UPDATE_TOL) {
            if (polished || rep->residual_final < POLISH_FACTOR * EKM_STEADY_RES_TOL)
                return EKM_OK;
            polished = 1;
        }
        if (surface_moves(p))
            return EKM_EOF; /* the caller re-freezes the empty set and goes on */
    }
}

/* The solution into s (w = 0 but on sealed faces). */
static void store(ss_problem *p, ekm_state *s)
{
    unpack(p, p->U);
    const int n = p->n;
    s->dz = p->moving ? p->dz[n - 1] : p->dz0;
    for (int j = 0; j < n; j++) {
        s->z[j] = (j + 0.5) * s->dz;
        s->phi[j] = p->s->phi[j];
        /* the stepper's emptiness rule: no u, T below phi_dry */
        const int empty = p->dry[j] || s->phi[j] < p->sc->numerics.phi_dry;
        s->u[j] = empty ? 0.0 : p->s->u[j] + p->u_ref;
        s->T[j] = empty ? 0.0 : p->s->T[j];
    }
    memcpy(s->w, p->s->w, ((size_t)n + 1) * sizeof *s->w);
}

/* 1: the empty set or a sealed face of the solution differs from the
 * frozen one (the faces with an upward w join their run), but in the
 * fringe: a cell with material that thinned below phi_dry, or a face
 * whose cells are both below PHI_FRINGE, keeps its frozen kind
 * (docs/model/steady.md: the emptiness rule has no exact fixed point at a dilute
 * tail's top). */
static int topology_changed(ss_problem *p, const ekm_state *s)
{
    const double phi_dry = p->sc->numerics.phi_dry;
    const int n = p->n;
    int changed = 0;
    for (int j = 0; j < n; j++)
        changed |= p->dry[j] ? s->phi[j] >= phi_dry : s->phi[j] < phi_dry && s->phi[j] >= PHI_FRINGE;
    for (int f = 1; f < n; f++) {
        const int fringe = s->phi[f - 1] < PHI_FRINGE && s->phi[f] < PHI_FRINGE;
        changed |= (0.5 * (s->phi[f - 1] + s->phi[f]) < phi_dry) != p->dry_face[f] && !fringe;
        if (p->sealed[f] && s->w[f] > 0.0) {
            p->joined[f] = 1;
            changed = 1;
        }
    }
    return changed;
}

/* The largest change of field a -> b over the cells with at least
 * phi_min of material in both states, over scale; *where its cell. */
static double change_max(const double *a, const double *b, const double *phi_a, const double *phi_b, int n,
                         double phi_min, double scale, int *where)
{
    double mx = 0.0;
    for (int j = 0; j < n; j++) {
        if (!(phi_a[j] >= phi_min && phi_b[j] >= phi_min))
            continue;
        const double c = fabs(a[j] - b[j]) / scale;
        if (!(c <= mx)) { /* a value that is not finite counts as infinite */
            mx = isfinite(c) ? c : INFINITY;
            *where = j;
        }
    }
    return mx;
}

/* Time steps of the real stepper from the solution must not move it: at
 * least EKM_STEADY_VERIFY_STEPS steps at the step limit and at least
 * EKM_STEADY_VERIFY_FLOW_TIMES times the gap over the velocity scale (at
 * most EKM_STEADY_VERIFY_MAX_STEPS steps), then the max-norm change of
 * each field relative to its scale in the solution below
 * EKM_STEADY_VERIFY_TOL: phi over max phi (every cell), u over max(|u|,
 * 1 mm/s) and T over max T (the cells with at least PHI_FRINGE of
 * material in both states), w as the volume flux w phi_face over max phi
 * times that velocity (every face), the gap relative. */
static ekm_status verify(const ekm_scenario *sc, const ekm_state *sol, ekm_steady_report *rep, ekm_error *err)
{
    ekm_state *s = ekm_state_alloc(sol->n, sc->length);
    ekm_stepper *st = s ? ekm_step_alloc(sc, err) : NULL;
    if (!s || !st) {
        ekm_state_free(s);
        ekm_step_free(st);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory verifying the steady state");
    }
    const int n = sol->n;
    double phi_max = 0.0, u_max = 1e-3, T_max = 0.0;
    for (int j = 0; j < n; j++) {
        phi_max = fmax(phi_max, sol->phi[j]);
        if (sol->phi[j] >= PHI_FRINGE) {
            u_max = fmax(u_max, fabs(sol->u[j]));
            T_max = fmax(T_max, sol->T[j]);
        }
    }
    phi_max = fmax(phi_max, sc->numerics.phi_dry);
    const double t_span = EKM_STEADY_VERIFY_FLOW_TIMES * n * sol->dz / u_max;
    ekm_state_copy(s, sol);
    s->t = 0.0;
    ekm_status rc = EKM_OK;
    int steps = 0;
    while (rc == EKM_OK && steps < EKM_STEADY_VERIFY_MAX_STEPS &&
           (steps < EKM_STEADY_VERIFY_STEPS || s->t < t_span)) {
        const double dt = ekm_control_max_dt(sc, s, NULL);
        int accepted = 0;
        rc = ekm_step_apply(st, s, dt, &accepted, err);
        if (rc == EKM_OK && !accepted)
            rc = EKM_FAIL(err, EKM_ENOTSTEADY,
                          "%s: no steady state: the time stepper rejects a step from the solution: %s",
                          sc->source, st->reject_reason);
        steps++;
    }
    rep->verify_steps = steps;
    rep->verify_time = s->t;
    if (rc == EKM_OK) {
        static const char *const names[5] = {"phi", "vx", "T", "w phi", "gap"};
        int where[5] = {0, 0, 0, 0, 0};
        double ch[5];
        ch[0] = change_max(s->phi, sol->phi, s->phi, sol->phi, n, 0.0, phi_max, &where[0]);
        ch[1] = change_max(s->u, sol->u, s->phi, sol->phi, n, PHI_FRINGE, u_max, &where[1]);
        ch[2] =
            T_max > 0.0 ? change_max(s->T, sol->T, s->phi, sol->phi, n, PHI_FRINGE, T_max, &where[2]) : 0.0;
        ch[3] = 0.0;
        for (int f = 0; f <= n; f++) {
            const double phi_face = f == 0   ? sol->phi[0]
                                    : f == n ? sol->phi[n - 1]
                                             : 0.5 * (sol->phi[f - 1] + sol->phi[f]);
            const double c = fabs(s->w[f] - sol->w[f]) * phi_face / (phi_max * u_max);
            if (!(c <= ch[3])) {
                ch[3] = isfinite(c) ? c : INFINITY;
                where[3] = f;
            }
        }
        ch[4] = fabs(s->dz - sol->dz) / sol->dz;
        if (!isfinite(ch[4]))
            ch[4] = INFINITY;
        int worst = 0;
        for (int k = 0; k < 5; k++) {
            rep->verify_field[k] = ch[k];
            if (ch[k] > ch[worst])
                worst = k;
        }
        rep->verify_change = ch[worst];
        if (!(ch[worst] < EKM_STEADY_VERIFY_TOL))
            rc = EKM_FAIL(err, EKM_ENOTSTEADY,
                          "%s: no steady state: the time stepper moves away from the Newton solution "
                          "(change of %s %.3g relative%s%d > %.0e over %d steps, %.3g s)",
                          sc->source, names[worst], ch[worst],
                          worst == 4   ? ""
                          : worst == 3 ? ", face "
                                       : ", cell ",
                          worst == 4 ? 0 : where[worst], EKM_STEADY_VERIFY_TOL, steps, s->t);
    }
    ekm_step_free(st);
    ekm_state_free(s);
    return rc;
}

/* A surface face pushed upwards (joined): the empty cell above gets
 * SEED_FRACTION of the material below, with its u and T (the stepper's
 * next steps fill it so), and is a cell with material from now on. */
static void seed_joined(ss_problem *p, ekm_state *s)
{
    const double phi_dry = p->sc->numerics.phi_dry;
    for (int f = 1; f < p->n; f++) {
        if (!p->joined[f] || !(s->phi[f] < phi_dry) || !(s->phi[f - 1] >= phi_dry / SEED_FRACTION))
            continue;
        const double dm = SEED_FRACTION * s->phi[f - 1];
        s->phi[f] += dm;
        s->phi[f - 1] -= dm;
        s->u[f] = s->u[f - 1];
        s->T[f] = s->T[f - 1];
        p->joined[f] = 0;
    }
}

/* The top of a dilute tail whose face above has material (the stepper
 * opens it, and the tail creeps upwards through it at a rate that grows
 * with the top cell's phi): the empty cell above gets SEED_FRACTION of
 * the top cell's material, u and T, and is a cell with material in the
 * next solve.  1: a cell was seeded. */
static int extend_tail(ss_problem *p, ekm_state *s)
{
    const double phi_dry = p->sc->numerics.phi_dry;
    for (int f = 1; f < p->n; f++) {
        if (!(s->phi[f] == 0.0 && s->phi[f - 1] >= phi_dry && s->phi[f - 1] < PHI_FRINGE &&
              0.5 * s->phi[f - 1] >= phi_dry))
            continue;
        const double dm = SEED_FRACTION * s->phi[f - 1];
        s->phi[f] = dm;
        s->phi[f - 1] -= dm;
        s->u[f] = s->u[f - 1];
        s->T[f] = s->T[f - 1];
        return 1;
    }
    return 0;
}

/* A sealed surface face with w < 0 under an empty cell that holds some
 * material (below phi_dry): the stepper's flux w phi_upwind drains it into
 * the cell below; it is moved there.  1: some was. */
static int drain_sealed(const ss_problem *p, ekm_state *s)
{
    int moved = 0;
    for (int f = 1; f < p->n; f++)
        if (p->sealed[f] && s->w[f] < 0.0 && s->phi[f] > 0.0) {
            s->phi[f - 1] += s->phi[f];
            s->phi[f] = 0.0;
            moved = 1;
        }
    return moved;
}

/* Runs of cells with material (phi >= phi_dry) whose phi stays below
 * PHI_FRINGE and that are not joined to thicker material (a film a
 * transient left above a surface, with empty cells between) join the
 * nearest cell with at least PHI_FRINGE below (above when none): mass
 * kept, the cells empty.  Such a film has no shear to heat it and falls
 * onto the layer in the stepper; it has no steady state of its own.  A
 * dilute tail joined to the layer below it is kept. */
static void merge_detached_films(const ekm_scenario *sc, ekm_state *s)
{
    const double phi_dry = sc->numerics.phi_dry;
    const int n = s->n;
    for (int a = 0; a < n;) {
        if (!(s->phi[a] >= phi_dry)) {
            a++;
            continue;
        }
        int b = a;
        double top = s->phi[a];
        while (b + 1 < n && s->phi[b + 1] >= phi_dry)
            top = fmax(top, s->phi[++b]);
        if (top < PHI_FRINGE) {
            int k = a - 1;
            while (k >= 0 && s->phi[k] < PHI_FRINGE)
                k--;
            if (k < 0)
                for (k = b + 1; k < n && s->phi[k] < PHI_FRINGE; k++)
                    ;
            if (k < n)
                for (int j = a; j <= b; j++) {
                    s->phi[k] += s->phi[j];
                    s->phi[j] = 0.0;
                    s->u[j] = s->T[j] = 0.0;
                }
        }
        a = b + 1;
    }
}

/* Newton from s, with new solves while the empty set changes. */
static ekm_status solve_from(ss_problem *p, ekm_state *s, ekm_steady_report *rep, ekm_error *err)
{
    memset(p->joined, 0, (size_t)p->n + 1);
    merge_detached_films(p->sc, s);
    const int budget = rep->iterations + EKM_STEADY_ATTEMPT_ITER;
    for (int pass = 0;; pass++) {
        classify(p, s);
        ekm_status rc = newton(p, rep, budget, err);
        if (rc == EKM_EOF && pass < MAX_RESOLVES) {
            /* the surface moved during the solve: go on from there */
            store(p, s);
            merge_detached_films(p->sc, s);
            seed_joined(p, s);
            rep->dry_resolves++;
            continue;
        }
        if (rc == EKM_EOF)
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: the surface still moves after %d solves", p->sc->source,
                            MAX_RESOLVES + 1);
        if (rc != EKM_OK)
            return rc;
        store(p, s);
        if (!topology_changed(p, s) && !drain_sealed(p, s) && !extend_tail(p, s))
            break;
        seed_joined(p, s);
        if (pass == MAX_RESOLVES)
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: the set of empty cells still changes after %d solves",
                            p->sc->source, MAX_RESOLVES + 1);
        rep->dry_resolves++;
    }
    for (int j = 0; j < s->n; j++)
        if (!(s->phi[j] >= 0.0 && s->phi[j] < p->sc->material.phi_cp))
            return EKM_FAIL(err, EKM_ENOTSTEADY,
                            "%s: no steady state: phi = %.9g in cell %d is outside [0, %g)", p->sc->source,
                            s->phi[j], j, p->sc->material.phi_cp);
    return EKM_OK;
}

/* mu of the steady homogeneous shear at phi (rate 1/s; 0 when none) and
 * its P_Y (the rate matters then). */
static double homog_mu(const ekm_scenario *sc, double phi, ekm_homog_state *h)
{
    ekm_error herr;
    if (ekm_homog_shear(&sc->material, sc->variant, phi, 1.0, h, &herr) != EKM_OK)
        return 0.0;
    return h->mu;
}

/* The local (Bagnold) steady flow of a layer on an incline (a wall below,
 * free top, g along the slab), with g's mass: uniform phi* where the
 * homogeneous shear's stress ratio mu(phi*) = |g_x / g_z| (mu falls with
 * phi, rate-free where P_Y = 0), the shear rate of the weight above,
 * P(phi*, gdot) = rho_p phi* |g_z| (h - z) with P = P_1 gdot^2, T = T_1
 * gdot^2 (P_1, T_1 at 1/s), u integrated from the wall's slip.  0 (s
 * unchanged): no such state (another geometry, no root below phi_co, a
 * yield pressure at phi*, the layer does not fit, a slip length longer
 * than the layer). */
static int local_guess(const ekm_scenario *sc, const ekm_state *g, ekm_state *s)
{
    const double g_x = ekm_scenario_gravity_x(sc), g_z = ekm_scenario_gravity_z(sc);
    if (sc->bottom.kind != EKM_BC_WALL || sc->top.kind != EKM_BC_FREE || !(g_z < 0.0) || g_x == 0.0 ||
        ekm_boundary_rate_wall(&sc->bottom))
        return 0;
    const double target = fabs(g_x / g_z), phi_dry = sc->numerics.phi_dry;
    ekm_homog_state h;
    double lo = 1e-3, hi = sc->material.phi_co * (1.0 - 1e-9);
    if (!(homog_mu(sc, lo, &h) > target && homog_mu(sc, hi, &h) < target && h.mu > 0.0))
        return 0;
    for (int k = 0; k < 60; k++) {
        const double mid = 0.5 * (lo + hi);
        if (homog_mu(sc, mid, &h) > target)
            lo = mid;
        else
            hi = mid;
    }
    const double phi_s = 0.5 * (lo + hi);
    if (!(homog_mu(sc, phi_s, &h) > 0.0) || h.P_Y != 0.0 || !(h.P > 0.0 && h.T > 0.0))
        return 0;
    const int n = g->n;
    const double dz = g->dz;
    double mass = 0.0; /* [cells] */
    for (int j = 0; j < n; j++)
        mass += g->phi[j];
    const int full = (int)floor(mass / phi_s);
    if (full < 2 || full >= n)
        return 0;
    const double height = mass / phi_s * dz, weight = sc->material.rho_p * phi_s * fabs(g_z);
    const ekm_bc_face bb = ekm_bc_evaluate(&sc->bottom, EKM_SIDE_BOTTOM, 0.0, g);
    if (!(bb.wall_conductance * height >= 1.0))
        return 0; /* a base slipping over more than the layer's height: no local flow */
    ekm_state_copy(s, g);
    /* shear rate at height z (at least that of half a cell below the top) */
    const double sign = g_x > 0.0 ? 1.0 : -1.0;
#define GDOT_AT(z) sqrt(weight *fmax(height - (z), 0.5 * dz) / h.P)
    double u = bb.u_wall + sign * GDOT_AT(0.0) / bb.wall_conductance;
    for (int j = 0; j < n; j++) {
        const double z = (j + 0.5) * dz;
        if (j > 0)
            u += sign * GDOT_AT(j * dz) * dz;
        const double phi = j < full ? phi_s : (j == full ? mass - full * phi_s : 0.0);
        s->phi[j] = phi;
        s->u[j] = phi >= phi_dry ? u : 0.0;
        s->T[j] = phi >= phi_dry ? h.T * GDOT_AT(z) * GDOT_AT(z) : 0.0;
    }
#undef GDOT_AT
    for (int f = 0; f <= n; f++)
        s->w[f] = 0.0;
    return 1;
}

/* The homogeneous steady shear between two walls without gravity (plane
 * Couette flow, walls moving at their velocities, adiabatic): uniform phi,
 * T and shear rate, u linear through the slip of both walls, w = 0, with
 * g's mass; on a gap held at [top] pressure p the phi whose homogeneous
 * shear has P(phi, gdot(phi)) = p (the gap L = mass / phi, the rate
 * gdot = U / (L + b_bottom + b_top), b the slip lengths: P rises with phi
 * on both counts, bisection), on a fixed gap the guess's mean phi.  0 (s
 * unchanged): another geometry (gravity, a free end, inflow, a rate-driven
 * wall), walls at the same speed, no root below phi_cp. */
static int couette_guess(const ekm_scenario *sc, const ekm_state *g, ekm_state *s)
{
    const ekm_bc *b = &sc->bottom, *t = &sc->top;
    if (b->kind != EKM_BC_WALL || t->kind != EKM_BC_WALL || ekm_boundary_rate_wall(b) ||
        ekm_boundary_rate_wall(t) || ekm_scenario_gravity_x(sc) != 0.0 || ekm_scenario_gravity_z(sc) != 0.0 ||
        sc->angle_rate != 0.0)
        return 0;
    const double U = t->velocity - b->velocity;
    if (!(fabs(U) > 0.0))
        return 0;
    const int n = g->n;
    double mass = 0.0; /* sum phi dz [m] */
    for (int j = 0; j < n; j++)
        mass += g->phi[j] * g->dz;
    const double slip = b->slip_length + t->slip_length, phi_cp = sc->material.phi_cp;
    const int pressure = ekm_boundary_pressure_wall(t);
    ekm_homog_state h;
    ekm_error herr;
#define GDOT_OF(phi) (fabs(U) / (mass / (phi) + slip))
    double phi = mass / (n * g->dz);
    if (pressure) {
        double lo = 1e-6, hi = phi_cp * (1.0 - 1e-12);
        if (!(mass / hi < sc->length * 1e3))
            return 0;
        if (ekm_homog_shear(&sc->material, sc->variant, hi, GDOT_OF(hi), &h, &herr) != EKM_OK ||
            !(h.P > t->pressure))
            return 0;
        for (int k = 0; k < 80; k++) {
            const double mid = 0.5 * (lo + hi);
            if (ekm_homog_shear(&sc->material, sc->variant, mid, GDOT_OF(mid), &h, &herr) == EKM_OK &&
                h.P > t->pressure)
                hi = mid;
            else
                lo = mid;
        }
        phi = 0.5 * (lo + hi);
    }
    if (!(phi > 0.0 && phi < phi_cp) ||
        ekm_homog_shear(&sc->material, sc->variant, phi, GDOT_OF(phi), &h, &herr) != EKM_OK || !(h.T > 0.0))
        return 0;
    const double gdot = GDOT_OF(phi) * (U > 0.0 ? 1.0 : -1.0);
#undef GDOT_OF
    ekm_state_copy(s, g);
    if (pressure) {
        s->dz = mass / phi / n;
        for (int j = 0; j < n; j++)
            s->z[j] = (j + 0.5) * s->dz;
    }
    for (int j = 0; j < n; j++) {
        s->phi[j] = phi;
        s->u[j] = b->velocity + gdot * (b->slip_length + (j + 0.5) * s->dz);
        s->T[j] = h.T;
    }
    for (int f = 0; f <= n; f++)
        s->w[f] = 0.0;
    return 1;
}

/* Advance g by `span` of model time with the real time loop (run.h), no
 * output. */
static ekm_status warm_up(ekm_scenario *sc_warm, ekm_stepper *st, ekm_state *g, double span, ekm_error *err)
{
    sc_warm->t_end = span;
    sc_warm->output_dt = span;
    sc_warm->stop = EKM_STOP_T_END;
    g->t = 0.0;
    ekm_run_stats stats;
    return ekm_run(sc_warm, g, st, NULL, &stats, err);
}

ekm_status ekm_steady_solve(const ekm_scenario *sc, ekm_state *s, ekm_steady_report *rep_out, ekm_error *err)
{
    const double t0 = ekm_now_s();
    ekm_steady_report rep_local;
    ekm_steady_report *rep = rep_out ? rep_out : &rep_local;
    FILE *progress = rep_out ? rep_out->progress : NULL;
    memset(rep, 0, sizeof *rep);
    rep->progress = progress;
    ekm_status rc = ekm_steady_supported(sc, err);
    if (rc != EKM_OK)
        return rc;
    if (s->n != sc->cells)
        return EKM_FAIL(err, EKM_EINPUT, "%s: the guess has %d cells, the scenario %d", sc->source, s->n,
                        sc->cells);
    ss_problem p;
    rc = problem_alloc(&p, sc, err);
    if (rc != EKM_OK)
        return rc;
    /* the guess, advanced by the time stepper between attempts */
    ekm_state *g = ekm_state_alloc(s->n, sc->length);
    ekm_scenario sc_warm = *sc; /* shallow: only t_end, output_dt, stop differ */
    ekm_stepper *st = g ? ekm_step_alloc(&sc_warm, err) : NULL;
    if (!g || !st) {
        ekm_state_free(g);
        problem_free(&p);
        if (g) /* the status ekm_step_alloc recorded */
            return err->code;
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the steady solver (%d cells)", sc->cells);
    }
    ekm_state_copy(g, s);
    const double t_saved = s->t;
    const long steps_saved = s->steps;
    double span = EKM_STEADY_WARM_SPAN0, warmed = 0.0;
    /* Plane Couette flow: its steady state is the homogeneous shear (no
     * gravity, adiabatic walls), where Newton starts first; should the
     * stepper not keep it (a shear band), the attempts below go on from
     * the guess. */
    int done = 0;
    if (couette_guess(sc, g, s)) {
        rep->attempts++;
        rep->local_guess = 2;
        rc = solve_from(&p, s, rep, err);
        if (rc == EKM_OK)
            rc = verify(sc, s, rep, err);
        done = rc != EKM_ENOTSTEADY;
    }
    for (int attempt = 0; !done; attempt++) {
        ekm_state_copy(s, g);
        rep->attempts++;
        rc = solve_from(&p, s, rep, err);
        if (rc == EKM_OK)
            rc = verify(sc, s, rep, err);
        if (rc == EKM_ENOTSTEADY && attempt == 0 && local_guess(sc, g, s)) {
            /* the second attempt: from the local steady flow of g's mass,
             * which is also where the time steps towards the steady state
             * start (not the guess: from rest the flow takes ~30 s of
             * model time to build up) */
            ekm_state_copy(g, s);
            rep->attempts++;
            rep->local_guess = 1;
            rc = solve_from(&p, s, rep, err);
            if (rc == EKM_OK)
                rc = verify(sc, s, rep, err);
        }
        if (rc != EKM_ENOTSTEADY || attempt == EKM_STEADY_ATTEMPTS - 1 ||
            rep->iterations >= EKM_STEADY_MAX_ITER)
            break;
        /* not (yet) in Newton's basin: time steps towards it */
        ekm_error werr = {0};
        const double chunk = fmin(span, sc->t_end - warmed);
        if (!(chunk > 0.0))
            break;
        const ekm_status wrc = warm_up(&sc_warm, st, g, chunk, &werr);
        if (wrc == EKM_ENOTSTEADY) {
            rc = EKM_FAIL(err, EKM_ENOTSTEADY,
                          "%s: no steady state: Newton did not converge and the time steps towards it failed "
                          "after %.3g s of model time: %.700s",
                          sc->source, warmed, werr.message);
            break;
        }
        if (wrc != EKM_OK) {
            /* the time stepper itself failed (as `ekm run` would: its status, e.g. a step below dt_min) */
            rc = EKM_FAIL(err, wrc,
                          "%s: Newton did not converge and the time steps towards it failed after %.3g s of "
                          "model time: %.700s",
                          sc->source, warmed, werr.message);
            break;
        }
        warmed += chunk;
        rep->warm_time += chunk;
        rep->warm_steps += g->steps;
        g->steps = 0;
        span *= 2.0;
    }
    if (rc == EKM_ENOTSTEADY && rep->warm_time > 0.0 && !strstr(err->message, "time steps towards it")) {
        char msg[sizeof err->message];
        snprintf(msg, sizeof msg, "%.900s (after %.3g s of model time stepped, %d attempts)", err->message,
                 rep->warm_time, rep->attempts);
        snprintf(err->message, sizeof err->message, "%s", msg);
    }
    s->t = t_saved;
    s->steps = steps_saved;
    ekm_step_free(st);
    ekm_state_free(g);
    problem_free(&p);
    rep->gap = s->n * s->dz;
    rep->wall_s = ekm_now_s() - t0;
    return rc;
}
