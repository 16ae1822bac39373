/* ekm: run the EKM slab solver on a scenario file.  See `ekm --help`. */
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "atomic.h"
#include "bc.h"
#include "agree_cli.h"
#include "cli_args.h"
#include "ekm_version.h"
#include "h5out.h"
#include "homog_cli.h"
#include "local_slab.h"
#include "run.h"
#include "scenario.h"
#include "scenario_cli.h"
#include "state.h"
#include "steady_cli.h"
#include "step.h"
#include "xdmf.h"
#ifdef EKM_HAVE_2D
#include "run2d.h"
#endif

static void usage(FILE *fp)
{
    fprintf(fp,
            "usage: ekm run FILE.ini [-o OUT.h5] [--material FIT.ini] [--set section.key=value ...]\n"
            "               [--quiet] [--checkpoint CKPT.h5 [--checkpoint-every S]] [-- PETSc options]\n"
            "       mpirun -np N ekm run FILE.ini ...   (a 2D scenario: [domain] cells_x > 1)\n"
            "       ekm scenario FILE.ini [--engine liggghts|lammps] [--size smoke|ref]\n"
            "                    [--point TAG] [--material FIT.ini] [--set section.key=value ...] --json\n"
            "       ekm homog FILE.ini [--material FIT.ini] [--set section.key=value ...]\n"
            "                 --phi LO:HI:N --rate R[,R,...] --json\n"
            "       ekm steady FILE.ini [-o OUT.h5] [--from RUN.h5] [--material FIT.ini]\n"
            "                  [--set section.key=value ...] [--quiet]\n"
            "       ekm agree NEWTON.h5 RUN.h5 [--tol X]\n"
            "       ekm --help | --version\n"
            "\n"
            "Integrates the Extended Kinetic Model in the slab geometry described by the\n"
            "scenario file and writes one HDF5 file (+ XDMF sidecar for ParaView).\n"
            "[model] closure = mu_i runs on the slab solver of a local rheology (a dense\n"
            "layer on a no-slip base; needs [numerics] gdot_min; docs/model/closures.md).\n"
            "\n"
            "  -o OUT.h5        output file (default: the scenario file's name with .h5,\n"
            "                   in the current directory); written atomically\n"
            "  --material FIT.ini  the whole [material] section from FIT.ini (only\n"
            "                   [material] and comments, e.g. `ekmcompare fit --ini`)\n"
            "                   instead of FILE.ini's; --set still applies after it\n"
            "  --set S.K=V      override key K of section S (repeatable), e.g.\n"
            "                   --set domain.cells=200 --set model.variant=thesis\n"
            "  --quiet          no progress line and no summary (the progress line is\n"
            "                   rewritten on a terminal; in a log, a line a minute)\n"
            "  --checkpoint CKPT.h5  (2D runs) write the run's state to CKPT.h5 after an\n"
            "                   output frame every S seconds of wall time (--checkpoint-every,\n"
            "                   default 600) and after the last; when CKPT.h5 exists the run\n"
            "                   goes on from it (the same command, or a later [run] t_end)\n"
            "                   and takes the same steps as a run never stopped\n"
            "  -- OPTIONS       the rest of the line goes to PETSc (2D runs only), e.g.\n"
            "                   -- -ekm_step_monitor -ekm_v_ksp_converged_reason\n"
            "\n"
            "A scenario with [domain] cells_x > 1 is solved in 2D on PETSc, on the MPI\n"
            "ranks ekm is started on (docs/output-format.md, \"2D runs\"); %s.\n"
            "\n"
            "ekm scenario is the program ekmscenario's command (ekmscenario --help): the\n"
            "resolved scenario as one JSON object on stdout (docs/resolved-scenario.md).\n"
            "\n"
            "ekm agree: does the last state of an `ekm steady` output (NEWTON) agree with\n"
            "the steady state an `ekm run` output (RUN) reached? Agree: the run ended\n"
            "steady and phi, vx, T, P (where both have material) and the gap differ by\n"
            "at most X (default 5e-2) of the run's maxima. One line on stdout; exit 0\n"
            "agree, 6 disagree (the campaign's test, continuum/point.h).\n"
            "\n"
            "ekm homog prints the steady homogeneous simple shear of FILE.ini's material\n"
            "and [model] closure (docs/model/law.md, \"ekm homog\"; docs/model/closures.md)\n"
            "as one JSON object: T, P, P_K, P_Y, |sigma_xz|, mu at N volume fractions from\n"
            "LO to HI (inclusive) times each shear rate R [1/s] (T, P_K, P_Y null for a\n"
            "closure without a temperature); a point outside the closure's range (the EKM:\n"
            "phi >= phi_cp) has status \"no_steady_state\" and the reason.\n"
            "\n"
            "ekm steady writes the steady state of FILE.ini (a slab with wall or free ends,\n"
            "no solid regime, no tilting) as one frame of ekm run's output, found by Newton\n"
            "on the time stepper's discrete steady equations and verified by time steps\n"
            "(docs/model/steady.md, \"Steady solver\"); none found: exit 6 \"no steady state\".\n"
            "  --from RUN.h5    start from the last frame of an output on the same grid\n"
            "                   (default: the scenario's initial state)\n"
            "\n"
            "Exit codes (docs/exit-codes.md): 0 success; 1 usage error; 2 bad scenario or\n"
            "command line value; 3 file could not be read or written (also: -o names the\n"
            "scenario file); 4 the solver could not continue (phi would reach phi_cp, no\n"
            "convergence); 5 internal error or out of memory; 6 no steady state; 128+N stopped by signal N\n"
            "(its temporary files removed).\n"
            "Formats and units: README.md and docs/ of ekmbench.\n",
#ifdef EKM_HAVE_2D
            "this ekm has the 2D solver"
#else
            "this ekm has no 2D solver (" EKM_NO_2D_REASON ")"
#endif
    );
}

typedef struct {
    ekm_h5_writer *writer;
} frame_ctx;

static ekm_status write_frame(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)st;
    return ekm_h5_writer_append(((frame_ctx *)ctx)->writer, s, err);
}

static int fail(const ekm_error *err, ekm_status st)
{
    ekm_error_print("ekm", err);
    return ekm_status_exit_code(st);
}

/* `ekm run` on a 2D scenario ([domain] cells_x > 1): the 2D solver on
 * every MPI rank (continuum/twod/run2d.h), its error printed by rank 0
 * only; exit 7 when this ekm is built without it. */
static int run_2d(const ekm_scenario *sc, const ekm_cli_args *a)
{
    ekm_error err = {0};
#ifdef EKM_HAVE_2D
    const ekm2d_run_options opt = {.out = a->out,
                                   .quiet = a->quiet,
                                   .progress = !a->quiet,
                                   .checkpoint = a->checkpoint,
                                   .checkpoint_every_s = a->checkpoint_every_s,
                                   .petsc_args = a->petsc_args,
                                   .n_petsc_args = a->n_petsc_args};
    const ekm_status st = ekm2d_cmd_run(sc, &opt, &err);
    if (st == EKM_OK)
        return 0;
    if (ekm2d_is_rank0())
        ekm_error_print("ekm", &err);
    return ekm_status_exit_code(st);
#else
    (void)a;
    return fail(&err, ekm_scenario_require_1d(
                          sc, "the 2D solver is not built in this ekm (" EKM_NO_2D_REASON ")", &err));
#endif
}

static int cmd_run(int argc, char **argv)
{
    ekm_cli_args args;
    const int usage = ekm_cli_args_parse("run", argc, argv, 0, 1, &args);
    if (usage) {
        ekm_cli_args_free(&args);
        return usage;
    }
    const char *ini = args.ini, *out = args.out, *material = args.material;
    const int quiet = args.quiet;
    const char **sets = args.sets; /* freed below (free(sets)) */
    const size_t n_sets = args.n_sets;
    ekm_error err = {0};
    /* neither the output nor its sidecar may replace an input */
    ekm_status st = ekm_cli_args_check_outputs(&args, &err);
    if (st != EKM_OK) {
        free(sets);
        return fail(&err, st);
    }
    ekm_scenario sc;
    st = ekm_scenario_load_material(&sc, ini, material, sets, n_sets, &err);
    free(sets);
    if (st != EKM_OK) {
        ekm_scenario_free(&sc);
        return fail(&err, st);
    }
    if (sc.cells_x > 1) {
        const int code = run_2d(&sc, &args);
        ekm_scenario_free(&sc);
        return code;
    }
    if (args.checkpoint) {
        fprintf(
            stderr,
            "ekm run: --checkpoint is for 2D runs, but %s is a 1D scenario ([domain] cells_x = 1; a 1D run "
            "is short enough to run again) (see ekm --help)\n",
            ini);
        ekm_scenario_free(&sc);
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    if (args.dashdash) {
        fprintf(stderr,
                "ekm run: '--' passes PETSc options to the 2D solver, but %s is a 1D scenario ([domain] "
                "cells_x = 1) (see ekm --help)\n",
                ini);
        ekm_scenario_free(&sc);
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    /* a local rheology without a temperature (mu_i): the dense slab solver */
    const int local = ekm_local_slab_applies(&sc);
    ekm_state *s = ekm_state_alloc(sc.cells, sc.length);
    ekm_stepper *stepper = NULL;
    ekm_local_slab *slab = NULL;
    if (s && local)
        slab = ekm_local_slab_alloc(&sc, &err);
    else if (s)
        stepper = ekm_step_alloc(&sc, &err);
    if (!s || (!stepper && !slab)) {
        if (!s)
            EKM_FAIL(&err, EKM_ENOMEM, "out of memory (%d cells)", sc.cells);
        ekm_state_free(s);
        ekm_scenario_free(&sc);
        return fail(&err, err.code); /* the status the allocation recorded */
    }
    if (local)
        st = ekm_local_slab_init(slab, s, &err);
    else
        ekm_state_init(s, &sc);
    frame_ctx fc = {0};
    ekm_run_stats stats;
    if (st == EKM_OK)
        st = ekm_h5_writer_open(&fc.writer, out, &sc, s, &err);
    if (st == EKM_OK) {
        ekm_run_hooks hooks = {.frame = write_frame, .ctx = &fc, .progress = !quiet};
        st = local ? ekm_local_slab_run(slab, s, &hooks, &stats, &err)
                   : ekm_run(&sc, s, stepper, &hooks, &stats, &err);
        if (st == EKM_OK && local) {
            /* the slab solver's: its Newton iterations and the most cells whose phi was held at the
             * end of the dilatancy law's range (local_slab.h) */
            st = ekm_h5_writer_set_attr(fc.writer, "stats.newton_iterations", (double)stats.newton_iterations,
                                        &err);
            if (st == EKM_OK)
                st = ekm_h5_writer_set_attr(fc.writer, "local.beyond_cells_max",
                                            (double)ekm_local_slab_beyond_max(slab), &err);
        }
        if (st == EKM_OK) {
            /* run statistics as root attributes: cost (the campaign's
             * DEM/EKM wall-time ratio) and the mass balance, for
             * provenance; with the solid regime also its switches and
             * first failure (the last six) */
            const struct {
                const char *name;
                double value;
            } attrs[] = {
                {"stats.wall_time_s", stats.wall_s},
                {"stats.steps", (double)stats.steps},
                {"stats.rejected_steps", (double)stats.rejected},
                {"stats.cell_updates", stats.cell_updates},
                {"stats.mass_initial", stats.mass_initial},
                {"stats.mass_final", stats.mass_final},
                {"stats.mass_in", stats.mass_in},
                {"hypo.to_solid", (double)stats.to_solid},
                {"hypo.to_flow", (double)stats.to_flow},
                {"hypo.jump_max", stats.jump_max},
                {"hypo.fail_time", stats.fail_time},
                {"hypo.fail_angle", stats.fail_angle},
                {"hypo.fail_fY", stats.fail_fY},
            };
            const size_t n_all = sizeof attrs / sizeof attrs[0];
            const size_t n = sc.hypo.enabled ? n_all : n_all - 6;
            for (size_t i = 0; i < n && st == EKM_OK; i++)
                st = ekm_h5_writer_set_attr(fc.writer, attrs[i].name, attrs[i].value, &err);
            /* [run] stop = steady: the verdict of the steady-state test */
            const struct {
                const char *name;
                double value;
            } steady_attrs[] = {
                {"steady", (double)stats.steady},
                {"steady_drift", stats.steady_drift},
                {"steady_time", stats.steady_time},
                {"steady_acceleration", stats.steady_acceleration},
            };
            for (size_t i = 0; sc.stop == EKM_STOP_STEADY && i < 4 && st == EKM_OK; i++)
                st = ekm_h5_writer_set_attr(fc.writer, steady_attrs[i].name, steady_attrs[i].value, &err);
            if (st == EKM_OK && ekm_boundary_pressure_wall(&sc.top))
                st = ekm_h5_writer_set_attr(fc.writer, "gap_final", s->n * s->dz, &err);
        }
        if (st == EKM_OK)
            st = ekm_h5_writer_commit(fc.writer, &err);
        else
            ekm_h5_writer_abort(fc.writer);
    }
    int code = 0;
    if (st != EKM_OK) {
        code = fail(&err, st);
    } else if (!quiet) {
        const double m0 = stats.mass_initial, m1 = stats.mass_final;
        const double scale = fmax(fmax(m0, m1), 1e-300);
        printf("%-20s t = %-8.4g s  %7ld steps (%ld rejected)  %5d cells  phi_max %.4f  "
               "mass balance %.1e  Newton/step %.2f  %.3f s  -> %s\n",
               sc.name, s->t, stats.steps, stats.rejected, sc.cells, stats.phi_max,
               (m1 - m0 - stats.mass_in) / scale,
               stats.steps ? (double)stats.newton_iterations / stats.steps : 0.0, stats.wall_s, out);
        if (sc.hypo.enabled) {
            printf("%-20s switches: %ld flow -> solid, %ld solid -> flow, largest stress jump %.1e", "",
                   stats.to_solid, stats.to_flow, stats.jump_max);
            if (stats.fail_time >= 0.0)
                printf("; first failure t = %.6g s at angle %.4f deg (f_Y = %.1e)", stats.fail_time,
                       stats.fail_angle, stats.fail_fY);
            printf("\n");
        }
        if (sc.stop == EKM_STOP_STEADY && stats.steady)
            printf("%-20s steady at t = %.6g s (held from %.6g s, drift %.2e 1/s < steady_tol %.2e 1/s)\n",
                   "", s->t, stats.steady_time, stats.steady_drift, sc.steady_tol);
        else if (sc.stop == EKM_STOP_STEADY)
            printf("%-20s NOT steady at t_end = %.6g s (drift %.2e 1/s, acceleration %.3e m/s^2)\n", "", s->t,
                   stats.steady_drift, stats.steady_acceleration);
        if (ekm_boundary_pressure_wall(&sc.top))
            printf("%-20s gap %.6g m (initial %.6g m) at top pressure %.6g Pa\n", "", s->n * s->dz, sc.length,
                   sc.top.pressure);
    }
    ekm_step_free(stepper);
    ekm_local_slab_free(slab);
    ekm_state_free(s);
    ekm_scenario_free(&sc);
    return code;
}

int main(int argc, char **argv)
{
    gsl_set_error_handler_off();
    ekm_error err = {0};
    if (ekm_atomic_install_signal_cleanup(&err) != EKM_OK)
        return fail(&err, EKM_EINTERNAL);
    if (argc < 2) {
        usage(stderr);
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("ekm %s\n", EKMBENCH_VERSION);
        return 0;
    }
    if (strcmp(argv[1], "run") == 0)
        return cmd_run(argc - 2, argv + 2);
    if (strcmp(argv[1], "scenario") == 0)
        return ekm_scenario_cli_main(argc - 2, argv + 2, "ekm", "ekm scenario");
    if (strcmp(argv[1], "agree") == 0)
        return ekm_agree_cli_main(argc - 2, argv + 2);
    if (strcmp(argv[1], "homog") == 0)
        return ekm_homog_cli_main(argc - 2, argv + 2);
    if (strcmp(argv[1], "steady") == 0)
        return ekm_steady_cli_main(argc - 2, argv + 2);
    fprintf(stderr, "ekm: unknown command '%s' (see ekm --help)\n", argv[1]);
    return ekm_status_exit_code(EKM_EUSAGE);
}
