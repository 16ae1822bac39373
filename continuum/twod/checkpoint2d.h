/* checkpoint2d.h: the restart file of a 2D run (`ekm run FILE.ini
 * --checkpoint CKPT.h5`): the stepper's whole state (step2d.h:
 * ekm2d_restart), the output frames written so far and the wall time
 * spent, so that a run stopped by a job's time limit or a machine's end
 * goes on from its last checkpoint and takes the same steps as a run that
 * was never stopped (docs/model/twod.md "Checkpoints").
 *
 * HDF5, written by rank 0 under a temporary name and renamed
 * (common/h5.h), so that a checkpoint is whole or absent:
 *   root attributes  format ("ekm2d checkpoint 1"), code_version,
 *                    scenario_keys (every scenario key but run.t_end,
 *                    "section.key = value" a line), t [s], dz [m],
 *                    dt_prev, dt_solid, dt_change [s], mass_in [kg/m],
 *                    solid_lag_max [-], steps, rejected, newton_total,
 *                    to_solid, to_flow, solid_floor_steps, wall_time_s [s]
 *   /state           double[nz + 1][nx + 1][dof + 1] (step2d.h's layout)
 *   /frame_t         the output frames' times [s], double[k]
 *   /frame_dz        their cell sizes along z [m], double[k]
 *   /frames          double[k][EKM2D_NFIELDS][nz * nx] (out2d.h's fields)
 */
#ifndef EKM2D_CHECKPOINT2D_H
#define EKM2D_CHECKPOINT2D_H

#include <stddef.h>

#include "out2d.h"
#include "scenario.h"
#include "status.h"
#include "step2d.h"

typedef struct {
    ekm2d_restart state;
    size_t n_frames;        /* output frames written before the checkpoint */
    double *frame_t;        /* their times [s] */
    double *frame_dz;       /* their cell sizes along z [m] */
    double *frames;         /* [n_frames][EKM2D_NFIELDS][nz * nx] */
    double wall_s;          /* wall time of the run up to the checkpoint [s] */
    char code_version[128]; /* the ekm that wrote it (read) */
} ekm2d_checkpoint;

/* Write c to path (rank 0): the file appears whole or not at all. */
ekm_status ekm2d_checkpoint_write(const char *path, const ekm_scenario *sc, const ekm2d_checkpoint *c,
                                  ekm_error *err);

/* Read path into *c (rank 0; ekm2d_checkpoint_free releases it): EKM_EIO
 * unreadable, EKM_EINPUT not a checkpoint of sc (the first differing key
 * named: every key but run.t_end must be the same), of another grid, a
 * value that is not finite, or a time beyond sc's t_end. */
ekm_status ekm2d_checkpoint_read(const char *path, const ekm_scenario *sc, ekm2d_checkpoint *c,
                                 ekm_error *err);

void ekm2d_checkpoint_free(ekm2d_checkpoint *c);

#endif
