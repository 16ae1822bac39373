/* progress.h: the progress line of a long run, on stderr.
 *
 * On a terminal the line is rewritten in place four times a second; in a
 * file (a batch's log: scripts/lib/ekm_runs.sh, the campaign) a full line
 * is written once a minute, so that the log says how far a run is and
 * when it should end. The line: simulated time, its fraction of t_end,
 * the step (when known), the steps taken and the estimated wall time left
 * (ETA, from the fraction done so far). */
#ifndef EKM_PROGRESS_H
#define EKM_PROGRESS_H

#include <stdio.h>

typedef struct {
    FILE *fp;         /* where the line goes (stderr), NULL: no progress */
    int tty;          /* 1: fp is a terminal (the line is rewritten) */
    double every_s;   /* wall time between lines [s] */
    double started_s; /* wall clock at the start [s] */
    double t0_s;      /* simulated time at the start (a resumed run: its checkpoint's) [s] */
    double last_s;    /* wall clock at the last line [s] */
    int open_line;    /* 1: a rewritten line waits for its newline */
} ekm_progress;

/* A monotonic wall clock [s]. */
double ekm_now_s(void);

/* Start the clock; fp NULL: every call below does nothing. */
void ekm_progress_start(ekm_progress *p, FILE *fp);

/* A run resumed at simulated time t0_s: the ETA from the time simulated
 * since (after ekm_progress_start). */
void ekm_progress_from(ekm_progress *p, double t0_s);

/* A line at simulated time t_s of t_end_s when one is due (dt_s <= 0: not
 * shown); force: now, whatever the interval. */
void ekm_progress_update(ekm_progress *p, double t_s, double t_end_s, double dt_s, long steps, int force);

/* End the rewritten line (a newline on a terminal). */
void ekm_progress_end(ekm_progress *p);

#endif
