/* flux.h: convective fluxes on the staggered grid, and the registry of
 * TVD limiters (Clawpack style: one signature, chosen by name).
 *
 * Cell quantities q (phi, u, T) are carried by the face volume flux
 * F_f = w_f phi_f [m/s]: the flux of q through face f is F_f q_f with q_f
 * the upwind value (first order) or the upwind value plus a limited slope
 * (second order TVD, van Leer's MUSCL form):
 *     q_f = q_up + psi(r)/2 (q_down - q_up),  r = (q_up - q_upup)/(q_down - q_up)
 * The face momentum (w at faces) is carried by the cell-centre fluxes
 * Fc_j = (F_j + F_{j+1})/2 with the upwind face velocity, which keeps the
 * face mass phi_face = (phi_{j-1} + phi_j)/2 exactly consistent with the
 * cell mass update.
 */
#ifndef EKM_FLUX_H
#define EKM_FLUX_H

#include "status.h"

/* psi(r): a TVD flux limiter. */
typedef double (*ekm_limiter_fn)(double r);

typedef struct {
    const char *name;
    ekm_limiter_fn psi;
} ekm_limiter;

/* Find a limiter by name; an unknown name is an error listing them all. */
ekm_status ekm_limiter_find(const char *name, const ekm_limiter **out, ekm_error *err);

/* Value of the cell array q (n cells) at interior face f (1..n-1) for flow
 * in the direction of `upward` (1: +z, 0: -z); psi NULL is first order. */
double ekm_flux_face_value(const double *q, int n, int f, int upward, ekm_limiter_fn psi);

/* qF_f = F_f q_f at every face f = 0..n.  At the boundary faces the
 * incoming value is q_in_bottom / q_in_top (used when F points into the
 * domain) and the adjacent cell value otherwise. */
void ekm_flux_advect(int n, const double *F, const double *q, double q_in_bottom, double q_in_top,
                     ekm_limiter_fn psi, double *qF);

/* Momentum flux of the face velocity w through the cell centres:
 * out_j = Fc_j w_up(j), Fc_j = (F_j + F_{j+1})/2, for j = 0..n-1. */
void ekm_flux_face_momentum(int n, const double *F, const double *w, double *out);

#endif
