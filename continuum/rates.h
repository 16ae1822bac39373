/* rates.h: the shear rates of a slab state at its cells, from the face
 * gradients of its velocities; shared by the time step (step.h), its solid
 * regime (regime.h) and the steady solver (steady_solve.h).
 */
#ifndef EKM_RATES_H
#define EKM_RATES_H

#include "bc.h"
#include "state.h"

/* Squared shear rate u2 at cells from the face gradients of u (faces next
 * to an empty cell, dry != 0, or a stress-free end carry none) and w2 = w'^2
 * [1/s^2], n each. */
void ekm_rates_shear(const ekm_state *s, const ekm_bc_face *bb, const ekm_bc_face *bt,
                     const unsigned char *dry, double *u2, double *w2);

#endif
