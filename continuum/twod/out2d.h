/* out2d.h: the output file of a 2D run (ekm run on a [domain] with
 * cells_x > 1): HDF5 and its XDMF sidecar, written by rank 0.
 *
 * Layout (docs/output-format.md, "2D runs"): as the 1D file (h5out.h), with
 *   /x                      cell centres along x [m], double[nx]
 *   /z                      cell centres along z [m], double[nz]
 *   /t                      output times [s], double[nt]
 *   /gap                    with a pressure-controlled top wall: the height
 *                           of each frame [m], double[nt] (/z: the centres
 *                           of the scenario's length; frame k's are
 *                           (j + 1/2) gap[k]/nz)
 *   /phi /vx /vz /T /P /sxx /szz /sxz   double[nt][nz][nx] (x fastest), SI,
 *                           cell-centred (the face velocities and corner
 *                           stresses interpolated to the centres, fields2d.c)
 *   /regime                 int32[nt][nz][nx] (fields.h's codes)
 * every dataset with a string attribute "units"; the root attributes of the
 * 1D file (every scenario key, gravity_x, gravity_z, variant, code_version,
 * scenario_file, created) plus ranks (MPI ranks of the run) and the
 * statistics the caller sets.  Built in memory (at most
 * EKM_H5OUT_MAX_BYTES), written under a temporary name and renamed on
 * commit with its sidecar (common/atomic.h, common/xdmf.h, 2D grid).
 */
#ifndef EKM2D_OUT2D_H
#define EKM2D_OUT2D_H

#include "scenario.h"
#include "status.h"

/* The fields of a frame, in this order. */
typedef enum {
    EKM2D_PHI = 0,
    EKM2D_VX,
    EKM2D_VZ,
    EKM2D_T,
    EKM2D_P,
    EKM2D_SXX,
    EKM2D_SZZ,
    EKM2D_SXZ,
    EKM2D_REGIME, /* stored as int32 (the values are small integers held in doubles) */
    EKM2D_NFIELDS
} ekm2d_field;

typedef struct ekm2d_writer ekm2d_writer;

/* Open PATH for a run of sc on nx x nz cells (cell sizes dx = width/nx,
 * dz = length/nz from sc) that will write at most max_frames frames; ranks
 * is recorded.  Rank 0 only. */
ekm_status ekm2d_writer_open(ekm2d_writer **out, const char *path, const ekm_scenario *sc, int ranks,
                             size_t max_frames, ekm_error *err);
/* Append one frame at time t [s] with cell size dz [m] along z (length
 * / nz unless the top wall moves): fields[k] is field k on the nz x nx
 * cells, x fastest (fields[k][iz * nx + ix]).  A value that is not finite
 * is EKM_ENUMERIC naming the field, cell and time (nothing is written). */
ekm_status ekm2d_writer_append(ekm2d_writer *w, double t, double dz,
                               const double *const fields[EKM2D_NFIELDS], ekm_error *err);
/* A number as a root attribute (run statistics), before commit. */
ekm_status ekm2d_writer_set_attr(ekm2d_writer *w, const char *name, double value, ekm_error *err);
/* Close, write the XDMF sidecar, rename both into place, free w. */
ekm_status ekm2d_writer_commit(ekm2d_writer *w, ekm_error *err);
/* Close and delete the temporary file, free w (NULL is harmless). */
void ekm2d_writer_abort(ekm2d_writer *w);

#endif
