#include "steady_stop.h"

#include "closure.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FLOOR_PHI 1e-3 /* [-] */
#define FLOOR_U   1e-4 /* [m/s] */
#define FLOOR_T   1e-8 /* [m^2/s^2] */

ekm_status ekm_steady_stop_init(ekm_steady_stop *sd, int n, ekm_error *err)
{
    *sd = (ekm_steady_stop){.n = n, .t_prev = -1.0, .drift = NAN, .steady_since = NAN, .steady_time = NAN};
    sd->phi = calloc((size_t)n, sizeof *sd->phi);
    sd->u = calloc((size_t)n, sizeof *sd->u);
    sd->T = calloc((size_t)n, sizeof *sd->T);
    sd->mask = calloc((size_t)n, 1);
    if (!sd->phi || !sd->u || !sd->T || !sd->mask) {
        ekm_steady_stop_free(sd);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory allocating the steady-state test (%d cells)", n);
    }
    return EKM_OK;
}

void ekm_steady_stop_free(ekm_steady_stop *sd)
{
    free(sd->phi);
    free(sd->u);
    free(sd->T);
    free(sd->mask);
    free(sd->hist_t);
    free(sd->hist_v);
    sd->phi = sd->u = sd->T = sd->hist_t = sd->hist_v = NULL;
    sd->mask = NULL;
}

/* ||a - b|| / max(||a||, floor sqrt(count)) over the cells of mask. */
static double relative_change(const double *a, const double *b, const unsigned char *mask, int n,
                              double floor)
{
    double diff = 0.0, norm = 0.0;
    int count = 0;
    for (int j = 0; j < n; j++)
        if (mask[j]) {
            diff += (a[j] - b[j]) * (a[j] - b[j]);
            norm += a[j] * a[j];
            count++;
        }
    if (count == 0)
        return 0.0;
    return sqrt(diff) / fmax(sqrt(norm), floor * sqrt((double)count));
}

static ekm_status record(ekm_steady_stop *sd, double t, double v, ekm_error *err)
{
    if (sd->n_hist == sd->cap) {
        const size_t cap = sd->cap ? 2 * sd->cap : 64;
        double *ht = realloc(sd->hist_t, cap * sizeof *ht);
        if (!ht)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory in the steady-state test");
        sd->hist_t = ht;
        double *hv = realloc(sd->hist_v, cap * sizeof *hv);
        if (!hv)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory in the steady-state test");
        sd->hist_v = hv;
        sd->cap = cap;
    }
    sd->hist_t[sd->n_hist] = t;
    sd->hist_v[sd->n_hist] = v;
    sd->n_hist++;
    return EKM_OK;
}

ekm_status ekm_steady_stop_check(ekm_steady_stop *sd, const ekm_scenario *sc, const ekm_state *s, int *stop,
                                 ekm_error *err)
{
    const int n = s->n;
    const double phi_dry = sc->numerics.phi_dry;
    *stop = 0;
    double Q = 0.0, depth = 0.0; /* flow rate [m^2/s], sum phi dz [m] */
    for (int j = 0; j < n; j++)
        if (s->phi[j] >= phi_dry) {
            Q += s->phi[j] * s->u[j] * s->dz;
            depth += s->phi[j] * s->dz;
        }
    ekm_status rc = record(sd, s->t, depth > 0.0 ? Q / depth : 0.0, err);
    if (rc != EKM_OK)
        return rc;
    if (sd->t_prev >= 0.0 && s->t > sd->t_prev) {
        unsigned char *mask = sd->mask;
        for (int j = 0; j < n; j++)
            mask[j] = s->phi[j] >= phi_dry || sd->phi[j] >= phi_dry;
        const double dt = s->t - sd->t_prev;
        double change = relative_change(s->phi, sd->phi, mask, n, FLOOR_PHI);
        change = fmax(change, relative_change(s->u, sd->u, mask, n, FLOOR_U));
        if (sc->closure->has_temperature) /* else T is n/a (NAN) */
            change = fmax(change, relative_change(s->T, sd->T, mask, n, FLOOR_T));
        change = fmax(change, fabs(Q - sd->Q_prev) / fmax(fabs(Q), FLOOR_U * depth));
        sd->drift = change / dt;
        if (sd->drift < sc->steady_tol) {
            if (isnan(sd->steady_since))
                sd->steady_since = sd->t_prev;
            if (s->t - sd->steady_since >= sc->steady_window * (1.0 - 1e-12)) {
                sd->steady = 1;
                sd->steady_time = sd->steady_since;
                *stop = 1;
            }
        } else {
            sd->steady_since = NAN;
        }
    }
    memcpy(sd->phi, s->phi, (size_t)n * sizeof *sd->phi);
    memcpy(sd->u, s->u, (size_t)n * sizeof *sd->u);
    memcpy(sd->T, s->T, (size_t)n * sizeof *sd->T);
    sd->t_prev = s->t;
    sd->Q_prev = Q;
    return EKM_OK;
}

double ekm_steady_stop_acceleration(const ekm_steady_stop *sd, const ekm_scenario *sc)
{
    if (sd->n_hist < 2)
        return 0.0;
    const size_t last = sd->n_hist - 1;
    const double t_from = sd->hist_t[last] - sc->steady_window;
    size_t k = last;
    while (k > 0 && sd->hist_t[k - 1] >= t_from * (1.0 - 1e-12))
        k--;
    if (k == last)
        k = last - 1;
    return (sd->hist_v[last] - sd->hist_v[k]) / (sd->hist_t[last] - sd->hist_t[k]);
}
