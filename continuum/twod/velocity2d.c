/* velocity2d.c: phase 5 of the 2D step (step2d.h), the velocity system.
 *
 * Unknowns: vx on the x-faces, vz on the z-faces [m/s] (grid2d.h's dmv).
 * At each face f, with rho_f = rho_p (phi*_a + phi*_b)/2 of its two cells,
 *
 *   rho_f v_f - dt (div sigma_visc)_f - dt^2 (grad (K div(phi_up v)))_f
 *       = (rho_f v)*_f + dt rho_f g - dt (grad P*)_f
 *
 * (backward Euler; kg/(m^2 s) per row).  sigma_visc of the new velocities:
 *   cells:   sxx = mu_n exx + lam ezz,  szz = mu_n ezz + lam exx
 *            (mu_n = 4/3 eta + zeta, lam = zeta - 2/3 eta; thesis variant
 *            mu_n = lam = zeta: model.h's ekm_stress_plane without -P)
 *   corners: sxz = eta_c (dvx/dz + dvz/dx), eta_c the harmonic mean of the
 *            corner's four cells (none if one is empty); on a wall the
 *            slip rate over dz/2 + slip_length with the harmonic mean of its
 *            two cells; none at a free end, beside an inlet face or at the
 *            box's corners (ekm2d_corner_rate).
 * The last term is the 1D solver's implicit pressure coupling
 * (implicit.h) in 2D: the pressure at the end of the step linearised in
 * the next mass update, P** = P* + K (phi** - phi*), phi** - phi* =
 * -dt div(phi_up v), K = dP/dphi at (phi*, T*) (0 in empty cells), phi_up
 * the upwind phi* by the direction of the current v (the mean of the two
 * cells at v = 0); a prescribed end face's flux is known, a free end's
 * follows its interior face (its diagonal kept >= 0, as in 1D).
 * Faces of empty cells (mean phi* < phi_dry), side walls and prescribed
 * end faces are identity rows; a free end's face equals its interior
 * neighbour (zero normal rate in the end cell).  With x-derivatives zero
 * (a state uniform in x) the rows are the 1D normal and shear solves'.
 */
#include "step2d_impl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A linear form in the velocity unknowns: sum val_k v(col_k) + c. */
#define VFORM_MAX 24
typedef struct {
    int n;
    DMStagStencil col[VFORM_MAX];
    double val[VFORM_MAX];
    double c;
} vform;

static inline double harmonic(double a, double b)
{
    return a > 0.0 && b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
}

static inline int wet(const ekm2d_step *st, PetscInt i, PetscInt j)
{
    return ekm2d_cell_exists(&st->g, i, j) && !BOX(st, dry, i, j);
}

static inline double eta_of(const ekm2d_step *st, PetscInt i, PetscInt j)
{
    return wet(st, i, j) ? BOX(st, prop, i, j).eta : 0.0;
}

/* The velocity unknown at (loc, i, j), a periodic image wrapped. */
static DMStagStencil unknown(const ekm2d_step *st, DMStagStencilLocation loc, PetscInt i, PetscInt j)
{
    DMStagStencil s = {.loc = loc, .i = i, .j = j, .k = 0, .c = 0};
    (void)st;
    return s;
}

/* Add a v(loc, i, j) to f: a prescribed end face's vz (wall, inlet) and a
 * side wall's vx go into the constant; a free end's vz is its interior
 * neighbour's. */
static void vf_add(const ekm2d_step *st, vform *f, DMStagStencilLocation loc, PetscInt i, PetscInt j,
                   double a)
{
    const ekm2d_grid *g = &st->g;
    if (a == 0.0)
        return;
    if (loc == DMSTAG_LEFT && ekm2d_side_face(g, i))
        return;
    if (loc == DMSTAG_DOWN && (j == 0 || j == g->nz)) {
        const ekm2d_end *e = j == 0 ? &st->bottom : &st->top;
        if (ekm2d_open_face(g, e, i)) {
            j = j == 0 ? 1 : g->nz - 1;
        } else {
            f->c += a * ekm2d_end_face_w(g, e, i);
            return;
        }
    }
    for (int k = 0; k < f->n; k++)
        if (f->col[k].loc == loc && f->col[k].i == i && f->col[k].j == j) {
            f->val[k] += a;
            return;
        }
    f->col[f->n] = unknown(st, loc, i, j);
    f->val[f->n] = a;
    f->n++;
}

/* f += a * h */
static void vf_axpy(const ekm2d_step *st, vform *f, double a, const vform *h)
{
    for (int k = 0; k < h->n; k++)
        vf_add(st, f, h->col[k].loc, h->col[k].i, h->col[k].j, a * h->val[k]);
    f->c += a * h->c;
}

/* The corner viscosity of corner (i, j) (ekm2d_corner_eta); while the
 * velocity system is assembled, each corner's computed once (four rows
 * take it) and kept in eta_c for that assembly. */
static double corner_eta_of(const ekm2d_step *st, PetscInt i, PetscInt j)
{
    if (!st->assembly)
        return ekm2d_corner_eta(st, i, j, NULL, -1, -1, 0.0);
    const size_t k = ekm2d_box_index(&st->g, i, j);
    if (st->eta_c_stamp[k] != st->assembly) {
        st->eta_c[k] = ekm2d_corner_eta(st, i, j, NULL, -1, -1, 0.0);
        st->eta_c_stamp[k] = st->assembly;
    }
    return st->eta_c[k];
}

/* The corner (i, j)'s shear rate as a form, its viscosity into *eta (eta
 * NULL: not computed);
 * 0 where the corner carries none. */
static int corner_form(const ekm2d_step *st, PetscInt i, PetscInt j, vform *f, double *eta)
{
    const ekm2d_grid *g = &st->g;
    f->n = 0;
    f->c = 0.0;
    if (eta)
        *eta = 0.0;
    if (ekm2d_side_face(g, i)) {
        if (j == 0 || j == g->nz)
            return 0; /* a corner of the box: no velocity beside it moves */
        const PetscInt ic = i == 0 ? 0 : g->nx - 1;
        if (!wet(st, ic, j - 1) || !wet(st, ic, j))
            return 0;
        const double k = g->side_conductance[i == 0 ? 0 : 1];
        vf_add(st, f, DMSTAG_DOWN, ic, j, i == 0 ? k : -k);
        if (eta)
            *eta = corner_eta_of(st, i, j);
        return 1;
    }
    if (j == 0 || j == g->nz) {
        const ekm2d_end *e = j == 0 ? &st->bottom : &st->top;
        if (ekm2d_open_face(g, e, i - 1) || ekm2d_open_face(g, e, i) || ekm2d_inlet_face(g, e, i - 1) ||
            ekm2d_inlet_face(g, e, i))
            return 0;
        const PetscInt jc = j == 0 ? 0 : g->nz - 1;
        const double k = e->conductance;
        vf_add(st, f, DMSTAG_LEFT, i, jc, j == 0 ? k : -k);
        f->c += (j == 0 ? -k : k) * e->u_wall;
        if (eta)
            *eta = corner_eta_of(st, i, j);
        return 1;
    }
    if (!wet(st, i - 1, j - 1) || !wet(st, i, j - 1) || !wet(st, i - 1, j) || !wet(st, i, j))
        return 0;
    vf_add(st, f, DMSTAG_LEFT, i, j, 1.0 / g->dz);
    vf_add(st, f, DMSTAG_LEFT, i, j - 1, -1.0 / g->dz);
    vf_add(st, f, DMSTAG_DOWN, i, j, 1.0 / g->dx);
    vf_add(st, f, DMSTAG_DOWN, i - 1, j, -1.0 / g->dx);
    if (eta)
        *eta = corner_eta_of(st, i, j);
    return 1;
}

double ekm2d_corner_eta(const ekm2d_step *st, PetscInt i, PetscInt j, const double *eta_box, PetscInt oi,
                        PetscInt oj, double o_eta)
{
    const ekm2d_grid *g = &st->g;
    double eta[4];
    int solid[4], n = 0, n_flow = 0;
    for (PetscInt b = j - 1; b <= j; b++)
        for (PetscInt a = i - 1; a <= i; a++) {
            if (!ekm2d_cell_exists(g, a, b))
                continue;
            const int over = a == oi && b == oj;
            eta[n] = over ? o_eta : eta_box ? eta_box[ekm2d_box_index(g, a, b)] : eta_of(st, a, b);
            solid[n] = !over && st->n_solid && BOX(st, solid, a, b);
            if (!(eta[n] > 0.0))
                return 0.0;
            n_flow += !solid[n];
            n++;
        }
    if (n_flow > 0 && n_flow < n) { /* beside a solid cell: the flowing cells' (fields.h) */
        int m = 0;
        for (int q = 0; q < n; q++)
            if (!solid[q])
                eta[m++] = eta[q];
        n = m;
    }
    if (n == 1)
        return eta[0];
    if (n == 2)
        return harmonic(eta[0], eta[1]);
    double sum = 0.0;
    for (int q = 0; q < n; q++)
        sum += 1.0 / eta[q];
    return n / sum;
}

double ekm2d_corner_rate(const ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j, double *eta,
                         int *has)
{
    vform f;
    *has = corner_form(st, i, j, &f, eta);
    if (!*has)
        return 0.0;
    double rate = f.c;
    for (int k = 0; k < f.n; k++)
        rate += f.val[k] * u[f.col[k].j][f.col[k].i][f.col[k].loc == DMSTAG_LEFT ? st->g.s_vx : st->g.s_vz];
    return rate;
}

double ekm2d_cell_shear2(const ekm2d_step *st, PetscScalar ***u, PetscInt i, PetscInt j)
{
    double sum2 = 0.0;
    int count = 0, has;
    const PetscInt cn[4][2] = {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}};
    for (int q = 0; q < 4; q++) {
        const double rate = ekm2d_corner_rate(st, u, cn[q][0], cn[q][1], NULL, &has);
        if (has) {
            sum2 += rate * rate;
            count++;
        }
    }
    return count ? sum2 / count : 0.0;
}

/* The viscous normal stress (sxx if along_x, else szz) of cell (i, j) as a
 * form [Pa]; empty: none. */
static void normal_stress_form(const ekm2d_step *st, PetscInt i, PetscInt j, int along_x, vform *f)
{
    f->n = 0;
    f->c = 0.0;
    if (!wet(st, i, j))
        return;
    double a_x, a_z;
    if (st->n_solid && BOX(st, solid, i, j)) { /* the solid's stress (regime2d.c) */
        const ekm_hypo_implicit *c = &BOX(st, hyp, i, j);
        a_x = (along_x ? c->Vzz : c->Vxx) / st->g.dx;
        a_z = (along_x ? c->Vxx : c->Vzz) / st->g.dz;
        f->c = along_x ? c->Exx : c->Ezz;
    } else {
        const ekm_cell_properties p = ekm2d_cell_mean_properties(st, i, j);
        const double two_eta = st->sc->variant == EKM_VARIANT_THESIS ? 0.0 : 2.0 * p.eta;
        a_x = (along_x ? p.mu_n : p.mu_n - two_eta) / st->g.dx;
        a_z = (along_x ? p.mu_n - two_eta : p.mu_n) / st->g.dz;
    }
    vf_add(st, f, DMSTAG_LEFT, i + 1, j, a_x);
    vf_add(st, f, DMSTAG_LEFT, i, j, -a_x);
    vf_add(st, f, DMSTAG_DOWN, i, j + 1, a_z);
    vf_add(st, f, DMSTAG_DOWN, i, j, -a_z);
}

/* phi the next mass update carries through each face at the velocities
 * of the step's start (the upwind phi* by the sign of v, the mean at
 * v = 0; an end face: the inflow's phi_in when the flow enters), for
 * every face of the box whose cells phase 2 reached. */
static void coupling_phi(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
        for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
            if (j < g->nz && i > g->gx0 && !ekm2d_side_face(g, i) && ekm2d_cell_exists(g, i, j)) {
                const double v = u[j][i][g->s_vx], a = BOX(st, phi_new, i - 1, j), b = BOX(st, phi_new, i, j);
                BOX(st, pu_x, i, j) = v > 0.0 ? a : v < 0.0 ? b : 0.5 * (a + b);
            }
            if ((j == 0 || j == g->nz || j > g->gz0) && j <= g->nz &&
                ekm2d_cell_exists(g, i, j < g->nz ? j : g->nz - 1)) {
                const double v = u[j][i][g->s_vz];
                double p;
                if (j == 0)
                    p = v > 0.0 ? ekm2d_inlet_phi(g, &st->bottom, i) : BOX(st, phi_new, i, 0);
                else if (j == g->nz)
                    p = v < 0.0 ? ekm2d_inlet_phi(g, &st->top, i) : BOX(st, phi_new, i, j - 1);
                else { /* upwind by the velocity relative to the face (a moving top wall) */
                    const double a = BOX(st, phi_new, i, j - 1), b = BOX(st, phi_new, i, j);
                    const double v_rel = v - j * g->w_grid;
                    p = v_rel > 0.0 ? a : v_rel < 0.0 ? b : 0.5 * (a + b);
                }
                BOX(st, pu_z, i, j) = p;
            }
        }
}

/* div(phi_up v) of cell (i, j) as a form [1/s] (a side wall carries no
 * flux; a prescribed end face its known flux).  A moving top wall: the
 * walls carry none relative to the grid, and the grid's own part of the
 * interior faces' is left out (step.c: known, and 0 once the gap holds). */
static void divergence_form(const ekm2d_step *st, PetscInt i, PetscInt j, vform *f)
{
    const ekm2d_grid *g = &st->g;
    f->n = 0;
    f->c = 0.0;
    vf_add(st, f, DMSTAG_LEFT, i + 1, j, BOX(st, pu_x, i + 1, j) / g->dx);
    vf_add(st, f, DMSTAG_LEFT, i, j, -BOX(st, pu_x, i, j) / g->dx);
    if (!(g->top_moving && j + 1 == g->nz))
        vf_add(st, f, DMSTAG_DOWN, i, j + 1, BOX(st, pu_z, i, j + 1) / g->dz);
    if (!(g->top_moving && j == 0))
        vf_add(st, f, DMSTAG_DOWN, i, j, -BOX(st, pu_z, i, j) / g->dz);
}

/* Row (loc, i, j) = form f (its constant moved to the right-hand side); added
 * to the zeroed matrix, so that two periodic images of one unknown (nx = 2)
 * add up. */
/* Row `row` of the matrix (n entries at cols, added) and of the
 * right-hand side (b): DMStagMatSetValuesStencil's work without its
 * allocation per call (the local indices on the stack). */
static PetscErrorCode put_row(ekm2d_step *st, const DMStagStencil *row, PetscInt n, const DMStagStencil *cols,
                              const double *vals, double b)
{
    PetscInt ir, ic[VFORM_MAX];
    PetscCall(DMStagStencilToIndexLocal(st->g.dmv, 2, 1, row, &ir));
    PetscCall(DMStagStencilToIndexLocal(st->g.dmv, 2, n, cols, ic));
    PetscCall(MatSetValuesLocal(st->A, 1, &ir, n, ic, vals, ADD_VALUES));
    PetscCall(VecSetValuesLocal(st->Vb, 1, &ir, &b, INSERT_VALUES));
    return 0;
}

static PetscErrorCode set_row(ekm2d_step *st, DMStagStencilLocation loc, PetscInt i, PetscInt j,
                              const vform *f, double rhs)
{
    DMStagStencil row = unknown(st, loc, i, j);
    return put_row(st, &row, f->n, f->col, f->val, rhs - f->c);
}

/* f += a * (the shear stress of corner (i, j)): eta_c times its rate, or
 * at a solid corner the solid's sxz^n xz_scale + Vxz rate (regime2d.c). */
static void corner_stress(const ekm2d_step *st, vform *f, PetscInt i, PetscInt j, double a)
{
    vform h;
    double eta;
    if (!corner_form(st, i, j, &h, &eta))
        return;
    if (st->n_solid && BOX(st, solid_c, i, j)) {
        vf_axpy(st, f, a * BOX(st, hyp_c, i, j).Vxz, &h);
        f->c += a * BOX(st, t0_c, i, j);
    } else {
        vf_axpy(st, f, a * eta, &h);
    }
}

/* The momentum row of face (loc, i, j) with the two cells a (below or
 * left) and b beside it and the two corners c0, c1 at its ends. */
static PetscErrorCode momentum_row(ekm2d_step *st, DMStagStencilLocation loc, PetscInt i, PetscInt j,
                                   double dt)
{
    const ekm2d_grid *g = &st->g;
    const int along_x = loc == DMSTAG_LEFT;
    const PetscInt ia = along_x ? i - 1 : i, ja = along_x ? j : j - 1;
    const double phi_face = 0.5 * (BOX(st, phi_new, ia, ja) + BOX(st, phi_new, i, j));
    vform f = {0}, h;
    double rhs = 0.0;
    if (phi_face < st->sc->numerics.phi_dry) {
        vf_add(st, &f, loc, i, j, 1.0);
        return set_row(st, loc, i, j, &f, 0.0);
    }
    const double rho_f = st->sc->material.rho_p * phi_face;
    const double h_n = along_x ? g->dx : g->dz, h_t = along_x ? g->dz : g->dx;
    vf_add(st, &f, loc, i, j, rho_f);
    /* -dt d(s_nn)/dn between the cells */
    normal_stress_form(st, i, j, along_x, &h);
    vf_axpy(st, &f, -dt / h_n, &h);
    normal_stress_form(st, ia, ja, along_x, &h);
    vf_axpy(st, &f, dt / h_n, &h);
    /* -dt d(sxz)/dt between the corners */
    const PetscInt ci = along_x ? i : i + 1, cj = along_x ? j + 1 : j;
    corner_stress(st, &f, ci, cj, -dt / h_t);
    corner_stress(st, &f, i, j, dt / h_t);
    /* -dt^2 d(K div F)/dn: the coupling; a free end's diagonal share kept >= 0 */
    vform cpl = {0};
    divergence_form(st, i, j, &h);
    vf_axpy(st, &cpl, -dt * dt / h_n * BOX(st, K, i, j), &h);
    divergence_form(st, ia, ja, &h);
    vf_axpy(st, &cpl, dt * dt / h_n * BOX(st, K, ia, ja), &h);
    const int next_to_free = !along_x && ((j == 1 && ekm2d_open_face(g, &st->bottom, i)) ||
                                          (j == g->nz - 1 && ekm2d_open_face(g, &st->top, i)));
    for (int k = 0; next_to_free && k < cpl.n; k++)
        if (cpl.col[k].loc == loc && cpl.col[k].i == i && cpl.col[k].j == j && cpl.val[k] < 0.0)
            cpl.val[k] = 0.0;
    vf_axpy(st, &f, 1.0, &cpl);
    /* gravity and the pressure gradient of P* */
    const double P_a = BOX(st, prop, ia, ja).P, P_b = BOX(st, prop, i, j).P;
    rhs = (along_x ? BOX(st, rhs_x, i, j) : BOX(st, rhs_z, i, j)) +
          dt * (rho_f * (along_x ? st->g_x : st->g_z) - (P_b - P_a) / h_n);
    return set_row(st, loc, i, j, &f, rhs);
}

/* Identity row v(loc, i, j) = value. */
static PetscErrorCode fixed_row(ekm2d_step *st, DMStagStencilLocation loc, PetscInt i, PetscInt j,
                                double value)
{
    DMStagStencil row = unknown(st, loc, i, j);
    const double one = 1.0;
    return put_row(st, &row, 1, &row, &one, value);
}

/* A free end's face equals its interior neighbour: v_end - v_inner = 0. */
static PetscErrorCode follow_row(ekm2d_step *st, PetscInt i, PetscInt j, PetscInt j_inner)
{
    DMStagStencil rows[2] = {unknown(st, DMSTAG_DOWN, i, j), unknown(st, DMSTAG_DOWN, i, j_inner)};
    const double vals[2] = {1.0, -1.0};
    return put_row(st, rows, 2, rows, vals, 0.0);
}

static PetscErrorCode assemble(ekm2d_step *st, double dt)
{
    const ekm2d_grid *g = &st->g;
    st->assembly = ++st->assemblies;
    PetscCall(MatZeroEntries(st->A));
    for (PetscInt j = g->z0; j < g->z0 + g->nzl + (g->z0 + g->nzl == g->nz); j++)
        for (PetscInt i = g->x0; i < g->x0 + g->nxl + (!g->periodic && g->x0 + g->nxl == g->nx); i++) {
            if (j < g->nz) { /* x-face (i, j) */
                if (ekm2d_side_face(g, i))
                    PetscCall(fixed_row(st, DMSTAG_LEFT, i, j, 0.0));
                else
                    PetscCall(momentum_row(st, DMSTAG_LEFT, i, j, dt));
            }
            if (i < g->nx) { /* z-face (i, j) */
                if (j == 0 || j == g->nz) {
                    const ekm2d_end *e = j == 0 ? &st->bottom : &st->top;
                    if (ekm2d_open_face(g, e, i))
                        PetscCall(follow_row(st, i, j, j == 0 ? 1 : g->nz - 1));
                    else
                        PetscCall(fixed_row(st, DMSTAG_DOWN, i, j, ekm2d_end_face_w(g, e, i)));
                } else {
                    PetscCall(momentum_row(st, DMSTAG_DOWN, i, j, dt));
                }
            }
        }
    st->assembly = 0;
    PetscCall(MatAssemblyBegin(st->A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(st->A, MAT_FINAL_ASSEMBLY));
    PetscCall(VecAssemblyBegin(st->Vb));
    PetscCall(VecAssemblyEnd(st->Vb));
    return 0;
}

/* The solution into u's face slots over dmv's ghosted box. */
static PetscErrorCode copy_solution(ekm2d_step *st, PetscScalar ***u)
{
    const ekm2d_grid *g = &st->g;
    PetscInt x0, z0, nx, nz;
    const PetscScalar ***v;
    PetscCall(DMGlobalToLocal(g->dmv, st->V, INSERT_VALUES, st->Vl));
    PetscCall(DMStagGetGhostCorners(g->dmv, &x0, &z0, NULL, &nx, &nz, NULL));
    PetscCall(DMStagVecGetArrayRead(g->dmv, st->Vl, (void *)&v));
    for (PetscInt j = z0; j < z0 + nz; j++)
        for (PetscInt i = x0; i < x0 + nx; i++) {
            u[j][i][g->s_vx] = v[j][i][g->v_vx];
            u[j][i][g->s_vz] = v[j][i][g->v_vz];
        }
    PetscCall(DMStagVecRestoreArrayRead(g->dmv, st->Vl, (void *)&v));
    return 0;
}

int ekm2d_velocity_solve(ekm2d_step *st, PetscScalar ***u, double dt, ekm_error *err)
{
    PetscLogEventBegin(st->ev_v_asm, 0, 0, 0, 0);
    coupling_phi(st, u);
    const PetscErrorCode pe = assemble(st, dt);
    st->assembly = 0;
    PetscLogEventEnd(st->ev_v_asm, 0, 0, 0, 0);
    if (pe) {
        EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error assembling the velocity system");
        return -1;
    }
    KSPConvergedReason why;
    PetscLogEventBegin(st->ev_v_solve, 0, 0, 0, 0);
    const PetscErrorCode ps =
        ekm2d_kept_solve(st->ksp_v, &st->v_keep_factor, &st->v_refactors, st->Vb, st->V, &why);
    PetscLogEventEnd(st->ev_v_solve, 0, 0, 0, 0);
    if (ps) {
        EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error solving the velocity system");
        return -1;
    }
    if (why < 0) {
        snprintf(st->reason, sizeof st->reason, "t = %.9g s, dt = %.3g s: the velocity solve failed (%s)",
                 st->t, dt, KSPConvergedReasons[why]);
        return 0;
    }
    if (copy_solution(st, u)) {
        EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error copying the velocities");
        return -1;
    }
    ekm2d_regime_vacuum(st, u);
    return 1;
}
