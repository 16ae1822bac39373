/* run.h: the time loop (GSL's evolve): each step takes the limit of
 * control.h, grows at most x1.5 per step, ends on the next output time or
 * change of the driving (control.h, then restarts from the acoustic step),
 * is halved on a rejected step down to dt_min (below it: EKM_ENUMERIC with
 * the last rejection's reason; also when the limit itself is below dt_min,
 * naming the limit and the cell); frames at output_dt, progress line.
 * [run] stop = steady: the steady-state test of steady_stop.h at every output;
 * the run ends at the first output where it holds (t_end: the longest). */
#ifndef EKM_RUN_H
#define EKM_RUN_H

#include "control.h"
#include "scenario.h"
#include "state.h"
#include "step.h"
#include "steady_stop.h"

typedef struct {
    /* Called at t = 0, every output_dt and at t_end. */
    ekm_status (*frame)(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err);
    /* Called after every accepted step (may be NULL), with the same ctx:
     * e.g. to watch the regime switches of each step (tests). */
    ekm_status (*step)(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err);
    void *ctx;
    int progress; /* 1: a progress line with ETA on stderr (common/progress.h: rewritten on a
                     terminal, a line a minute in a log) */
} ekm_run_hooks;

typedef struct {
    long steps;                  /* accepted steps */
    long rejected;               /* rejected (and retried) steps */
    double cell_updates;         /* accepted steps x cells */
    double wall_s;               /* wall-clock time of the loop [s] */
    double dt_min_used;          /* smallest accepted step [s] */
    double mass_initial;         /* [kg/m^2] */
    double mass_final;           /* [kg/m^2] */
    double mass_in;              /* net boundary inflow [kg/m^2] */
    double phi_max;              /* largest phi of any output frame [-] */
    long newton_iterations;      /* temperature Newton iterations, all steps */
    long to_solid, to_flow;      /* regime switches flow -> solid, solid -> flow */
    double jump_max;             /* largest relative stress jump at a switch [-] */
    double fail_time;            /* first solid -> flow switch [s], -1: none */
    double fail_angle;           /* gravity angle then [deg] */
    double fail_fY;              /* f_Y of the failing cell's stress then [-] */
    int fail_cell;               /* the failing cell (-1: none) */
    double fail_phi;             /* its phi then (the law's, as fail_fY) [-] */
    ekm_hypo_stress fail_stress; /* its stress then [Pa] */
    /* [run] stop = steady (steady_stop.h): */
    int steady;                 /* 1: ended steady, 0: reached t_end unsteady */
    double steady_drift;        /* drift at the last output [1/s] */
    double steady_time;         /* start of the held steady window [s], NAN: never */
    double steady_acceleration; /* d(mean vx)/dt over the last steady_window [m/s^2] */
} ekm_run_stats;

ekm_status ekm_run(const ekm_scenario *sc, ekm_state *s, ekm_stepper *st, const ekm_run_hooks *hooks,
                   ekm_run_stats *stats, ekm_error *err);

/* What every 1D time loop does at its outputs (ekm_run, and the local
 * rheology's slab solver, local_slab.h): the frame hook, phi_max, and with
 * [run] stop = steady the steady test (steady_stop.h). */
typedef struct {
    ekm_steady_stop steady;
    int until_steady; /* [run] stop = steady */
    int is_steady;    /* the test holds: the loop ends */
} ekm_run_watch;

/* The first output (t = 0): w set up, the frame hook and the first steady
 * check. On an error w holds nothing to free. */
ekm_status ekm_run_watch_start(ekm_run_watch *w, const ekm_scenario *sc, const ekm_state *s,
                               const ekm_stepper *st, const ekm_run_hooks *hooks, ekm_run_stats *stats,
                               ekm_error *err);
/* An output: phi_max, the frame hook, the steady check. */
ekm_status ekm_run_watch_frame(ekm_run_watch *w, const ekm_scenario *sc, const ekm_state *s,
                               const ekm_stepper *st, const ekm_run_hooks *hooks, ekm_run_stats *stats,
                               ekm_error *err);
/* After an accepted step: steps and cell_updates counted, the step hook,
 * and at t_next_out [s] the output (++*frame, ekm_run_watch_frame). */
ekm_status ekm_run_watch_step(ekm_run_watch *w, const ekm_scenario *sc, const ekm_state *s,
                              const ekm_stepper *st, const ekm_run_hooks *hooks, ekm_run_stats *stats,
                              double t_next_out, long *frame, ekm_error *err);
/* The steady verdict into stats (steady, steady_drift, steady_time,
 * steady_acceleration), when until_steady. */
void ekm_run_watch_verdict(const ekm_run_watch *w, const ekm_scenario *sc, ekm_run_stats *stats);
void ekm_run_watch_free(ekm_run_watch *w);

#endif
