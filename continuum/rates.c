/* rates.c: shear rates at cells (rates.h). */
#include "rates.h"

void ekm_rates_shear(const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                     const unsigned char *dry, double *u2, double *w2)
{
    const int n = s->n;
    const double inv_dz = 1.0 / s->dz;
    /* the squared gradient at the face below cell j, carried to the next
     * cell (each face once) */
    double below = 0.0;
    int has_below = 0;
    if (bb->wall_conductance > 0.0) {
        const double g = (s->u[0] - bb->u_wall) * bb->wall_conductance;
        below = g * g;
        has_below = 1;
    }
    for (int j = 0; j < n; j++) {
        double sum = has_below ? below : 0.0;
        int count = has_below;
        if (j < n - 1) {
            const double g = (s->u[j + 1] - s->u[j]) * inv_dz;
            below = g * g;
            has_below = !dry[j];
            if (!dry[j + 1]) {
                sum += below;
                count++;
            }
        } else if (bt->wall_conductance > 0.0) {
            const double g = (bt->u_wall - s->u[n - 1]) * bt->wall_conductance;
            sum += g * g;
            count++;
        }
        u2[j] = count == 2 ? 0.5 * sum : sum;
        const double dw = (s->w[j + 1] - s->w[j]) * inv_dz;
        w2[j] = dw * dw;
    }
}
