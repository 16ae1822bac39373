/* surface2d.c: partly filled surface cells as dense material filling part
 * of the cell ([numerics] surface_fill = 1; docs/model/twod.md "Surface cells in 2D").
 *
 * A free surface cuts the top cell of a bed: grains at about the bed's
 * density fill the lower part of the cell, vacuum the rest. Read as an
 * EKM state, its mean phi (0.1-0.5) is a dilute gas: no yield pressure,
 * a gas's viscosity, and on a pile's flank such cells slide down as a
 * hot skin one cell thick (measured: 0.1-0.3 m/s at T about 3e-3 m^2/s^2
 * half a second after the inflow stopped). With surface_fill, a wet
 * flowing cell with phi < phi_co, an empty cell above (phi below
 * max(phi_vacuum, phi_dry), the vacuum rule's threshold: regime2d.c) and
 * a support below (the bottom wall, or a cell with phi >= phi_co) is read as
 * material of volume fraction phi_m filling the fraction f = phi/phi_m
 * of the cell, with the yield pressure of the weight it carries at its
 * base, where the cell's corners with the material below lie:
 *
 *   p_s   = rho_p phi |g_z| dz                               [Pa]
 *   phi_m = phi_cp (p_s + rho_p T0 phi_co) / (rho_p T0 phi_cp + p_s)
 *           (P_Y(phi_m) = p_s; phi_co < phi_m < phi_cp)
 *
 * Its shear viscosity is the material's, eta(phi_m, T) [Pa s]: the
 * corners it shares with flowing cells are at its base, inside the
 * material (the corners at its top touch the nearly empty cell above,
 * whose small viscosity the corner's harmonic mean takes). Its cell-mean quantities are f times the
 * material's: the normal viscosities mu_n, zeta and the eta of its normal stress [Pa s]
 * (step2d_impl.h's ekm2d_cell_mean_properties), the conductivity lambda [kg/(m s)], the heating; its
 * dissipation is rho_p phi eps(phi_m, T) T (eps from g(phi_m) and Y(phi_m)). Its pressure and dP/dphi stay
 * those of its own phi (P_K(phi, T)), so that its weight rests on the cell below as before (with f P(phi_m)
 * the face below would lose its pressure support as f -> 1). */
#include <math.h>

#include "step2d_impl.h"

/* phi_m of the material of a surface cell of mean volume fraction phi:
 * P_Y(phi_m) = the weight of the cell's grains per area of its base. */
static double material_phi(const ekm_material *m, double phi, double g_z, double dz)
{
    const double p_s = m->rho_p * phi * fabs(g_z) * dz;
    const double rT = m->rho_p * m->T0;
    return m->phi_cp * (p_s + rT * m->phi_co) / (rT * m->phi_cp + p_s);
}

/* (i, j) is a surface cell: wet, flowing, below phi_co, an empty cell
 * above, the bottom wall or a cell at phi_co or above below; 0 where a
 * neighbour lies outside the box phase 4 reached. */
static int surface_cell(const ekm2d_step *st, PetscInt i, PetscInt j)
{
    const ekm2d_grid *g = &st->g;
    if (BOX(st, dry, i, j) || BOX(st, phi_new, i, j) >= st->sc->material.phi_co ||
        (st->solid && BOX(st, solid, i, j)) || j + 1 >= g->nz || !ekm2d_cell_ok(g, i, j + 1) ||
        !(BOX(st, phi_new, i, j + 1) < fmax(st->sc->numerics.phi_vacuum, st->sc->numerics.phi_dry)))
        return 0;
    if (j == 0)
        return st->bottom.kind == EKM_BC_WALL && !ekm2d_open_face(g, &st->bottom, i);
    return ekm2d_cell_ok(g, i, j - 1) && !BOX(st, dry, i, j - 1) &&
           BOX(st, phi_new, i, j - 1) >= st->sc->material.phi_co;
}

void ekm2d_surface_properties(ekm2d_step *st)
{
    const ekm2d_grid *g = &st->g;
    const ekm_scenario *sc = st->sc;
    const ekm_material *m = &sc->material;
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++)
            BOX(st, fill, i, j) = 1.0;
    if (!sc->numerics.surface_fill)
        return;
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (!ekm2d_cell_ok(g, i, j) || !surface_cell(st, i, j))
                continue;
            const double phi = BOX(st, phi_new, i, j), T = BOX(st, T_star, i, j);
            const double phi_m = material_phi(m, phi, st->g_z, g->dz), f = phi / phi_m;
            const ekm_cell_properties mat = ekm_cell_properties_at(m, sc->variant, phi_m, T);
            ekm_cell_properties *p = &BOX(st, prop, i, j);
            p->g = mat.g;
            p->Y = mat.Y;
            p->eta = mat.eta;
            p->mu_n = f * mat.mu_n;
            p->zeta = f * mat.zeta;
            p->lambda = f * mat.lambda;
            BOX(st, fill, i, j) = f;
        }
}
