#include "flux.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static double psi_minmod(double r)
{
    return fmax(0.0, fmin(1.0, r));
}
static double psi_vanleer(double r)
{
    return (r + fabs(r)) / (1.0 + fabs(r));
}
static double psi_superbee(double r)
{
    return fmax(0.0, fmax(fmin(2.0 * r, 1.0), fmin(r, 2.0)));
}
static double psi_mc(double r)
{
    return fmax(0.0, fmin(fmin(2.0 * r, 0.5 * (1.0 + r)), 2.0));
}

static const ekm_limiter LIMITERS[] = {
    {"minmod", psi_minmod},
    {"vanleer", psi_vanleer},
    {"superbee", psi_superbee},
    {"mc", psi_mc},
};

ekm_status ekm_limiter_find(const char *name, const ekm_limiter **out, ekm_error *err)
{
    char list[128] = "";
    for (size_t i = 0; i < sizeof LIMITERS / sizeof LIMITERS[0]; i++) {
        if (strcmp(LIMITERS[i].name, name) == 0) {
            *out = &LIMITERS[i];
            return EKM_OK;
        }
        strncat(list, " ", sizeof list - strlen(list) - 1);
        strncat(list, LIMITERS[i].name, sizeof list - strlen(list) - 1);
    }
    return EKM_FAIL(err, EKM_EINPUT, "[numerics] limiter: unknown limiter '%s' (known:%s)", name, list);
}

double ekm_flux_face_value(const double *q, int n, int f, int upward, ekm_limiter_fn psi)
{
    const int up = upward ? f - 1 : f;
    const int down = upward ? f : f - 1;
    const int upup = upward ? f - 2 : f + 1;
    if (!psi || upup < 0 || upup >= n)
        return q[up];
    const double dq = q[down] - q[up];
    if (dq == 0.0)
        return q[up];
    const double r = (q[up] - q[upup]) / dq;
    return q[up] + 0.5 * psi(r) * dq;
}

void ekm_flux_advect(int n, const double *F, const double *q, double q_in_bottom, double q_in_top,
                     ekm_limiter_fn psi, double *qF)
{
    qF[0] = F[0] * (F[0] > 0.0 ? q_in_bottom : q[0]);
    qF[n] = F[n] * (F[n] < 0.0 ? q_in_top : q[n - 1]);
    for (int f = 1; f < n; f++)
        qF[f] = F[f] == 0.0 ? 0.0 : F[f] * ekm_flux_face_value(q, n, f, F[f] > 0.0, psi);
}

void ekm_flux_face_momentum(int n, const double *F, const double *w, double *out)
{
    for (int j = 0; j < n; j++) {
        const double Fc = 0.5 * (F[j] + F[j + 1]);
        out[j] = Fc * (Fc > 0.0 ? w[j] : w[j + 1]);
    }
}
