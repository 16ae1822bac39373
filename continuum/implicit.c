#include "implicit.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

ekm_implicit_work *ekm_implicit_alloc(int n)
{
    ekm_implicit_work *wk = calloc(1, sizeof *wk);
    if (!wk)
        return NULL;
    wk->n = n;
    const size_t m = (size_t)n + 1;
    wk->diag = calloc(m, sizeof(double));
    wk->sub = calloc(m, sizeof(double));
    wk->sup = calloc(m, sizeof(double));
    wk->rhs = calloc(m, sizeof(double));
    wk->x = calloc(m, sizeof(double));
    wk->aux = calloc(m, sizeof(double));
    wk->update = calloc(m, sizeof(double));
    if (!wk->diag || !wk->sub || !wk->sup || !wk->rhs || !wk->x || !wk->aux || !wk->update) {
        ekm_implicit_free(wk);
        return NULL;
    }
    return wk;
}

void ekm_implicit_free(ekm_implicit_work *wk)
{
    if (!wk)
        return;
    free(wk->diag);
    free(wk->sub);
    free(wk->sup);
    free(wk->rhs);
    free(wk->x);
    free(wk->aux);
    free(wk->update);
    free(wk);
}

/* Solve the m x m tridiagonal system held in wk (sub[i] couples row i to
 * i-1, sup[i] to i+1) with the right-hand side x, into x, with LAPACK (no allocation: the *_work
 * routines in column-major order call the Fortran ones directly).  A
 * symmetric, weakly diagonally dominant system with a positive diagonal
 * (spd != 0: row_spd of every row)
 * (the viscous and conduction operators, and the temperature Jacobian
 * wherever the source does not heat faster than dt relaxes it) is
 * positive semi-definite and takes the L D L^T factorisation dptsv, which
 * has one division on the recurrence per row where dgtsv (Gaussian
 * elimination with partial pivoting) has two; any other system takes
 * dgtsv.  The system is overwritten (every caller assembles it anew). */
static ekm_status solve_in(ekm_implicit_work *wk, int m, int spd, double *x, const char *what, ekm_error *err)
{
    if (m == 1) {
        if (wk->diag[0] == 0.0)
            return EKM_FAIL(err, EKM_ENUMERIC, "%s: singular 1x1 system", what);
        x[0] /= wk->diag[0];
        return EKM_OK;
    }
    lapack_int info;
    if (spd) {
        /* d = diag, e = sup[0..m-2] (= sub[1..m-1]); both overwritten */
        info = LAPACKE_dptsv_work(LAPACK_COL_MAJOR, m, 1, wk->diag, wk->sup, x, m);
    } else {
        /* dl = sub[1..m-1], d = diag, du = sup[0..m-2]; all overwritten */
        info = LAPACKE_dgtsv_work(LAPACK_COL_MAJOR, m, 1, wk->sub + 1, wk->diag, wk->sup, x, m);
    }
    if (info > 0)
        return EKM_FAIL(err, EKM_ENUMERIC,
                        "%s: tridiagonal solve failed: singular system (%s pivot in row %d)", what,
                        spd ? "non-positive" : "zero", (int)info);
    if (info < 0)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: tridiagonal solve: LAPACK rejected argument %d", what,
                        (int)-info);
    return EKM_OK;
}

ekm_status ekm_implicit_solve(ekm_implicit_work *wk, int m, int spd, double *x, const char *what,
                              ekm_error *err)
{
    return solve_in(wk, m, spd, x, what, err);
}

/* Row j of the system in wk as solve_in's test needs it: a positive
 * diagonal that dominates the row, and (j > 0) symmetric with row j - 1. */
static inline int row_spd(const ekm_implicit_work *wk, int j)
{
    return (wk->diag[j] > 0.0) & (wk->diag[j] >= fabs(wk->sub[j]) + fabs(wk->sup[j])) &
           (j == 0 || wk->sub[j] == wk->sup[j - 1]);
}

/* The same with the right-hand side in wk->rhs and the solution into
 * wk->x, testing the system itself (one pass). */
static ekm_status solve(ekm_implicit_work *wk, int m, const char *what, ekm_error *err)
{
    int spd = 1;
    for (int i = 0; i < m; i++) {
        spd &= row_spd(wk, i);
        wk->x[i] = wk->rhs[i];
    }
    return solve_in(wk, m, spd, wk->x, what, err);
}

static double harmonic(double a, double b)
{
    return a > 0.0 && b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
}

/* Row i (face f = i + 1, cells f-1 below and f above) of the normal solve:
 * the implicit pressure coupling (implicit.h).  A following end face carries
 * F_end = phi_face_end w_end with w_end = the adjacent interior w: its
 * contribution joins the diagonal, kept >= 0 (so the column sums stay
 * >= rho_face). */
static void add_coupling(ekm_implicit_work *wk, int i, int n, double c, const ekm_implicit_coupling *cp,
                         ekm_implicit_end bottom, ekm_implicit_end top)
{
    const int f = i + 1;
    const double *K = cp->K, *pf = cp->phi_face;
    const double k_above = c * K[f], k_below = c * K[f - 1];
    double diag = (k_above + k_below) * pf[f];
    if (f == n - 1) { /* F_n */
        if (top.follows)
            diag = fmax(0.0, diag - k_above * pf[n]);
        else
            wk->rhs[i] += k_above * cp->flux_top;
    } else {
        wk->sup[i] -= k_above * pf[f + 1];
    }
    if (f == 1) { /* F_0 */
        if (bottom.follows)
            diag = fmax(0.0, diag - k_below * pf[0]);
        else
            wk->rhs[i] += k_below * cp->flux_bottom;
    } else {
        wk->sub[i] -= k_below * pf[f - 1];
    }
    wk->diag[i] += diag;
}

ekm_status ekm_implicit_normal_velocity(ekm_implicit_work *wk, int n, double dt, double dz,
                                        const double *rho_face, const double *rhs, const double *mu_n,
                                        const unsigned char *dry_face, ekm_implicit_end bottom,
                                        ekm_implicit_end top, const ekm_implicit_coupling *coupling,
                                        double *w, ekm_error *err)
{
    if (n < 2) {
        w[0] = bottom.follows ? 0.0 : bottom.value;
        w[n] = top.follows ? 0.0 : top.value;
        return EKM_OK;
    }
    const int m = n - 1; /* unknowns: faces 1..n-1 -> rows 0..m-1 */
    const double a = dt / (dz * dz);
    const double c = dt * a; /* dt^2/dz^2 [s^2/m^2] */
    for (int i = 0; i < m; i++) {
        const int f = i + 1;
        if (dry_face[f]) {
            wk->diag[i] = 1.0;
            wk->sub[i] = wk->sup[i] = wk->rhs[i] = 0.0;
            continue;
        }
        const double mu_below = mu_n[f - 1], mu_above = mu_n[f];
        wk->diag[i] = rho_face[f] + a * (mu_below + mu_above);
        wk->sub[i] = -a * mu_below;
        wk->sup[i] = -a * mu_above;
        wk->rhs[i] = rhs[f];
        if (f == 1) {
            if (bottom.follows)
                wk->diag[i] -= a * mu_below; /* no viscous stress difference in cell 0 */
            else
                wk->rhs[i] += a * mu_below * bottom.value;
            wk->sub[i] = 0.0;
        }
        if (f == n - 1) {
            if (top.follows)
                wk->diag[i] -= a * mu_above;
            else
                wk->rhs[i] += a * mu_above * top.value;
            wk->sup[i] = 0.0;
        }
        if (coupling)
            add_coupling(wk, i, n, c, coupling, bottom, top);
    }
    ekm_status st = solve(wk, m, "normal momentum", err);
    if (st != EKM_OK)
        return st;
    for (int i = 0; i < m; i++)
        w[i + 1] = wk->x[i];
    w[0] = bottom.follows ? w[1] : bottom.value;
    w[n] = top.follows ? w[n - 1] : top.value;
    return EKM_OK;
}

ekm_status ekm_implicit_shear_velocity(ekm_implicit_work *wk, int n, double dt, double dz, const double *rho,
                                       const double *rhs, const double *eta, const unsigned char *dry,
                                       ekm_implicit_end bottom, ekm_implicit_end top, double *u,
                                       ekm_error *err)
{
    const double a = dt / (dz * dz);
    const double b = dt / dz;
    double e_above = 0.0; /* the face viscosity above cell j - 1, once per face */
    int spd = 1;
    double *x = wk->x; /* the right-hand side, then the solution (u is left as it was on a failure) */
    for (int j = 0; j < n; j++) {
        const double e_below = e_above;
        e_above = j < n - 1 ? harmonic(eta[j], eta[j + 1]) : 0.0;
        if (dry[j]) {
            wk->diag[j] = 1.0;
            wk->sub[j] = wk->sup[j] = x[j] = 0.0;
        } else {
            wk->diag[j] = rho[j] + a * (e_below + e_above);
            wk->sub[j] = -a * e_below;
            wk->sup[j] = -a * e_above;
            x[j] = rhs[j];
            if (j == 0 && bottom.conductance > 0.0) {
                wk->diag[j] += b * eta[j] * bottom.conductance;
                x[j] += b * eta[j] * bottom.conductance * bottom.value;
            }
            if (j == n - 1 && top.conductance > 0.0) {
                wk->diag[j] += b * eta[j] * top.conductance;
                x[j] += b * eta[j] * top.conductance * top.value;
            }
        }
        spd &= row_spd(wk, j);
    }
    ekm_status st = solve_in(wk, n, spd, x, "shear momentum", err);
    if (st != EKM_OK)
        return st;
    for (int j = 0; j < n; j++)
        u[j] = x[j];
    return EKM_OK;
}

ekm_status ekm_implicit_shear_faces(ekm_implicit_work *wk, int n, double dt, double dz, const double *rho,
                                    const double *rhs, const double *k, const double *t0,
                                    const unsigned char *dry, double u_wall_bottom, double u_wall_top,
                                    double *u, ekm_error *err)
{
    const double b = dt / dz;
    int spd = 1;
    double *x = wk->x; /* the right-hand side, then the solution (u is left as it was on a failure) */
    for (int j = 0; j < n; j++) {
        if (dry[j]) {
            wk->diag[j] = 1.0;
            wk->sub[j] = wk->sup[j] = x[j] = 0.0;
        } else {
            wk->diag[j] = rho[j] + b * (k[j] + k[j + 1]);
            wk->sub[j] = j > 0 ? -b * k[j] : 0.0;
            wk->sup[j] = j < n - 1 ? -b * k[j + 1] : 0.0;
            x[j] = rhs[j] + b * (t0[j + 1] - t0[j]);
            if (j == 0)
                x[j] += b * k[0] * u_wall_bottom;
            if (j == n - 1)
                x[j] += b * k[n] * u_wall_top;
        }
        spd &= row_spd(wk, j);
    }
    ekm_status st = solve_in(wk, n, spd, x, "shear momentum", err);
    if (st != EKM_OK)
        return st;
    for (int j = 0; j < n; j++)
        u[j] = x[j];
    return EKM_OK;
}

void ekm_implicit_vapour_heating(ekm_source_coeffs *src, double phi, double phi_vacuum)
{
    if (phi_vacuum > 0.0 && phi < phi_vacuum) {
        const double f = phi > 0.0 ? phi / phi_vacuum : 0.0;
        src->k_heat_a *= f;
        src->k_heat_y *= f;
    }
}

ekm_status ekm_implicit_temperature(ekm_implicit_work *wk, int n, double dt, double dz, double rho_p,
                                    const double *phi, const double *rhoT_star, const double *lambda,
                                    const ekm_source_coeffs *src, const unsigned char *dry, double phi_vacuum,
                                    double T_floor, double tol, int newton_max, double *T, int *iterations,
                                    ekm_error *err)
{
    const double a = 2.0 / 3.0 * dt / (dz * dz);
    /* Face conductances (lagged); lam_face[j] is the face between cells
     * j-1 and j, zero at the (adiabatic) ends. */
    double *lam_face = wk->aux;
    lam_face[0] = 0.0;
    for (int j = 1; j < n; j++)
        lam_face[j] = phi_vacuum > 0.0 && (phi[j - 1] < phi_vacuum) != (phi[j] < phi_vacuum)
                          ? 0.0
                          : harmonic(lambda[j - 1], lambda[j]);
    lam_face[n] = 0.0;
    for (int it = 1; it <= newton_max; it++) {
        /* S and dS/dT of every cell first, without branches (a loop the
         * compiler vectorises; empty cells get values nobody reads), into
         * rhs (unused: the right-hand side goes to x) and diag, which the
         * assembly reads before it overwrites it */
        double *S_cell = wk->rhs, *dS_cell = wk->diag;
        for (int j = 0; j < n; j++)
            S_cell[j] = ekm_source_eval(&src[j], T[j], &dS_cell[j]);
        int spd = 1, restarted = 0;
        for (int j = 0; j < n; j++) {
            if (dry[j]) {
                wk->diag[j] = 1.0;
                wk->sub[j] = wk->sup[j] = wk->x[j] = 0.0;
                spd &= row_spd(wk, j);
                continue;
            }
            const double rho = rho_p * phi[j];
            double dS = dS_cell[j];
            double S = S_cell[j];
            const double l_below = lam_face[j], l_above = lam_face[j + 1];
            const double T_below = j > 0 ? T[j - 1] : 0.0;
            const double T_above = j < n - 1 ? T[j + 1] : 0.0;
            double residual = rho * T[j] - rhoT_star[j] -
                              a * (l_above * (T_above - T[j]) - l_below * (T[j] - T_below)) - dt * S;
            if (it == 1 && dt * fabs(dS) > 10.0 * rho) {
                /* the local balance, unless the guess already fits the
                 * cell's whole equation better (a bed near its steady
                 * state, where conduction balances the source: starting
                 * there from the local balance left Newton's last update
                 * as the error, 6e-6 relative in a dense Couette flow
                 * with steps of 1e-3 s) */
                const double Tb = fmax(ekm_source_balance(&src[j]), T_floor);
                double dSb;
                const double Sb = ekm_source_eval(&src[j], Tb, &dSb);
                const double rb = rho * Tb - rhoT_star[j] -
                                  a * (l_above * (T_above - Tb) - l_below * (Tb - T_below)) - dt * Sb;
                if (fabs(rb) < fabs(residual)) {
                    T[j] = Tb;
                    S = Sb;
                    dS = dSb;
                    residual = rb;
                }
            }
            double diag = rho + a * (l_below + l_above) - dt * dS;
            if (!(diag > 0.0)) {
                /* Left of the minimum of the cell's equation (heating
                 * faster than the step can follow: dt dS/dT > rho + the
                 * conduction's diagonal), where Newton would step down
                 * towards T = 0 and past the root.  Restart the cell at
                 * the top of its bracket: the root lies between
                 * T*' = (rho T* + conduction from the neighbours) / (rho
                 * + its diagonal) and the local balance S(Tb) = 0, and
                 * above max(T*', Tb) the source falls (dS/dT < 0), so the
                 * row is positive there and Newton descends to the root
                 * (docs/model/slab.md "Temperature step"). */
                const double T_cond = (rhoT_star[j] + a * (l_above * T_above + l_below * T_below)) /
                                      (rho + a * (l_below + l_above));
                const double Tt = fmax(fmax(ekm_source_balance(&src[j]), T_cond), T_floor);
                S = ekm_source_eval(&src[j], Tt, &dS);
                T[j] = Tt;
                residual = rho * Tt - rhoT_star[j] -
                           a * (l_above * (T_above - Tt) - l_below * (Tt - T_below)) - dt * S;
                diag = rho + a * (l_below + l_above) - dt * dS;
                restarted = 1; /* the rows before were linearised at the old T[j] */
            }
            wk->diag[j] = diag;
            wk->sub[j] = -a * l_below;
            wk->sup[j] = -a * l_above;
            wk->x[j] = -residual;
            spd &= row_spd(wk, j);
        }
        ekm_status st = solve_in(wk, n, spd, wk->x, "temperature", err);
        if (st != EKM_OK)
            return st;
        /* Newton converges quadratically: once a cell's relative update
         * |dT|/T is below sqrt(tol), its remaining error (~ update^2) is
         * below tol; from the second iteration on, the error estimated
         * with the contraction measured, |dT_k|^3 / |dT_{k-1}|^2 (an
         * update that did not shrink fails it), also counts (both tested
         * without a division). */
        const double limit = fmax(tol, sqrt(tol));
        int converged = !restarted;
        double finite = 0.0; /* 0, or NaN once an update is not finite */
        double *update = wk->update;
        for (int j = 0; j < n; j++) {
            const double Tj = T[j];
            /* Newton safeguard: never step to or below zero; approach the
             * (concave) root from below instead. */
            double Tn = Tj + wk->x[j];
            Tn = Tn > 0.1 * Tj ? Tn : 0.1 * Tj;
            Tn = Tn < T_floor ? T_floor : Tn;
            const double d = fabs(Tn - Tj);
            const int wet = !dry[j];
            const double d_prev = it > 1 ? update[j] : 0.0;
            update[j] = d;
            converged &= !wet || d < limit * Tn || (d <= d_prev && d * d * d < tol * Tn * d_prev * d_prev);
            finite += wet ? 0.0 * d : 0.0;
            T[j] = wet ? Tn : 0.0;
        }
        if (!isfinite(finite))
            return EKM_FAIL(err, EKM_ENUMERIC, "temperature: non-finite Newton update");
        if (converged) {
            *iterations = it;
            return EKM_OK;
        }
    }
    *iterations = newton_max;
    return EKM_FAIL(err, EKM_ENUMERIC, "temperature: Newton did not converge in %d iterations", newton_max);
}
