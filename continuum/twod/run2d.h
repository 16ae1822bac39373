/* run2d.h: `ekm run` on a 2D scenario ([domain] cells_x > 1): PETSc's
 * start and end, the 2D solver's run (solver2d.h) and its output (out2d.h).
 *
 * Called by main.c after the scenario is loaded, on every MPI rank
 * (`mpirun -np N ekm run FILE.ini`); petsc_args are the command line's
 * words after "--" (PETSc options, e.g. -ekm_step_monitor, -ekm_v_ksp_converged_reason),
 * n_petsc_args of them.  Returns the run's status; err holds the message
 * (printed by rank 0 only, by the caller: ekm2d_is_rank0).
 *
 * With a checkpoint file the run writes its state there after an output
 * frame once checkpoint_every_s of wall time have passed since the last,
 * and after the last frame; a run that finds the file goes on from it (its
 * frames copied into the output, the same steps as a run never stopped),
 * also to a later t_end.  The output records stats.resumed_at_t [s].
 */
#ifndef EKM2D_RUN2D_H
#define EKM2D_RUN2D_H

#include "scenario.h"
#include "status.h"

typedef struct {
    const char *out;           /* output path (.h5) */
    int quiet;                 /* 1: no summary line, no progress */
    int progress;              /* 1: a progress line with ETA on stderr (rank 0; common/progress.h) */
    const char *checkpoint;    /* restart file (checkpoint2d.h), NULL: none; resumed from when it exists */
    double checkpoint_every_s; /* wall time between checkpoints [s] (one also after the last frame) */
    char **petsc_args;         /* PETSc options after "--" */
    int n_petsc_args;
} ekm2d_run_options;

ekm_status ekm2d_cmd_run(const ekm_scenario *sc, const ekm2d_run_options *opt, ekm_error *err);

/* 1 on rank 0 of the run (also before PETSc is started and after it ended: 1). */
int ekm2d_is_rank0(void);

#endif
