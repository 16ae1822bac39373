/* ekm_bench: solver throughput for `make bench` (bench/ekm.sh).
 *
 *   ekm_bench SOURCE_DIR OUT.json
 *
 * Cell-updates per second (accepted steps x cells / wall time of the time
 * loop, ekm_run without output, one core) of shear_cell at 100, 1000,
 * 10000 and 100000 cells and of filling at 100, 1000 and 10000 cells, each
 * run from its initial state over a short model time (the step count grows
 * with the cell count: the acoustic limit), the best of a few repeats for
 * the small sizes (the machine may be shared); the temperature Newton
 * iterations per step of each; and the wall time of a whole thesis_filling
 * run (30 cells, until the bed has formed, no output), the best of five.
 * Writes a JSON fragment for scripts/bench.sh. */
#include <gsl/gsl_errno.h>
#include <stdio.h>
#include <string.h>

#include "atomic.h"
#include "run.h"
#include "scenario.h"
#include "state.h"
#include "step.h"

/* One measured run. */
typedef struct {
    double rate;            /* cell-updates/s */
    double wall_s;          /* wall time of the loop [s] */
    long steps;             /* accepted steps */
    double newton_per_step; /* temperature Newton iterations per step */
} bench_result;

/* Run `name` with cells cells to t_end (no output), repeats times; the
 * fastest into *best.  Prints the failure and returns its status. */
static ekm_status measure(const char *src, const char *name, int cells, double t_end, int repeats,
                          bench_result *best)
{
    char path[1024], set_cells[64], set_t_end[64], set_out[64];
    snprintf(path, sizeof path, "%s/scenarios/%s.ini", src, name);
    snprintf(set_cells, sizeof set_cells, "domain.cells=%d", cells);
    snprintf(set_t_end, sizeof set_t_end, "run.t_end=%.17g", t_end);
    snprintf(set_out, sizeof set_out, "run.output_dt=%.17g", t_end);
    const char *sets[] = {set_cells, set_t_end, set_out, "run.stop=t_end"};
    *best = (bench_result){0};
    for (int r = 0; r < repeats; r++) {
        ekm_scenario sc;
        ekm_error err = {0};
        ekm_status status =
            ekm_scenario_load(&sc, path, cells > 0 ? sets : sets + 1, cells > 0 ? 4 : 0, &err);
        ekm_state *s = NULL;
        ekm_stepper *st = NULL;
        if (status == EKM_OK) {
            s = ekm_state_alloc(sc.cells, sc.length);
            if (!s)
                status = EKM_FAIL(&err, EKM_ENOMEM, "out of memory (%d cells)", sc.cells);
            else if (!(st = ekm_step_alloc(&sc, &err)))
                status = err.code;
        }
        ekm_run_stats stats = {0};
        if (status == EKM_OK) {
            ekm_state_init(s, &sc);
            status = ekm_run(&sc, s, st, NULL, &stats, &err);
        }
        ekm_step_free(st);
        ekm_state_free(s);
        ekm_scenario_free(&sc);
        if (status != EKM_OK) {
            fprintf(stderr, "ekm_bench: %s at %d cells: %s\n", name, cells, err.message);
            return status;
        }
        const double rate = stats.cell_updates / stats.wall_s;
        if (rate > best->rate)
            *best = (bench_result){rate, stats.wall_s, stats.steps,
                                   (double)stats.newton_iterations / (double)stats.steps};
    }
    fprintf(stderr, "  %-14s %6d cells: %7ld steps in %.3f s, %.3g cell-updates/s, %.2f Newton/step\n", name,
            cells, best->steps, best->wall_s, best->rate, best->newton_per_step);
    return EKM_OK;
}

#define N_SHEAR   4
#define N_FILLING 3

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
    /* model times: about 1e7 cell-updates each at 1e7 cell-updates/s, the
     * largest a few hundred steps */
    const int shear_cells[N_SHEAR] = {100, 1000, 10000, 100000};
    const double shear_t_end[N_SHEAR] = {0.3, 0.02, 2e-4, 2e-6};
    const int shear_repeats[N_SHEAR] = {3, 3, 1, 1};
    const int filling_cells[N_FILLING] = {100, 1000, 10000};
    const double filling_t_end[N_FILLING] = {0.3, 0.03, 3e-4};
    bench_result shear[N_SHEAR], filling[N_FILLING], thesis;
    ekm_status st;
    for (int k = 0; k < N_SHEAR; k++)
        if ((st = measure(src, "shear_cell", shear_cells[k], shear_t_end[k], shear_repeats[k], &shear[k])) !=
            EKM_OK)
            return ekm_status_exit_code(st);
    for (int k = 0; k < N_FILLING; k++)
        if ((st = measure(src, "filling", filling_cells[k], filling_t_end[k], k < 2 ? 3 : 1, &filling[k])) !=
            EKM_OK)
            return ekm_status_exit_code(st);
    /* thesis_filling as it is (30 cells, t_end 40 s): cells = 0 keeps every key */
    if ((st = measure(src, "thesis_filling", 0, 0.0, 5, &thesis)) != EKM_OK)
        return ekm_status_exit_code(st);

    ekm_error err = {0};
    ekm_atomic out;
    st = ekm_atomic_open(&out, argv[2], &err);
    if (st != EKM_OK) {
        ekm_error_print("ekm_bench", &err);
        return ekm_status_exit_code(st);
    }
    FILE *fp = out.fp;
    fprintf(fp, "{\"rows\": [\n");
    for (int k = 0; k < N_SHEAR; k++) {
        const int target_row = shear_cells[k] == 1000;
        fprintf(
            fp,
            "  {\"benchmark\": \"ekm shear_cell, %d cells (%ld steps, %.2f Newton/step)\", \"value\": %.4g, "
            "\"unit\": \"cell-updates/s (1 core)\", \"target\": \"%s\", \"status\": \"%s\"},\n",
            shear_cells[k], shear[k].steps, shear[k].newton_per_step, shear[k].rate,
            target_row ? ">= 2e7 (goal 1e8)" : "",
            target_row ? (shear[k].rate >= 2e7 ? "ok" : "MISSED") : "");
    }
    for (int k = 0; k < N_FILLING; k++)
        fprintf(fp,
                "  {\"benchmark\": \"ekm filling, %d cells (%ld steps, %.2f Newton/step)\", \"value\": %.4g, "
                "\"unit\": \"cell-updates/s (1 core)\", \"target\": \"\", \"status\": \"\"},\n",
                filling_cells[k], filling[k].steps, filling[k].newton_per_step, filling[k].rate);
    fprintf(
        fp,
        "  {\"benchmark\": \"ekm thesis_filling, 30 cells, to its bed at t = 40 s (%ld steps)\", \"value\": "
        "%.4g, \"unit\": \"s wall\", \"target\": \"< 0.01\", \"status\": \"%s\"}\n",
        thesis.steps, thesis.wall_s, thesis.wall_s < 0.01 ? "ok" : "MISSED");
    fprintf(fp, "], \"keys\": {\"ekm_cell_updates_per_s\": %.6g", shear[1].rate);
    for (int k = 0; k < N_SHEAR; k++)
        fprintf(fp, ", \"cell_updates_per_s.shear_cell.%d\": %.6g, \"newton_per_step.shear_cell.%d\": %.4g",
                shear_cells[k], shear[k].rate, shear_cells[k], shear[k].newton_per_step);
    for (int k = 0; k < N_FILLING; k++)
        fprintf(fp, ", \"cell_updates_per_s.filling.%d\": %.6g", filling_cells[k], filling[k].rate);
    fprintf(fp, ", \"thesis_filling_wall_s\": %.6g}}\n", thesis.wall_s);
    st = ekm_atomic_commit(&out, &err);
    if (st != EKM_OK) {
        ekm_error_print("ekm_bench", &err);
        return ekm_status_exit_code(st);
    }
    return 0;
}
