#include "control.h"

#include <math.h>

#include "bc.h"
#include "hypo.h"

static inline double max2(double a, double b)
{
    return a > b ? a : b;
}

/* u' [1/s] at face f of the state (walls: through the wall's conductance). */
static double face_shear_rate(const ekm_scenario *sc, const ekm_state *s, int f)
{
    const int n = s->n;
    if (f > 0 && f < n)
        return (s->u[f] - s->u[f - 1]) / s->dz;
    const ekm_bc_face bf =
        ekm_bc_evaluate(f == 0 ? &sc->bottom : &sc->top, f == 0 ? EKM_SIDE_BOTTOM : EKM_SIDE_TOP, s->t, s);
    return f == 0 ? (s->u[0] - bf.u_wall) * bf.wall_conductance
                  : (bf.u_wall - s->u[n - 1]) * bf.wall_conductance;
}

/* The largest relaxation rate of the hypoplastic law [1/s] over the solid
 * cells and their faces (each at its own rates and phi, as the step
 * integrates them), from the state at the start of the step: the rates the
 * step will lag its norm on. */
static double solid_relaxation_max(const ekm_scenario *sc, const ekm_state *s)
{
    const ekm_material *m = &sc->material;
    const int n = s->n;
    double relax = 0.0, du_below = face_shear_rate(sc, s, 0);
    for (int j = 0; j < n; j++) {
        const double du_above = face_shear_rate(sc, s, j + 1);
        if (s->solid[j] && s->phi[j] >= sc->numerics.phi_dry) {
            const double dw = (s->w[j + 1] - s->w[j]) / s->dz;
            const double phi = ekm_scenario_law_phi(sc, s->phi[j]);
            relax =
                max2(relax, ekm_hypo_relaxation_rate(m, sc->variant, phi, 0.5 * (du_below + du_above), dw));
            relax = max2(relax, ekm_hypo_relaxation_rate(m, sc->variant, phi, du_below, dw));
            relax = max2(relax, ekm_hypo_relaxation_rate(m, sc->variant, phi, du_above, dw));
        }
        du_below = du_above;
    }
    return relax;
}

/* Largest convective speed [m/s] (faces and inflows) and the largest EKM
 * sound speeds squared [m^2/s^2] of the flowing and of the solid cells,
 * and the cells that have them (-1 when none). */
typedef struct {
    double speed, c2_flow, c2_solid;
    int cell_speed, cell_flow, cell_solid; /* cell_speed: next to the fastest face */
} wave_speed_max;

/* flow_c2 = 0: the sound speed of the solid cells only (with the implicit
 * coupling the flowing cells' does not limit the step). */
static wave_speed_max wave_speeds(const ekm_scenario *sc, const ekm_state *s, int flow_c2)
{
    double v = 0.0;
    int cell_speed = -1;
    for (int f = 0; f <= s->n; f++)
        if (fabs(s->w[f]) > v) {
            v = fabs(s->w[f]);
            cell_speed = f < s->n ? f : f - 1;
        }
    if (sc->bottom.kind == EKM_BC_INFLOW && fabs(sc->bottom.w) > v) {
        v = fabs(sc->bottom.w);
        cell_speed = 0;
    }
    if (sc->top.kind == EKM_BC_INFLOW && fabs(sc->top.w) > v) {
        v = fabs(sc->top.w);
        cell_speed = s->n - 1;
    }
    wave_speed_max m = {.speed = v, .cell_speed = cell_speed, .cell_flow = -1, .cell_solid = -1};
    for (int j = 0; j < s->n; j++)
        if (s->phi[j] >= sc->numerics.phi_dry && (flow_c2 || s->solid[j])) {
            const double c2 = ekm_sound_speed_squared(&sc->material, s->phi[j], s->T[j]);
            double *c2_max = s->solid[j] ? &m.c2_solid : &m.c2_flow;
            if (c2 > *c2_max) {
                *c2_max = c2;
                *(s->solid[j] ? &m.cell_solid : &m.cell_flow) = j;
            }
        }
    return m;
}

/* The largest relaxation rate of the kinetic pressure [1/s] over the
 * flowing cells, eps P_K / (P_K + P_Y), and the cell that has it (-1: none). */
typedef struct {
    double rate;
    int cell;
} thermal_rate_max;

static thermal_rate_max thermal_rate(const ekm_scenario *sc, const ekm_state *s)
{
    const ekm_material *m = &sc->material;
    const double phi_dry = sc->numerics.phi_dry;
    thermal_rate_max th = {0.0, -1};
    /* ekm_thermal_relaxation_rate: cells without a rate get a harmless
     * state and are not counted, with no branch (the loop vectorises), then
     * the cell of the largest */
    for (int j = 0; j < s->n; j++) {
        const double phi = s->phi[j], T = s->T[j];
        const int has_rate = (phi >= phi_dry) & !s->solid[j] & (T > 0.0);
        const double Tp = has_rate ? T : 1.0, pp = has_rate ? phi : 0.5 * m->phi_cp;
        const double rate = ekm_thermal_relaxation_rate(m, pp, Tp);
        if (has_rate && rate > th.rate) {
            th.rate = rate;
            th.cell = j;
        }
    }
    return th;
}

/* cfl dz / (speed + sqrt(c2)), INFINITY when nothing moves. */
static double acoustic_dt(const ekm_scenario *sc, const ekm_state *s, double speed, double c2)
{
    return speed + sqrt(c2) > 0.0 ? sc->numerics.cfl * s->dz / (speed + sqrt(c2)) : INFINITY;
}

double ekm_control_max_dt(const ekm_scenario *sc, const ekm_state *s, ekm_dt_limit *why)
{
    return ekm_control_max_dt_known(sc, s, NULL, why);
}

double ekm_control_max_dt_known(const ekm_scenario *sc, const ekm_state *s, const ekm_thermal_known *known,
                                ekm_dt_limit *why)
{
    const int implicit = sc->numerics.normal_coupling == EKM_COUPLING_IMPLICIT;
    const wave_speed_max w = wave_speeds(sc, s, !implicit);
    /* Compression limit: predicted dphi/dt = -phi dw/dz must not close more
     * than half of phi_step_max of the gap to phi_cp in one step (the
     * step is rejected beyond phi_step_max; this avoids most rejections). */
    double rate_max = 0.0; /* largest compression rate relative to the gap [1/s] */
    int cell_rate = -1;
    const double phi_cp = sc->material.phi_cp;
    for (int j = 0; j < s->n; j++)
        if (s->phi[j] >= sc->numerics.phi_dry) {
            const double compression = -s->phi[j] * (s->w[j + 1] - s->w[j]) / s->dz;
            if (compression > 0.0 && compression / (phi_cp - s->phi[j]) > rate_max) {
                rate_max = compression / (phi_cp - s->phi[j]);
                cell_rate = j;
            }
        }
    /* Flowing cells: with the implicit pressure coupling (step.h) the sound
     * does not limit them, the convection (explicit upwind transport of
     * phi, u, T and the face momentum) does: cfl dz / max |w|.  With the
     * explicit coupling the acoustic CFL, cfl dz / max(|w| + c). */
    ekm_dt_limit lim = implicit
                           ? (ekm_dt_limit){"convective", w.cell_speed, acoustic_dt(sc, s, w.speed, 0.0)}
                           : (ekm_dt_limit){"acoustic", w.cell_flow, acoustic_dt(sc, s, w.speed, w.c2_flow)};
    /* Solid cells: their stress is implicit in the momentum solves (hypo.h),
     * so the EKM's sound speed does not limit them; the accuracy of the law's
     * lagged norm does (solid_relax_step, solid_relaxation_max).  Never
     * below the acoustic limit they had as flow cells: at that step the
     * linearly implicit law is accurate enough (and a cell flowing
     * plastically on the limit surface relaxes fast but to its fixed point). */
    if (w.c2_solid > 0.0) {
        const double relax = solid_relaxation_max(sc, s);
        const double dt_relax = relax > 0.0 ? sc->numerics.solid_relax_step / relax : INFINITY;
        const double dt_solid = fmax(dt_relax, acoustic_dt(sc, s, w.speed, w.c2_solid));
        if (dt_solid < lim.dt_s)
            lim = (ekm_dt_limit){"solid relaxation", w.cell_solid, dt_solid};
    }
    if (rate_max > 0.0 && 0.5 * sc->numerics.phi_step_max / rate_max < lim.dt_s)
        lim = (ekm_dt_limit){"compression", cell_rate, 0.5 * sc->numerics.phi_step_max / rate_max};
    /* Implicit coupling: the pressure takes T* of the step (before the
     * temperature solve), so the kinetic pressure P_K lags T by one step;
     * where T relaxes faster than dt and P_K is a sizable part of P that
     * lag feeds back through w and phi into the heating (simple shear at
     * phi 0.55 oscillated by 1 % in phi, never settling, at dt 10x its
     * relaxation time).  dt times the relaxation rate of P_K (eps of the
     * cell times P_K/(P_K + P_Y): the kinetic dissipation rate eps0 sqrt(T)
     * g at nu = 1) at most thermal_relax_step.  A cold dense bed (P_Y >>
     * P_K) is not limited: its pressure does not depend on T. */
    if (implicit) {
        const thermal_rate_max th =
            known ? (thermal_rate_max){known->rate, known->cell} : thermal_rate(sc, s);
        if (th.rate > 0.0 && sc->numerics.thermal_relax_step / th.rate < lim.dt_s)
            lim = (ekm_dt_limit){"thermal relaxation", th.cell, sc->numerics.thermal_relax_step / th.rate};
    }
    if (!(lim.dt_s < sc->numerics.dt_max)) /* also when nothing limits it (INFINITY) */
        lim = (ekm_dt_limit){"dt_max", -1, sc->numerics.dt_max};
    if (why)
        *why = lim;
    return lim.dt_s;
}

double ekm_control_thermal_rate(const ekm_scenario *sc, const ekm_state *s, int *cell)
{
    const thermal_rate_max th = thermal_rate(sc, s);
    if (cell)
        *cell = th.cell;
    return th.rate;
}

double ekm_control_acoustic_dt(const ekm_scenario *sc, const ekm_state *s)
{
    const wave_speed_max w = wave_speeds(sc, s, 1);
    return acoustic_dt(sc, s, w.speed, w.c2_flow);
}

double ekm_control_restart_dt(const ekm_scenario *sc, const ekm_state *s)
{
    const wave_speed_max w = wave_speeds(sc, s, 1);
    return fmin(acoustic_dt(sc, s, w.speed, max2(w.c2_flow, w.c2_solid)), ekm_control_max_dt(sc, s, NULL));
}

double ekm_control_target(const ekm_scenario *sc, double t, double t_next_out, int *at_event)
{
    /* Times the driving changes: the inflows close, the base starts to
     * tilt (and a piston reverses, below). */
    double events[3] = {INFINITY, INFINITY, INFINITY};
    if (sc->bottom.kind == EKM_BC_INFLOW)
        events[0] = sc->bottom.t_stop;
    if (sc->top.kind == EKM_BC_INFLOW)
        events[1] = sc->top.t_stop;
    if (sc->angle_rate != 0.0 && sc->angle_start > 0.0)
        events[2] = sc->angle_start;
    double t_target = t_next_out;
    *at_event = 0;
    for (int e = 0; e < 3; e++)
        if (events[e] > t * (1.0 + 1e-14) && events[e] < t_target)
            t_target = events[e];
    for (int e = 0; e < 3; e++)
        *at_event |= events[e] > t * (1.0 + 1e-14) && fabs(events[e] - t_target) <= 1e-12 * t_target;
    /* A piston reverses every half period: steps end there too. */
    const ekm_bc *pistons[2] = {&sc->bottom, &sc->top};
    for (int e = 0; e < 2; e++)
        if (pistons[e]->kind == EKM_BC_PISTON) {
            const double half = 0.5 * pistons[e]->period;
            double next = (floor(t / half + 1e-9) + 1.0) * half;
            if (next <= t_target * (1.0 + 1e-12)) {
                t_target = fmin(t_target, next);
                *at_event = 1;
            }
        }
    return t_target;
}
