/* implicit.h: the implicit (backward Euler) parts of a time step, each a
 * tridiagonal solve with LAPACK (dptsv where the system is symmetric and
 * diagonally dominant, else dgtsv; nothing is allocated per solve):
 *
 *   normal momentum   rho_f w_f - dt d/dz(mu_n dw/dz)
 *                     - dt^2 d/dz(K d/dz(phi w))          = rho_f w**_f  (faces)
 *   shear momentum    rho_j u_j - dt d/dz(eta du/dz)       = (rho u)*_j   (cells)
 *   temperature       rho_j T_j - dt 2/3 d/dz(lambda dT/dz) - dt S_j(T_j)
 *                                                          = (rho T)*_j   (cells)
 *
 * so that the viscosities (up to 1e7 Pa s and beyond in a quasi-static bed),
 * the conduction and the stiff temperature source never limit the time
 * step.  The temperature equation is nonlinear in S (the yield viscosity
 * ~ 1/sqrt(T)); it is solved by Newton's method with the conductivities
 * lagged.  Transport coefficients at faces are harmonic means of the two
 * cells (series resistances; zero next to an empty cell).
 */
#ifndef EKM_IMPLICIT_H
#define EKM_IMPLICIT_H

#include "model.h"
#include "status.h"

typedef struct {
    int n;                              /* cells */
    double *diag, *sub, *sup, *rhs, *x; /* the system and its solution, n + 1 each */
    double *aux;                        /* face conductances of the temperature solve, n + 1 */
    double *update; /* |dT| of each cell in the last Newton iteration of the temperature solve, n + 1 */
} ekm_implicit_work;

ekm_implicit_work *ekm_implicit_alloc(int n);
void ekm_implicit_free(ekm_implicit_work *wk);

/* Solve the m x m (m <= n + 1) tridiagonal system held in wk (diag, sub[i]
 * coupling row i to i-1, sup[i] to i+1) with the right-hand side x, into
 * x; spd != 0: the system is symmetric with a positive diagonal and weakly
 * diagonally dominant (dptsv), else dgtsv. The system is overwritten.
 * `what` names the solve in the error message (EKM_ENUMERIC: singular). */
ekm_status ekm_implicit_solve(ekm_implicit_work *wk, int m, int spd, double *x, const char *what,
                              ekm_error *err);

/* Boundary data of a velocity solve at one end. */
typedef struct {
    int follows;        /* normal solve: w_b = adjacent interior w (zero gradient) */
    double value;       /* normal solve: prescribed w_b [m/s]; shear: wall velocity [m/s] */
    double conductance; /* shear solve: 1/(dz/2 + slip length), 0: stress-free [1/m] */
} ekm_implicit_end;

/* The implicit pressure coupling of the normal solve (docs/model/slab.md,
 * "Implicit pressure coupling"): the pressure of cell j at the end of the
 * step, linearised in the next mass update,
 *   P**_j = P*_j + K_j (phi**_j - phi*_j),  phi**_j - phi*_j = -dt/dz (F_{j+1} - F_j),
 *   F_f = phi_face_f w_f (interior faces, and an end whose w follows),
 *   F_end = flux (an end with prescribed w),
 * adds dt/dz (P**_f - P**_{f-1}) - dt/dz (P*_f - P*_{f-1}) to face f's row:
 * the tridiagonal terms c (K_f + K_{f-1}) phi_face_f w_f - c K_f phi_face_{f+1}
 * w_{f+1} - c K_{f-1} phi_face_{f-1} w_{f-1}, c = dt^2/dz^2.  Every
 * interior column then has the sum rho_face > 0 (diagonal minus
 * off-diagonals).  At an end whose w follows, the column of the face next
 * to it sums to rho_face - c K_end (phi_face_end - phi_face_inner) when the
 * end's phi is the larger, which is negative at large enough dt: there the
 * system need not be diagonally dominant; dgtsv (partial pivoting) solves
 * it, and a singular one fails the solve, which rejects the step (retried
 * with half of it, restoring dominance). */
typedef struct {
    const double *K;        /* dP/dphi at cells [Pa], n; 0 where P is not a function of phi (solid, empty) */
    const double *phi_face; /* volume fraction the next mass update carries through each face [-], n+1 */
    double flux_bottom;     /* F_0 of a prescribed bottom face [m/s] (along +z, as F) */
    double flux_top;        /* F_n of a prescribed top face [m/s] (along +z) */
} ekm_implicit_coupling;

/* Normal velocity at the interior faces 1..n-1 (w[0], w[n] are set from
 * the ends).  rho_face [kg/m^3] and rhs = rho_face w** [kg/(m^2 s)] at
 * faces (w** with the explicit pressure gradient of P*), mu_n [Pa s] at
 * cells; faces with dry[f] != 0 get w = 0.  coupling NULL: the pressure
 * stays explicit (the explicit scheme, [numerics] normal_coupling =
 * explicit). */
ekm_status ekm_implicit_normal_velocity(ekm_implicit_work *wk, int n, double dt, double dz,
                                        const double *rho_face, const double *rhs, const double *mu_n,
                                        const unsigned char *dry_face, ekm_implicit_end bottom,
                                        ekm_implicit_end top, const ekm_implicit_coupling *coupling,
                                        double *w, ekm_error *err);

/* Tangential velocity at the cells; rho [kg/m^3], rhs = (rho u)* + dt rho g_x
 * [kg/(m^2 s)], eta [Pa s]; dry cells get u = 0. */
ekm_status ekm_implicit_shear_velocity(ekm_implicit_work *wk, int n, double dt, double dz, const double *rho,
                                       const double *rhs, const double *eta, const unsigned char *dry,
                                       ekm_implicit_end bottom, ekm_implicit_end top, double *u,
                                       ekm_error *err);

/* Tangential velocity with face stresses tau_f = k_f (u_j - u_{j-1}) + t0_f
 * (interior faces f = 1..n-1, u_j the cell above the face), tau_0 =
 * k_0 (u_0 - u_wall_bottom) + t0_0, tau_n = k_n (u_wall_top - u_{n-1}) + t0_n:
 *   rho_j u_j - dt/dz (tau_{j+1} - tau_j) = rhs_j.
 * k [kg/(m^2 s)] and t0 [Pa] at the n + 1 faces (k = viscosity / distance;
 * a solid face: k = its rate-law stiffness dt f B_h / dz, t0 its known
 * stress).  The solid regime's form of the shear solve (its coefficients:
 * ekm_regime_shear_faces, regime.h). */
ekm_status ekm_implicit_shear_faces(ekm_implicit_work *wk, int n, double dt, double dz, const double *rho,
                                    const double *rhs, const double *k, const double *t0,
                                    const unsigned char *dry, double u_wall_bottom, double u_wall_top,
                                    double *u, ekm_error *err);

/* Temperature equation, Newton's method.  phi [-] (new), rhoT_star
 * [kg/(m s^2)] after convection, lambda [kg/(m s)] lagged, src the source
 * coefficients of each cell (model.h); T holds the initial guess on entry
 * and the solution on success.  Where the source relaxes much faster than
 * dt (quasi-static beds), the guess is replaced by the local balance
 * S(T) = 0.  A cell has converged when its error after the iteration,
 * estimated from Newton's quadratic convergence, is below tol relative:
 * |dT_k| < sqrt(tol) T (error ~ dT_k^2), or, once the updates contract,
 * |dT_k|^3 / |dT_{k-1}|^2 < tol T (error ~ C dT_k^2 with C ~ |dT_k| /
 * |dT_{k-1}|^2 measured).  phi_vacuum > 0: a face between a cell below
 * phi_vacuum and a cell at or above it conducts nothing (the vacuum rule:
 * a dilute "vapour" over a free surface, whose kinetic conductivity does
 * not fall with phi, would heat the surface for ever; docs/model/slab.md
 * "Surface cells in 2D"); 0: off.  Returns EKM_ENUMERIC when Newton does
 * not converge in newton_max iterations (the caller retries with a
 * smaller step). */
/* The vacuum rule's heating ([numerics] phi_vacuum > 0): a cell below
 * phi_vacuum (a Knudsen "vapour": its mean free path, about d/phi, is
 * longer than the cell) heats by phi/phi_vacuum times the kinetic heating
 * (k_heat_a and k_heat_y scaled; the dissipation k_diss, proportional to
 * phi, kept), so that its balance temperature under a given shear rate is
 * that of a cell at phi_vacuum instead of growing as 1/phi (the kinetic
 * viscosities do not vanish with phi; docs/model/twod.md "Vapour cells").
 * Unchanged at or above phi_vacuum and with phi_vacuum = 0. */
void ekm_implicit_vapour_heating(ekm_source_coeffs *src, double phi, double phi_vacuum);

ekm_status ekm_implicit_temperature(ekm_implicit_work *wk, int n, double dt, double dz, double rho_p,
                                    const double *phi, const double *rhoT_star, const double *lambda,
                                    const ekm_source_coeffs *src, const unsigned char *dry, double phi_vacuum,
                                    double T_floor, double tol, int newton_max, double *T, int *iterations,
                                    ekm_error *err);

#endif
