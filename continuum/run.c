#include "run.h"

#include "steady_stop.h"

#include <math.h>
#include <stdio.h>

#include "progress.h"

static void track_phi(ekm_run_stats *stats, const ekm_state *s)
{
    for (int j = 0; j < s->n; j++)
        if (s->phi[j] > stats->phi_max)
            stats->phi_max = s->phi[j];
}

/* EKM_ENUMERIC: the state's own step limit (not a rejection) is below
 * dt_min; say at what time, which limit, which cell and its state. */
static ekm_status step_limit_failure(const ekm_scenario *sc, const ekm_state *s, const ekm_dt_limit *limit,
                                     ekm_error *err)
{
    if (limit->cell < 0)
        return EKM_FAIL(err, EKM_ENUMERIC, "%s: t = %.9g s: the %s step limit %.3g s is below dt_min = %g s",
                        sc->source, s->t, limit->limit, limit->dt_s, sc->numerics.dt_min);
    const int j = limit->cell;
    return EKM_FAIL(err, EKM_ENUMERIC,
                    "%s: t = %.9g s: the %s step limit %.3g s is below dt_min = %g s, set by cell %d "
                    "(z = %.6g m: phi = %.9g, T = %.3g m^2/s^2, w = %.3g/%.3g m/s below/above, %s)",
                    sc->source, s->t, limit->limit, limit->dt_s, sc->numerics.dt_min, j, (j + 0.5) * s->dz,
                    s->phi[j], s->T[j], s->w[j], s->w[j + 1], s->solid[j] ? "solid" : "flowing");
}

ekm_status ekm_run_watch_start(ekm_run_watch *w, const ekm_scenario *sc, const ekm_state *s,
                               const ekm_stepper *st, const ekm_run_hooks *hooks, ekm_run_stats *stats,
                               ekm_error *err)
{
    *w = (ekm_run_watch){0};
    ekm_status rc;
    if (sc->stop == EKM_STOP_STEADY && (rc = ekm_steady_stop_init(&w->steady, s->n, err)) != EKM_OK)
        return rc;
    w->until_steady = sc->stop == EKM_STOP_STEADY;
    if ((rc = ekm_run_watch_frame(w, sc, s, st, hooks, stats, err)) != EKM_OK)
        ekm_run_watch_free(w);
    return rc;
}

ekm_status ekm_run_watch_step(ekm_run_watch *w, const ekm_scenario *sc, const ekm_state *s,
                              const ekm_stepper *st, const ekm_run_hooks *hooks, ekm_run_stats *stats,
                              double t_next_out, long *frame, ekm_error *err)
{
    stats->steps++;
    stats->cell_updates += s->n;
    ekm_status rc;
    if (hooks && hooks->step && (rc = hooks->step(hooks->ctx, s, st, err)) != EKM_OK)
        return rc;
    if (!(s->t >= t_next_out * (1.0 - 1e-12)))
        return EKM_OK;
    ++*frame;
    return ekm_run_watch_frame(w, sc, s, st, hooks, stats, err);
}

ekm_status ekm_run_watch_frame(ekm_run_watch *w, const ekm_scenario *sc, const ekm_state *s,
                               const ekm_stepper *st, const ekm_run_hooks *hooks, ekm_run_stats *stats,
                               ekm_error *err)
{
    track_phi(stats, s);
    ekm_status rc;
    if (hooks && hooks->frame && (rc = hooks->frame(hooks->ctx, s, st, err)) != EKM_OK)
        return rc;
    return w->until_steady ? ekm_steady_stop_check(&w->steady, sc, s, &w->is_steady, err) : EKM_OK;
}

void ekm_run_watch_verdict(const ekm_run_watch *w, const ekm_scenario *sc, ekm_run_stats *stats)
{
    if (!w->until_steady)
        return;
    stats->steady = w->steady.steady;
    stats->steady_drift = w->steady.drift;
    stats->steady_time = w->steady.steady_time;
    stats->steady_acceleration = ekm_steady_stop_acceleration(&w->steady, sc);
}

void ekm_run_watch_free(ekm_run_watch *w)
{
    if (w->until_steady)
        ekm_steady_stop_free(&w->steady);
    w->until_steady = 0;
}

ekm_status ekm_run(const ekm_scenario *sc, ekm_state *s, ekm_stepper *st, const ekm_run_hooks *hooks,
                   ekm_run_stats *stats, ekm_error *err)
{
    const double rho_p = sc->material.rho_p;
    *stats = (ekm_run_stats){.dt_min_used = INFINITY, .steady_drift = NAN, .steady_time = NAN};
    stats->mass_initial = ekm_state_mass(s, rho_p);
    ekm_run_watch watch;
    ekm_status rc = ekm_run_watch_start(&watch, sc, s, st, hooks, stats, err);
    if (rc != EKM_OK)
        return rc;
    const double started = ekm_now_s();
    ekm_progress progress;
    ekm_progress_start(&progress, hooks && hooks->progress ? stderr : NULL);
    long frame = 0;
    /* the run starts (the load is applied) like a change of the driving */
    /* a run does not depend on what the stepper did before it (a stepper
     * reused by the steady solver's warm-ups or a fit's evaluations): no
     * first-iterate history (step.h T_change), no kept thermal rate */
    st->dt_change = 0.0;
    st->end_rate_valid = 0;
    double dt_prev = ekm_control_restart_dt(sc, s) / 1.5;
    while (!watch.is_steady && s->t < sc->t_end * (1.0 - 1e-14)) {
        const double t_next_out = fmin(sc->t_end, (frame + 1) * sc->output_dt);
        ekm_dt_limit limit;
        const ekm_thermal_known known = {st->end_rate, st->end_rate_cell};
        const int rate_known = st->end_rate_valid && st->end_rate_step == s->steps;
        double dt = fmin(ekm_control_max_dt_known(sc, s, rate_known ? &known : NULL, &limit), 1.5 * dt_prev);
        if (!(limit.dt_s >= sc->numerics.dt_min)) { /* NaN too */
            rc = step_limit_failure(sc, s, &limit, err);
            goto done;
        }
        int at_event; /* the step ends at a change of the driving */
        const double t_target = ekm_control_target(sc, s->t, t_next_out, &at_event);
        const int reaches = s->t + dt >= t_target * (1.0 - 1e-12);
        if (reaches)
            dt = t_target - s->t;
        for (;;) {
            int accepted;
            if ((rc = ekm_step_apply(st, s, dt, &accepted, err)) != EKM_OK)
                goto done;
            if (accepted)
                break;
            stats->rejected++;
            dt *= 0.5;
            if (dt < sc->numerics.dt_min) {
                rc = EKM_FAIL(err, EKM_ENUMERIC,
                              "%s: time step fell below dt_min = %g s; last rejected step: %s", sc->source,
                              sc->numerics.dt_min, st->reject_reason);
                goto done;
            }
        }
        if (dt < stats->dt_min_used)
            stats->dt_min_used = dt;
        /* Do not let an event- or output-shortened step throttle growth;
         * after a change of the driving, restart from the acoustic step. */
        if (reaches && at_event)
            dt_prev = ekm_control_restart_dt(sc, s) / 1.5;
        else if (s->t < t_target * (1.0 - 1e-12))
            dt_prev = dt;
        stats->newton_iterations += st->newton_iterations;
        if ((rc = ekm_run_watch_step(&watch, sc, s, st, hooks, stats, t_next_out, &frame, err)) != EKM_OK)
            goto done;
        ekm_progress_update(&progress, s->t, sc->t_end, dt, s->steps, 0);
    }
    if (progress.tty)
        ekm_progress_update(&progress, s->t, sc->t_end, dt_prev, s->steps, 1);
    ekm_progress_end(&progress);
    stats->wall_s = ekm_now_s() - started;
    stats->mass_final = ekm_state_mass(s, rho_p);
    stats->mass_in = s->mass_in;
    stats->to_solid = st->regime.to_solid;
    stats->to_flow = st->regime.to_flow;
    stats->jump_max = st->regime.jump_max;
    stats->fail_time = st->regime.fail_time;
    stats->fail_angle = st->regime.fail_angle;
    stats->fail_fY = st->regime.fail_fY;
    stats->fail_cell = st->regime.fail_cell;
    stats->fail_phi = st->regime.fail_phi;
    stats->fail_stress = st->regime.fail_stress;
    ekm_run_watch_verdict(&watch, sc, stats);
done:
    ekm_progress_end(&progress); /* an error line starts on a line of its own */
    ekm_run_watch_free(&watch);
    return rc;
}
