#include "bc.h"

#include <math.h>

#include "model.h"

static int adjacent_cell(ekm_side side, const ekm_state *s)
{
    return side == EKM_SIDE_BOTTOM ? 0 : s->n - 1;
}

/* A wall; with shear_rate (top) its speed follows the gap L = n dz of the
 * state: velocity ([bottom] velocity, scenario.h) + shear_rate L. */
static ekm_bc_face bc_wall(const ekm_bc *bc, ekm_side side, const ekm_state *s)
{
    (void)side;
    ekm_bc_face b = {0};
    b.w = 0.0;
    b.wall_conductance = 1.0 / (0.5 * s->dz + bc->slip_length);
    b.u_wall = ekm_boundary_rate_wall(bc) ? bc->velocity + bc->shear_rate * s->n * s->dz : bc->velocity;
    return b;
}

static ekm_bc_face bc_inflow(const ekm_bc *bc, ekm_side side, const ekm_state *s)
{
    (void)side;
    (void)s;
    ekm_bc_face b = {0};
    b.w = bc->w;
    b.phi_in = bc->phi;
    b.u_in = bc->u;
    b.T_in = bc->T;
    return b;
}

static ekm_bc_face bc_outflow(const ekm_bc *bc, ekm_side side, const ekm_state *s)
{
    (void)bc;
    const int j = adjacent_cell(side, s);
    ekm_bc_face b = {0};
    b.w_follows = 1;
    b.phi_in = s->phi[j];
    b.u_in = s->u[j];
    b.T_in = s->T[j];
    return b;
}

static ekm_bc_face bc_free(const ekm_bc *bc, ekm_side side, const ekm_state *s)
{
    (void)bc;
    (void)side;
    (void)s;
    ekm_bc_face b = {0};
    b.w_follows = 1; /* vacuum outside: phi_in = 0, nothing enters */
    return b;
}

/* Piston: the face moves with w(t) = w in the first half of each period,
 * w_return (default -w) in the second; the material at the face follows it
 * (zero gradient of phi, u, T, as the face of a deforming sample); no slip. */
static ekm_bc_face bc_piston(const ekm_bc *bc, ekm_side side, const ekm_state *s, double t)
{
    const int j = adjacent_cell(side, s);
    ekm_bc_face b = {0};
    const double phase = t / bc->period - floor(t / bc->period);
    /* a step that ends exactly at a half period belongs to the half before it */
    const double w_return = isnan(bc->w_return) ? -bc->w : bc->w_return;
    b.w = phase < 0.5 - 1e-12 || phase > 1.0 - 1e-12 ? bc->w : w_return;
    b.phi_in = s->phi[j];
    b.u_in = s->u[j];
    b.T_in = s->T[j];
    b.wall_conductance = 1.0 / (0.5 * s->dz);
    return b;
}

typedef ekm_bc_face (*bc_fn)(const ekm_bc *, ekm_side, const ekm_state *);

static const bc_fn BC_KINDS[] = {
    [EKM_BC_WALL] = bc_wall, [EKM_BC_INFLOW] = bc_inflow, [EKM_BC_OUTFLOW] = bc_outflow,
    [EKM_BC_FREE] = bc_free, [EKM_BC_PISTON] = NULL, /* time-dependent: bc_piston */
};

ekm_bc_face ekm_bc_evaluate(const ekm_bc *bc, ekm_side side, double t, const ekm_state *s)
{
    if (bc->kind == EKM_BC_INFLOW && t >= bc->t_stop) {
        ekm_bc closed = *bc;
        closed.kind = EKM_BC_WALL;
        closed.velocity = 0.0;
        closed.slip_length = 0.0;
        return bc_wall(&closed, side, s);
    }
    if (bc->kind == EKM_BC_PISTON)
        return bc_piston(bc, side, s, t);
    return BC_KINDS[bc->kind](bc, side, s);
}

double ekm_bc_face_w(const ekm_bc_face *b, ekm_side side, const ekm_state *s)
{
    if (!b->w_follows)
        return b->w;
    if (s->n < 2)
        return 0.0;
    return side == EKM_SIDE_BOTTOM ? s->w[1] : s->w[s->n - 1];
}

/* dL/dt = rate L (-szz_top - P)/P with szz_top = -(P_K + P_Y) + mu_n (dL/dt
 * - w_{n-1})/dz of a flowing top cell (fields.h) taken at the end of the
 * step, linearised: its viscous term at the new dL/dt, and its equilibrium
 * pressure P_K + P_Y at the top cell's phi after the step, which the wall
 * compresses by dphi = phi dt (w_{n-1} - dL/dt)/dz (step.h), at the rate
 * d(P_K + P_Y)/dphi = rho_p c^2 (model.h: adiabatic, the compression heats
 * it).  Both are implicit in dL/dt: an explicit wall velocity is fed back
 * on itself through the top cell and oscillates at the step size once
 * rate L rho_p phi c^2 dt / (P dz) > 2 (dense cells near phi_co).  The rest
 * is taken at the start of the step; the steady state (dL/dt = w = 0,
 * P_K + P_Y = P) is the same. */
ekm_bc_top_cell ekm_bc_top_cell_load(const ekm_scenario *sc, double phi, double T, int solid, double szz,
                                     double w_below, double dz, double dt)
{
    if (solid)
        return (ekm_bc_top_cell){.load = -szz, .stiffness = 0.0};
    if (phi < sc->numerics.phi_dry)
        return (ekm_bc_top_cell){.load = 0.0, .stiffness = 0.0};
    const ekm_material *m = &sc->material;
    const ekm_transport c = ekm_transport_coefficients(m, sc->variant, phi, T);
    const double p_eq = ekm_pressure_kinetic(m, phi, T) + ekm_pressure_yield(m, phi);
    /* [Pa s]: the viscous and the compression response of szz_top to dL/dt */
    const double stiffness = c.mu_n + dt * m->rho_p * phi * ekm_sound_speed_squared(m, phi, T);
    return (ekm_bc_top_cell){.load = p_eq + stiffness * w_below / dz, .stiffness = stiffness};
}

double ekm_bc_gap_rate_of(const ekm_scenario *sc, ekm_bc_top_cell mean, int n, double dz)
{
    const double P = sc->top.pressure;
    const double k = sc->top.pressure_rate * n * dz / P; /* [m/(s Pa)] */
    return k * (mean.load - P) / (1.0 + k * mean.stiffness / dz);
}

double ekm_bc_gap_rate(const ekm_scenario *sc, const ekm_state *s, double dt)
{
    const int j = s->n - 1;
    const ekm_bc_top_cell top =
        ekm_bc_top_cell_load(sc, s->phi[j], s->T[j], s->solid[j], s->szz[j], s->w[j], s->dz, dt);
    return ekm_bc_gap_rate_of(sc, top, s->n, s->dz);
}
