/* run2d.c: `ekm run` on a 2D scenario (run2d.h). */
#include "run2d.h"

#include <math.h>
#include <petscsys.h>
#include <stdio.h>
#include <stdlib.h>

#include "out2d.h"
#include "progress.h"
#include "solver2d.h"

int ekm2d_is_rank0(void)
{
    int init = 0, fin = 0, rank = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    if (init && !fin)
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank == 0;
}

/* The next time a frame is due or the driving changes (an inflow opens or closes). */
static double next_stop(const ekm_scenario *sc, double t, double t_frame)
{
    double next = t_frame;
    const ekm_bc *ends[2] = {&sc->bottom, &sc->top};
    for (int k = 0; k < 2; k++) {
        if (ends[k]->kind != EKM_BC_INFLOW)
            continue;
        const double events[2] = {ends[k]->t_start, ends[k]->t_stop};
        for (int e = 0; e < 2; e++)
            if (events[e] > t * (1.0 + 1e-12) + 1e-300 && events[e] < next)
                next = events[e];
    }
    return next;
}

/* The run itself, with PETSc started. */
static ekm_status run(const ekm_scenario *sc, const ekm2d_run_options *opt, ekm_error *err)
{
    int rank = 0, ranks = 1;
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
    const double started = ekm_now_s();
    ekm2d_solver *sol = NULL;
    ekm_status st = ekm2d_solver_create(sc, PETSC_COMM_WORLD, NULL, &sol, err);
    if (st != EKM_OK)
        return st;
    const size_t ncell = (size_t)sc->cells * (size_t)sc->cells_x;
    /* frames at 0, output_dt, 2 output_dt, ... and at t_end (the 1D run's frames, run.c) */
    const double n_steps_out = floor(sc->t_end / sc->output_dt + 1e-9);
    const int t_end_on_grid = fabs(n_steps_out * sc->output_dt - sc->t_end) <= 1e-9 * sc->t_end;
    const size_t n_frames = (size_t)n_steps_out + 1 + (t_end_on_grid ? 0 : 1);
    double *buf = NULL;
    double *fields[EKM2D_NFIELDS] = {0};
    ekm2d_writer *w = NULL;
    /* rank 0 opens the output and holds the gathered fields; every rank learns its status */
    if (rank == 0) {
        buf = malloc(ncell * EKM2D_NFIELDS * sizeof *buf);
        if (!buf)
            st = EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D output, %zu cells)", ncell);
        for (int k = 0; buf && k < EKM2D_NFIELDS; k++)
            fields[k] = buf + (size_t)k * ncell;
        if (st == EKM_OK)
            st = ekm2d_writer_open(&w, opt->out, sc, ranks, n_frames, err);
    }
    int code = (int)st;
    MPI_Bcast(&code, 1, MPI_INT, 0, PETSC_COMM_WORLD);
    st = (ekm_status)code;
    if (st != EKM_OK && rank != 0)
        EKM_FAIL(err, st, "rank 0 could not open the output");
    ekm_progress progress;
    ekm_progress_start(&progress, opt->progress && rank == 0 ? stderr : NULL);
    for (size_t k = 0; st == EKM_OK && k < n_frames; k++) {
        const double t_frame = fmin((double)k * sc->output_dt, sc->t_end);
        ekm2d_stats stats;
        st = ekm2d_solver_stats(sol, &stats, err);
        while (st == EKM_OK && stats.t < t_frame * (1.0 - 1e-12)) {
            st = ekm2d_solver_advance(sol, next_stop(sc, stats.t, t_frame), err);
            if (st == EKM_OK)
                st = ekm2d_solver_stats(sol, &stats, err);
            if (st == EKM_OK)
                ekm_progress_update(&progress, stats.t, sc->t_end, 0.0, stats.steps, 0);
        }
        if (st == EKM_OK)
            st = ekm2d_solver_fields(sol, fields, err);
        if (st == EKM_OK && rank == 0)
            st = ekm2d_writer_append(w, stats.t, stats.dz, (const double *const *)fields, err);
        code = (int)st;
        MPI_Bcast(&code, 1, MPI_INT, 0, PETSC_COMM_WORLD);
        if (code != EKM_OK && st == EKM_OK)
            st = EKM_FAIL(err, (ekm_status)code, "rank 0 could not write the output");
    }
    ekm_progress_end(&progress);
    ekm2d_stats stats = {0};
    if (st == EKM_OK)
        st = ekm2d_solver_stats(sol, &stats, err);
    const double wall = ekm_now_s() - started;
    if (st == EKM_OK && rank == 0) {
        const struct {
            const char *name;
            double value;
        } attrs[] = {
            {"stats.wall_time_s", wall},
            {"stats.steps", (double)stats.steps},
            {"stats.rejected_steps", (double)stats.rejected},
            {"stats.newton_iterations", (double)stats.newton},
            {"stats.cell_updates", stats.cell_updates},
            {"stats.mass_final", stats.mass},
            {"stats.mass_in", stats.mass_in},
            {"stats.solid_lag_max", stats.solid_lag_max},
            {"stats.solid_floor_steps", (double)stats.solid_floor_steps},
        };
        for (size_t i = 0; i < sizeof attrs / sizeof attrs[0] && st == EKM_OK; i++)
            st = ekm2d_writer_set_attr(w, attrs[i].name, attrs[i].value, err);
        if (st == EKM_OK)
            st = ekm2d_writer_commit(w, err);
        else
            ekm2d_writer_abort(w);
        w = NULL;
    }
    if (w)
        ekm2d_writer_abort(w);
    code = (int)st;
    MPI_Bcast(&code, 1, MPI_INT, 0, PETSC_COMM_WORLD);
    if (code != EKM_OK && st == EKM_OK)
        st = EKM_FAIL(err, (ekm_status)code, "rank 0 could not write the output");
    if (st == EKM_OK && rank == 0 && !opt->quiet)
        printf("%-20s t = %-8.4g s  %7ld steps (%ld rejected)  %d x %d cells on %d rank%s  phi_max %.4f  "
               "mass %.9g kg/m (in %.3g)  Newton/step %.2f  %.3f s  -> %s\n",
               sc->name, stats.t, stats.steps, stats.rejected, sc->cells_x, sc->cells, ranks,
               ranks > 1 ? "s" : "", stats.phi_max, stats.mass, stats.mass_in,
               stats.steps ? (double)stats.newton / stats.steps : 0.0, wall, opt->out);
    free(buf);
    ekm2d_solver_destroy(sol);
    return st;
}

ekm_status ekm2d_cmd_run(const ekm_scenario *sc, const ekm2d_run_options *opt, ekm_error *err)
{
    /* PETSc sees "ekm", the options after "--", and -no_signal_handler (the
     * output's temporary files are removed by ekm's own handlers) */
    const int argc0 = opt->n_petsc_args + 2;
    char **argv = calloc((size_t)argc0 + 1, sizeof *argv);
    if (!argv)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    char name[] = "ekm", nosig[] = "-no_signal_handler";
    argv[0] = name;
    argv[1] = nosig;
    for (int i = 0; i < opt->n_petsc_args; i++)
        argv[i + 2] = opt->petsc_args[i];
    int argc = argc0;
    char **args = argv;
    PetscErrorCode rc = PetscInitialize(&argc, &args, NULL, NULL);
    if (rc) {
        free(argv);
        return EKM_FAIL(err, EKM_EINTERNAL, "2D solver: PetscInitialize failed (PETSc error %d)", (int)rc);
    }
    /* errors come back as codes, reported once as ekm's message */
    PetscPushErrorHandler(PetscReturnErrorHandler, NULL);
    ekm_status st = run(sc, opt, err);
    PetscPopErrorHandler();
    PetscFinalize();
    free(argv);
    return st;
}
