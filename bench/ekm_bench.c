/* ekm_bench: solver throughput for `make bench` (bench/ekm.sh).
 *
 *   ekm_bench SOURCE_DIR OUT.json
 *
 * Cell-updates per second (accepted steps x cells / wall time) of
 * shear_cell and filling at 100, 1000 and 10000 cells, each stepped from
 * its initial state for at least 1 s of wall time, and the wall time of a
 * whole thesis_filling run (30 cells, until the bed has formed, no output).
 * Writes a JSON fragment for scripts/bench.sh. */
#include <gsl/gsl_errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "atomic.h"
#include "control.h"
#include "run.h"
#include "scenario.h"
#include "state.h"
#include "step.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static ekm_status load(ekm_scenario *sc, const char *src, const char *name, const char *const *sets, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenarios/%s.ini", src, name);
    ekm_error err;
    const ekm_status st = ekm_scenario_load(sc, path, sets, n, &err);
    if (st != EKM_OK)
        ekm_error_print("ekm_bench", &err);
    return st;
}

/* Allocate the state and the stepper of sc; on failure prints the error
 * and returns its status (*s and *st freed and NULL). */
static ekm_status alloc_run(const ekm_scenario *sc, ekm_state **s, ekm_stepper **st)
{
    ekm_error err = {0};
    *st = NULL;
    *s = ekm_state_alloc(sc->cells, sc->length);
    if (!*s) {
        EKM_FAIL(&err, EKM_ENOMEM, "out of memory (%d cells)", sc->cells);
    } else if (!(*st = ekm_step_alloc(sc, &err))) {
        ekm_state_free(*s);
        *s = NULL;
    }
    if (!*s) {
        ekm_error_print("ekm_bench", &err);
        return err.code;
    }
    return EKM_OK;
}

/* Cell-updates per second into *rate; the failure's status otherwise. */
static ekm_status throughput(const char *src, const char *name, int cells, double *rate)
{
    char set_cells[64];
    snprintf(set_cells, sizeof set_cells, "domain.cells=%d", cells);
    const char *sets[] = {set_cells};
    ekm_scenario sc;
    ekm_status status = load(&sc, src, name, sets, 1);
    if (status != EKM_OK) {
        ekm_scenario_free(&sc);
        return status;
    }
    ekm_error err = {0};
    ekm_state *s = NULL;
    ekm_stepper *st = NULL;
    status = alloc_run(&sc, &s, &st);
    if (status == EKM_OK) {
        ekm_state_init(s, &sc);
        long updates = 0, steps = 0;
        const double t0 = now_s();
        double elapsed = 0;
        while (elapsed < 1.0 || steps < 20) {
            double dt = ekm_control_max_dt(&sc, s, NULL);
            int accepted = 0;
            while (!accepted) {
                status = ekm_step_apply(st, s, dt, &accepted, &err);
                if (status != EKM_OK) {
                    fprintf(stderr, "ekm_bench: %s at %d cells failed: %s\n", name, cells, err.message);
                    goto done;
                }
                if (dt < sc.numerics.dt_min) {
                    status = EKM_ENUMERIC;
                    fprintf(stderr, "ekm_bench: %s at %d cells failed: %s\n", name, cells, st->reject_reason);
                    goto done;
                }
                dt *= 0.5;
            }
            steps++;
            updates += cells;
            if ((steps & 15) == 0)
                elapsed = now_s() - t0;
        }
        elapsed = now_s() - t0;
        *rate = updates / elapsed;
        fprintf(stderr, "  %-12s %6d cells: %8ld steps in %.2f s, %.3g cell-updates/s\n", name, cells, steps,
                elapsed, *rate);
    }
done:
    ekm_step_free(st);
    ekm_state_free(s);
    ekm_scenario_free(&sc);
    return status;
}

/* Wall time of a whole thesis_filling run into *wall, its steps into *steps. */
static ekm_status thesis_filling_wall(const char *src, double *wall, long *steps)
{
    ekm_scenario sc;
    ekm_status status = load(&sc, src, "thesis_filling", NULL, 0);
    if (status != EKM_OK) {
        ekm_scenario_free(&sc);
        return status;
    }
    ekm_error err = {0};
    ekm_state *s = NULL;
    ekm_stepper *st = NULL;
    status = alloc_run(&sc, &s, &st);
    if (status == EKM_OK) {
        ekm_state_init(s, &sc);
        ekm_run_stats stats;
        const double t0 = now_s();
        status = ekm_run(&sc, s, st, NULL, &stats, &err);
        if (status == EKM_OK) {
            *wall = now_s() - t0;
            *steps = stats.steps;
        } else {
            fprintf(stderr, "ekm_bench: thesis_filling failed: %s\n", err.message);
        }
    }
    ekm_step_free(st);
    ekm_state_free(s);
    ekm_scenario_free(&sc);
    return status;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: ekm_bench SOURCE_DIR OUT.json\n");
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    gsl_set_error_handler_off();
    ekm_error setup_err = {0};
    if (ekm_atomic_install_signal_cleanup(&setup_err) != EKM_OK) {
        ekm_error_print("ekm_bench", &setup_err);
        return ekm_status_exit_code(EKM_EINTERNAL);
    }
    const char *src = argv[1];
    const char *names[] = {"shear_cell", "filling"};
    const int sizes[] = {100, 1000, 10000};
    double rates[2][3];
    ekm_status bench_st;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 3; k++)
            if ((bench_st = throughput(src, names[i], sizes[k], &rates[i][k])) != EKM_OK)
                return ekm_status_exit_code(bench_st);
    long steps = 0;
    double wall = 0;
    if ((bench_st = thesis_filling_wall(src, &wall, &steps)) != EKM_OK)
        return ekm_status_exit_code(bench_st);
    fprintf(stderr, "  thesis_filling (30 cells, 40 s): %ld steps, %.3f s\n", steps, wall);
    ekm_error err = {0};
    ekm_atomic out;
    ekm_status st = ekm_atomic_open(&out, argv[2], &err);
    if (st != EKM_OK) {
        ekm_error_print("ekm_bench", &err);
        return ekm_status_exit_code(st);
    }
    FILE *fp = out.fp;
    fprintf(fp, "{\"rows\": [\n");
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 3; k++) {
            const int target_row = i == 0 && k == 1;
            fprintf(fp,
                    "  {\"benchmark\": \"ekm %s, %d cells\", \"value\": %.4g, \"unit\": \"cell-updates/s (1 "
                    "core)\", "
                    "\"target\": \"%s\", \"status\": \"%s\"},\n",
                    names[i], sizes[k], rates[i][k], target_row ? ">= 2e7" : "",
                    target_row ? (rates[i][k] >= 2e7 ? "ok" : "MISSED") : "");
        }
    fprintf(fp,
            "  {\"benchmark\": \"ekm thesis_filling, 30 cells, to t = 40 s (%ld steps)\", \"value\": %.4g, "
            "\"unit\": \"s wall\", \"target\": \"< 1\", \"status\": \"%s\"}\n",
            steps, wall, wall < 1.0 ? "ok" : "MISSED");
    fprintf(fp, "], \"keys\": {\"ekm_cell_updates_per_s\": %.6g, \"thesis_filling_wall_s\": %.6g}}\n",
            rates[0][1], wall);
    st = ekm_atomic_commit(&out, &err);
    if (st != EKM_OK) {
        ekm_error_print("ekm_bench", &err);
        return ekm_status_exit_code(st);
    }
    return 0;
}
