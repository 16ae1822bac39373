/* control.h: the step-size control of the time loop (GSL's step / control /
 * evolve split: step.h advances the state by a given dt, this module
 * chooses dt and where a step must end, run.h drives the loop).
 *
 *   dt limit     flowing cells: [numerics] normal_coupling = implicit (the
 *                default) cfl dz / max |w| (the convective CFL: the
 *                pressure coupling is implicit, step.h), = explicit
 *                cfl dz / max(|w| + c) (the acoustic CFL); implicit
 *                coupling also: dt times the relaxation rate of the
 *                kinetic pressure, eps P_K/(P_K + P_Y), at most
 *                [numerics] thermal_relax_step (the pressure of a step
 *                lags its temperature solve); solid cells
 *                by the accuracy of the rate law's lagged norm
 *                ([numerics] solid_relax_step, never below their own
 *                acoustic step); the compression limit (half of
 *                phi_step_max of the gap to phi_cp per step); dt_max
 *   restart      after a change of the driving the acoustic step over every
 *                cell, solid ones included (run.h grows it 1.5x per step)
 *   events       the driving changes when an inflow closes (t_stop), the
 *                base starts tilting (angle_start) and a piston reverses
 *                (every half period): steps end exactly there
 */
#ifndef EKM_CONTROL_H
#define EKM_CONTROL_H

#include "scenario.h"
#include "state.h"

/* Which limit set the step, and where: for the diagnostic of a run whose
 * step limit fell below dt_min (run.c). */
typedef struct {
    const char *limit; /* "convective", "acoustic", "thermal relaxation", "solid relaxation",
                        * "compression" or "dt_max" */
    int cell;          /* the cell that set it, -1 for dt_max */
    double dt_s;       /* the limit [s] */
} ekm_dt_limit;

/* Largest step for the state: cfl dz / max |w| and the thermal relaxation
 * limit (implicit coupling) or cfl dz / max(|w| + c) over the flowing
 * cells (explicit coupling; |w| over every face and the inflows), the
 * solid cells' accuracy limit ([numerics] solid_relax_step, never below
 * their own acoustic step), the compression limit and dt_max.
 * *why (may be NULL) says which limit it was and which cell set it. */
double ekm_control_max_dt(const ekm_scenario *sc, const ekm_state *s, ekm_dt_limit *why);

/* The same with the thermal relaxation rate of s already known (the
 * stepper's end-of-step check computed it on this state: step.h
 * end_rate_*), rate and cell as ekm_control_thermal_rate returns them;
 * known = NULL: computed here. */
typedef struct {
    double rate; /* [1/s] */
    int cell;
} ekm_thermal_known;
double ekm_control_max_dt_known(const ekm_scenario *sc, const ekm_state *s, const ekm_thermal_known *known,
                                ekm_dt_limit *why);

/* The acoustic step cfl dz / max(|w| + c) over the flowing cells (c the
 * EKM sound speed, model.h): the limit of the explicit coupling, whatever
 * [numerics] normal_coupling says (for the diagnostics and the step-count
 * test of the implicit coupling).  INFINITY when nothing moves. */
double ekm_control_acoustic_dt(const ekm_scenario *sc, const ekm_state *s);

/* The largest relaxation rate of the kinetic pressure [1/s] over the
 * flowing cells of s, eps P_K / (P_K + P_Y) (the thermal relaxation limit's
 * rate), and the cell that has it (-1: none). */
double ekm_control_thermal_rate(const ekm_scenario *sc, const ekm_state *s, int *cell);

/* The step to restart from after a change of the driving (an inflow
 * closes, the base starts tilting, a piston reverses): the acoustic step
 * cfl dz / max(|w| + c) over every cell, solid ones included, so that the
 * lagged rates of the solid law follow the new load within a few short
 * steps before the step grows again (at most 1.5x per step). */
double ekm_control_restart_dt(const ekm_scenario *sc, const ekm_state *s);

/* The time [s] the step from time t must end at: t_next_out (the next
 * output) or the first change of the driving before it.  *at_event = 1
 * when the step ends at a change of the driving (then the next step
 * restarts from ekm_control_restart_dt). */
double ekm_control_target(const ekm_scenario *sc, double t, double t_next_out, int *at_event);

#endif
