/* progress.c: the progress line of a long run (progress.h). */
#include "progress.h"

#include <time.h>
#include <unistd.h>

double ekm_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

void ekm_progress_start(ekm_progress *p, FILE *fp)
{
    p->fp = fp;
    p->tty = fp && isatty(fileno(fp));
    p->every_s = p->tty ? 0.25 : 60.0;
    p->started_s = p->last_s = ekm_now_s();
    p->open_line = 0;
    p->t0_s = 0.0;
}

void ekm_progress_from(ekm_progress *p, double t0_s)
{
    p->t0_s = t0_s;
}

void ekm_progress_update(ekm_progress *p, double t_s, double t_end_s, double dt_s, long steps, int force)
{
    if (!p->fp)
        return;
    const double now = ekm_now_s();
    if (!force && now - p->last_s < p->every_s)
        return;
    p->last_s = now;
    const double frac = t_end_s > 0.0 ? t_s / t_end_s : 0.0, elapsed = now - p->started_s;
    const double done = t_end_s > p->t0_s ? (t_s - p->t0_s) / (t_end_s - p->t0_s) : 0.0;
    const double eta = done > 0.0 ? elapsed * (1.0 - done) / done : 0.0;
    fprintf(p->fp, "%s  t = %10.4g s / %.4g s  (%5.1f%%)", p->tty ? "\r" : "", t_s, t_end_s, 100.0 * frac);
    if (dt_s > 0.0)
        fprintf(p->fp, "  dt = %9.3g s", dt_s);
    fprintf(p->fp, "  steps %9ld  wall %6.0f s  ETA %6.0f s%s", steps, elapsed, eta, p->tty ? " " : "\n");
    fflush(p->fp);
    p->open_line = p->tty;
}

void ekm_progress_end(ekm_progress *p)
{
    if (p->fp && p->open_line)
        fputc('\n', p->fp);
    p->open_line = 0;
}
