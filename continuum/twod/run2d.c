/* run2d.c: `ekm run` on a 2D scenario (run2d.h). */
#include "run2d.h"

#include <math.h>
#include <petscsys.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "checkpoint2d.h"
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

/* A status decided on rank 0, known to every rank. */
static ekm_status share_status(ekm_status st, const char *what, ekm_error *err)
{
    int code = (int)st;
    MPI_Bcast(&code, 1, MPI_INT, 0, PETSC_COMM_WORLD);
    if (code != EKM_OK && st == EKM_OK)
        return EKM_FAIL(err, (ekm_status)code, "rank 0 %s", what);
    return code != EKM_OK ? (ekm_status)code : st;
}

/* The frames of a run with a checkpoint file: kept on rank 0 for the next
 * checkpoint (the output's frames are in its file). */
typedef struct {
    ekm2d_checkpoint ck; /* ck.n_frames frames so far; the state set when written */
    size_t cap;          /* frames ck's arrays hold */
    size_t ncell;
    double last_s; /* wall clock of the last checkpoint [s] */
} frame_store;

static ekm_status store_frame(frame_store *fs, double t, double dz, double *const fields[EKM2D_NFIELDS],
                              ekm_error *err)
{
    if (fs->ck.n_frames == fs->cap) {
        const size_t cap = fs->cap ? 2 * fs->cap : 16;
        double *ft = realloc(fs->ck.frame_t, cap * sizeof *ft);
        if (ft)
            fs->ck.frame_t = ft;
        double *fd = realloc(fs->ck.frame_dz, cap * sizeof *fd);
        if (fd)
            fs->ck.frame_dz = fd;
        double *ff = realloc(fs->ck.frames, cap * EKM2D_NFIELDS * fs->ncell * sizeof *ff);
        if (ff)
            fs->ck.frames = ff;
        if (!ft || !fd || !ff)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory (checkpoint frames)");
        fs->cap = cap;
    }
    const size_t k = fs->ck.n_frames++;
    fs->ck.frame_t[k] = t;
    fs->ck.frame_dz[k] = dz;
    for (int q = 0; q < EKM2D_NFIELDS; q++)
        memcpy(fs->ck.frames + (k * EKM2D_NFIELDS + (size_t)q) * fs->ncell, fields[q],
               fs->ncell * sizeof(double));
    return EKM_OK;
}

/* Resume from opt->checkpoint when it exists (collective): the solver's
 * state, the frames into the output (rank 0, w) and fs; *t0 the
 * checkpoint's time (-1: none), *wall_before its wall time. */
static ekm_status resume(const ekm_scenario *sc, const ekm2d_run_options *opt, ekm2d_solver *sol,
                         ekm2d_writer *w, frame_store *fs, double *t0, double *wall_before, ekm_error *err)
{
    int rank = 0;
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    *t0 = -1.0;
    *wall_before = 0.0;
    int found = rank == 0 && access(opt->checkpoint, F_OK) == 0;
    MPI_Bcast(&found, 1, MPI_INT, 0, PETSC_COMM_WORLD);
    if (!found)
        return EKM_OK;
    ekm2d_checkpoint *ck = &fs->ck;
    ekm_status st = rank == 0 ? ekm2d_checkpoint_read(opt->checkpoint, sc, ck, err) : EKM_OK;
    st = share_status(st, "could not read the checkpoint", err);
    if (st != EKM_OK)
        return st;
    fs->cap = ck->n_frames;
    /* the scalars to every rank (the values stay on rank 0) */
    ekm2d_restart scal = ck->state;
    scal.values = NULL;
    MPI_Bcast(&scal, (int)sizeof scal, MPI_BYTE, 0, PETSC_COMM_WORLD);
    scal.values = ck->state.values;
    st = ekm2d_solver_load(sol, &scal, err);
    if (st != EKM_OK) { /* the message names the file */
        char why[sizeof err->message];
        snprintf(why, sizeof why, "%s", err->message);
        return EKM_FAIL(err, st, "%s: %s", opt->checkpoint, why);
    }
    double *fields[EKM2D_NFIELDS];
    for (size_t k = 0; rank == 0 && k < ck->n_frames && st == EKM_OK; k++) {
        for (int q = 0; q < EKM2D_NFIELDS; q++)
            fields[q] = ck->frames + (k * EKM2D_NFIELDS + (size_t)q) * fs->ncell;
        st = ekm2d_writer_append(w, ck->frame_t[k], ck->frame_dz[k], (const double *const *)fields, err);
    }
    st = share_status(st, "could not write the output", err);
    *t0 = scal.t;
    *wall_before = ck->wall_s;
    MPI_Bcast(wall_before, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    ekm2d_restart_free(&ck->state);
    if (st == EKM_OK && rank == 0 && !opt->quiet)
        fprintf(stderr, "%s: resumed from %s at t = %.6g s (%zu frames, %ld steps)\n", sc->name,
                opt->checkpoint, scal.t, ck->n_frames, scal.steps);
    return st;
}

/* Write the checkpoint (collective; rank 0 writes). */
static ekm_status checkpoint(const ekm_scenario *sc, const ekm2d_run_options *opt, ekm2d_solver *sol,
                             frame_store *fs, double wall_s, ekm_error *err)
{
    int rank = 0;
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    ekm_status st = ekm2d_solver_save(sol, &fs->ck.state, err);
    if (st == EKM_OK && rank == 0) {
        fs->ck.wall_s = wall_s;
        st = ekm2d_checkpoint_write(opt->checkpoint, sc, &fs->ck, err);
    }
    ekm2d_restart_free(&fs->ck.state);
    fs->last_s = ekm_now_s();
    return share_status(st, "could not write the checkpoint", err);
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
    frame_store fs = {.ncell = ncell, .last_s = started};
    /* rank 0 opens the output and holds the gathered fields; every rank
     * learns its status (a resumed run may carry one frame off the
     * output_dt grid: the t_end of the run it continues) */
    if (rank == 0) {
        buf = malloc(ncell * EKM2D_NFIELDS * sizeof *buf);
        if (!buf)
            st = EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D output, %zu cells)", ncell);
        for (int k = 0; buf && k < EKM2D_NFIELDS; k++)
            fields[k] = buf + (size_t)k * ncell;
        if (st == EKM_OK)
            st = ekm2d_writer_open(&w, opt->out, sc, ranks, n_frames + (opt->checkpoint ? 1 : 0), err);
    }
    st = share_status(st, "could not open the output", err);
    double t0 = -1.0, wall_before = 0.0;
    if (st == EKM_OK && opt->checkpoint)
        st = resume(sc, opt, sol, w, &fs, &t0, &wall_before, err);
    ekm_progress progress;
    ekm_progress_start(&progress, opt->progress && rank == 0 ? stderr : NULL);
    if (t0 > 0.0)
        ekm_progress_from(&progress, t0);
    for (size_t k = 0; st == EKM_OK && k < n_frames; k++) {
        /* k output_dt (also when that is t_end to round-off: a run to an
         * earlier t_end on the grid stops where this one writes a frame, so
         * that a run continued from its checkpoint takes the same steps) */
        const double t_frame = k <= (size_t)n_steps_out ? (double)k * sc->output_dt : sc->t_end;
        if (t0 >= 0.0 && t_frame <= t0 * (1.0 + 1e-12))
            continue; /* in the checkpoint's frames */
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
        if (st == EKM_OK && rank == 0 && opt->checkpoint)
            st = store_frame(&fs, stats.t, stats.dz, fields, err);
        st = share_status(st, "could not write the output", err);
        if (st == EKM_OK && opt->checkpoint &&
            (k + 1 == n_frames || ekm_now_s() - fs.last_s >= opt->checkpoint_every_s))
            st = checkpoint(sc, opt, sol, &fs, wall_before + ekm_now_s() - started, err);
    }
    ekm_progress_end(&progress);
    ekm2d_checkpoint_free(&fs.ck);
    ekm2d_stats stats = {0};
    if (st == EKM_OK)
        st = ekm2d_solver_stats(sol, &stats, err);
    const double wall = wall_before + ekm_now_s() - started;
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
        if (st == EKM_OK && t0 >= 0.0) /* a resumed run: where it went on */
            st = ekm2d_writer_set_attr(w, "stats.resumed_at_t", t0, err);
        if (st == EKM_OK)
            st = ekm2d_writer_commit(w, err);
        else
            ekm2d_writer_abort(w);
        w = NULL;
    }
    if (w)
        ekm2d_writer_abort(w);
    st = share_status(st, "could not write the output", err);
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
