/* fields.h: the cell-centred output fields of a state (what ekm writes):
 *   vx = u;  vz = (w_{j-1/2} + w_{j+1/2})/2;
 *   sxz = mean of the two face shear stresses eta_f du/dz (walls: the wall
 *         stress, stress-free ends: 0; eta_f: ekm_face_viscosity);
 *   szz = -(P_K + P_Y) + mu_n dw/dz;  P = P_K + P_Y - zeta dw/dz;
 *   solid cells: szz, P from their stress state, sxz the mean of their two
 *         face stresses (hypo.h);
 *   regime = 0 empty (phi < phi_dry), 1 kinetic (phi <= phi_co),
 *            2 dense flow (phi > phi_co), 3 solid (hypoplastic).
 */
#ifndef EKM_FIELDS_H
#define EKM_FIELDS_H

#include "scenario.h"
#include "state.h"

enum { EKM_REGIME_EMPTY = 0, EKM_REGIME_KINETIC = 1, EKM_REGIME_DENSE = 2, EKM_REGIME_SOLID = 3 };

typedef struct {
    double *vx, *vz;       /* [m/s] */
    double *P, *sxz, *szz; /* [Pa] */
    int *regime;           /* EKM_REGIME_* */
} ekm_fields;

/* Viscosity of the face between cells a and b for the flow law's face
 * shear stress eta_f du/dz: the harmonic mean of two flowing cells; next to
 * a solid cell the flowing cell's own (a solid cell has no viscosity: its
 * frozen T gives a meaningless one); 0 next to an empty cell (eta = 0). */
double ekm_face_viscosity(double eta_a, int solid_a, double eta_b, int solid_b);

/* Arrays of n each, owned by the caller. The EKM's state; a state of the
 * dense slab solver (mu_i) has its own (local_slab.h; ekm_slab_fields
 * there takes either). */
void ekm_fields_compute(const ekm_scenario *sc, const ekm_state *s, double t, ekm_fields *out);

#endif
