/* h5out.h: the run's output file (HDF5) and its XDMF sidecar.
 *
 * Layout (docs/output-format.md):
 *   /t                      output times [s], double[nt]
 *   /z                      cell centres [m] of each frame, double[nt][nz]
 *                           (a pressure-held top wall moves them)
 *   /gap                    wall-to-wall gap [m], double[nt] (only with a
 *                           pressure-held top wall)
 *   /phi /vx /vz /T /P /sxz /szz   double[nt][nz], SI, cell-centred
 *   /regime                 int32[nt][nz] (fields.h)
 *   every dataset has a string attribute "units";
 *   /T is NAN in every cell for a closure without a granular temperature
 *   (has_temperature = 0: mu_i; its T is n/a);
 *   root attributes: every scenario key as "section.key" (number or
 *   string), gravity_x, gravity_z [m/s^2], variant, closure (its name),
 *   has_temperature (1 or 0), code_version,
 *   scenario_file, created (UTC); with [hypo] enabled also
 *   hypo.to_solid, hypo.to_flow (switch counts), hypo.jump_max (largest
 *   relative stress jump at a switch), hypo.fail_time [s], hypo.fail_angle
 *   [deg], hypo.fail_fY (first solid -> flow switch; fail_time -1: none).
 *   /xdmf/FIELD/I: row I of FIELD as a virtual dataset (no copy), for the
 *   XDMF sidecar (common/xdmf.h).
 * The file is built in memory (at most EKM_H5OUT_MAX_BYTES, estimated when
 * it is opened from the frames the run will write: more is EKM_EINPUT
 * before the run), written under a temporary (common/atomic.h)
 * and renamed to PATH on commit together with its sidecar
 * PATH-without-.h5 + ".xdmf", which lets ParaView open the time series
 * (any of its three XDMF readers; the profile along ParaView's Z axis).
 */
#ifndef EKM_H5OUT_H
#define EKM_H5OUT_H

#include "h5.h"
#include "scenario.h"
#include "state.h"
#include "status.h"

/* The largest output an ekm run may build in memory [bytes] (its image is
 * copied once more when written out at the end). */
#define EKM_H5OUT_MAX_BYTES (4.0 * 1024 * 1024 * 1024)

typedef struct ekm_h5_writer ekm_h5_writer;

ekm_status ekm_h5_writer_open(ekm_h5_writer **out, const char *path, const ekm_scenario *sc,
                              const ekm_state *s, ekm_error *err);
/* Append the state as one more time row. */
ekm_status ekm_h5_writer_append(ekm_h5_writer *w, const ekm_state *s, ekm_error *err);
/* A number as a root attribute (run statistics, e.g. the solid regime's
 * switch counts and first failure); before commit. */
ekm_status ekm_h5_writer_set_attr(ekm_h5_writer *w, const char *name, double value, ekm_error *err);
/* An array of numbers as a root attribute (ekm steady's residual history). */
ekm_status ekm_h5_writer_set_attr_array(ekm_h5_writer *w, const char *name, const double *values, size_t n,
                                        ekm_error *err);
/* The root attributes of a scenario's output (the 1D file's and the 2D
 * run's, twod/out2d.h): every scenario key as "section.key" (a number when
 * its value reads as one, else the string), gravity_x, gravity_z, variant,
 * code_version, scenario_file, material_file (when one), scenario,
 * created (UTC). */
ekm_status ekm_h5out_scenario_attrs(ekm_h5_file *file, const ekm_scenario *sc, ekm_error *err);

/* Close, write the XDMF sidecar, rename both into place, free w. */
ekm_status ekm_h5_writer_commit(ekm_h5_writer *w, ekm_error *err);
/* Close and delete the temporary file, free w (NULL is harmless). */
void ekm_h5_writer_abort(ekm_h5_writer *w);

#endif
