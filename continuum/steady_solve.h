/* steady_solve.h: the steady state of a slab scenario by Newton's method on
 * the discrete steady equations of the time stepper (step.h), globalised
 * by pseudo-transient continuation (docs/model/steady.md "Steady solver").
 *
 * The steady state is the fixed point of ekm_step_apply with w = 0 on every
 * face: phi is then unchanged by the mass update, and
 *
 *   faces f = 1..n-1 joined (phi_face >= phi_dry):
 *       (P_f - P_{f-1}) / dz - rho_p phi_face g_z = 0
 *   each run of cells joined by such faces keeps its mass (the cumulative
 *       volume up to the run's top cell is that of the guess)
 *   cells (non-empty): the shear solve's operator with rho g_x,
 *       (e_{j+1/2} (u_{j+1} - u_j) - e_{j-1/2} (u_j - u_{j-1})) / dz^2
 *       + eta_j k_wall (u_wall - u_j) / dz + rho_j g_x = 0  (walls)
 *   cells (non-empty): the temperature Newton residual of
 *       ekm_implicit_temperature with (rho T)* = rho T,
 *       2/3 (l_{j+1/2} (T_{j+1} - T_j) - l_{j-1/2} (T_j - T_{j-1})) / dz^2
 *       + S_j(T_j) = 0
 *   empty cells (phi < phi_dry): u = T = 0
 *   a pressure-controlled top wall: P_K + P_Y of the top cell = pressure,
 *       the gap L = n dz an unknown
 *
 * with P = P_K + P_Y, eta, lambda (harmonic means at faces) and the
 * source S of model.h at (phi, T) and the wall data of bc.h.  Unknowns per
 * cell j: the cumulative phi from the top c_j = sum_{i>=j} phi_i (so each
 * run's mass is a one-entry row, and a dilute tail's phi keeps its digits;
 * with a pressure wall from the base, sum_{i<=j}, the top cell's row the
 * wall pressure), u_j relative to the guess's top wet cell, ln T_j, and
 * with a pressure wall a copy dz_j of the cell height (rows dz_j =
 * dz_{j+1}, the volume row dz c_{n-1} = V at the top): the Jacobian is
 * banded (kl = ku = 3 nv - 1 with nv = 3 or 4 unknowns per cell), computed
 * by finite differences with column grouping (kl + ku + 1 residual
 * evaluations) and factorised by LAPACK dgbtrf.  Every cell with phi >=
 * phi_dry is an unknown (no film is merged away).  The set of empty cells
 * and faces is frozen from the guess and checked at the end (changed: a
 * new Newton solve from the solution; a dilute tail's fringe, phi < 1e-6,
 * keeps its frozen kind, and the tail grows until the face above its top
 * is empty).  On an incline the second attempt, and the time steps
 * between later ones, start from the local (Bagnold) flow of the guess's
 * mass.
 *
 * Converged: the scaled residual (each row over the sum of its terms'
 * magnitudes) below EKM_STEADY_RES_TOL and the last Newton update below
 * EKM_STEADY_UPDATE_TOL relative.  Verified: time steps of ekm_step_apply
 * at the step limit (control.h) from the solution, at least
 * EKM_STEADY_VERIFY_STEPS of them and at least EKM_STEADY_VERIFY_FLOW_TIMES
 * times the gap over the velocity scale of model time, change each of
 * phi, vx, T, the volume flux w phi and the gap by less than
 * EKM_STEADY_VERIFY_TOL in the max norm relative to the field's scale
 * (verify in steady_solve.c; docs/model/steady.md "Steady solver").
 */
#ifndef EKM_STEADY_SOLVE_H
#define EKM_STEADY_SOLVE_H

#include <stdio.h>

#include "scenario.h"
#include "state.h"
#include "status.h"

#define EKM_STEADY_MAX_ITER     1000 /* Newton (continuation) iterations, all attempts */
#define EKM_STEADY_ATTEMPT_ITER 60   /* ... of one attempt */
#define EKM_STEADY_ATTEMPTS     12   /* attempts (the first from the guess) */
#define EKM_STEADY_WARM_SPAN0                                                                       \
    0.25                                   /* model time stepped before the second attempt, doubled \
                                            * before each further one (at most [run] t_end in all) [s] */
#define EKM_STEADY_RES_TOL           1e-9  /* scaled residual, max norm [-] */
#define EKM_STEADY_UPDATE_TOL        1e-10 /* relative Newton update, max norm [-] */
#define EKM_STEADY_VERIFY_STEPS      200   /* least time steps of the verification */
#define EKM_STEADY_VERIFY_FLOW_TIMES 10.0  /* least model time of it, in gap / velocity scale [-] */
#define EKM_STEADY_VERIFY_MAX_STEPS  2000  /* most time steps of it */
#define EKM_STEADY_VERIFY_TOL        1e-9  /* max-norm relative change of each field over them [-] */

typedef struct {
    FILE *progress;   /* input: NULL, or a stream for one line per Newton iteration (kept by the solve) */
    int iterations;   /* Newton iterations (all solves) */
    int dry_resolves; /* new solves after the empty set changed */
    int attempts;     /* Newton attempts (1: from the guess) */
    int local_guess;  /* 1: an attempt started from the local (Bagnold) flow of an incline, 2: from the
                       * homogeneous shear of plane Couette flow (the first attempt) */
    double warm_time; /* model time stepped between attempts [s] */
    long warm_steps;  /* time steps taken then */
    double residual[EKM_STEADY_MAX_ITER]; /* scaled residual before each iteration [-] */
    double delta[EKM_STEADY_MAX_ITER];    /* pseudo-time step of each iteration [-] */
    double residual_final;                /* scaled residual at the solution [-] */
    double update_final;                  /* last relative Newton update [-] */
    double verify_change;                 /* largest of verify_field [-] */
    double verify_field[5];               /* max-norm relative change of phi, u, T, w phi, gap over it [-] */
    int verify_steps;                     /* time steps of the (last) verification */
    double verify_time;                   /* model time the verification stepped [s] */
    double gap;                           /* n dz at the solution [m] */
    double wall_s;                        /* wall-clock time of the solve [s] */
} ekm_steady_report;

/* The scenario can have a steady state the solver can find: EKM_EINPUT
 * naming the key otherwise ([hypo] enabled, a tilting base, an inflow,
 * outflow or piston end). */
ekm_status ekm_steady_supported(const ekm_scenario *sc, ekm_error *err);

/* Solve: s holds the guess (same cells as sc; phi, u, T, dz) on entry and
 * the verified steady state on success (w = 0, t and steps unchanged).
 * EKM_ENOTSTEADY with "SOURCE: no steady state: REASON" when Newton does
 * not converge, the Jacobian is singular, phi leaves [0, phi_cp), a value
 * is not finite or the time stepper moves away from the solution; then s
 * holds the last iterate. rep may be NULL; rep->progress is read on entry,
 * every other field is set. */
ekm_status ekm_steady_solve(const ekm_scenario *sc, ekm_state *s, ekm_steady_report *rep, ekm_error *err);

#endif
