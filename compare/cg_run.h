/* cg_run.h: the `ekmcompare cg` pipeline: dumps -> selected snapshots ->
 * particles -> kernel sums -> windows of block averages -> fields with
 * standard errors -> HDF5 (and CSV), written atomically.
 *
 * Snapshots are streamed file after file (memory is one snapshot plus the
 * block store); a step already seen (restart overlap between files) is
 * skipped. The time of a snapshot is ITEM: TIME when the dump has it,
 * otherwise step x dt (--dt); times increase strictly (cg_snapshot_time).
 * --steady reads the selection twice: first to find the steady start by
 * MSER-5 on the kinetic energy per unit mass and (on a non-periodic axis)
 * the centre of mass, then to average.
 *
 * The options: cg_opts.h. The steps, one module each: cg_input.h (dumps -> selected snapshots ->
 * particles), contacts.h (pair dumps -> contacts), steadiness.h (the steady
 * start), cg.h (kernel sums of one snapshot), window.h (averaging windows
 * and standard errors), cg_output.h (HDF5 and CSV writers).
 */
#ifndef CG_RUN_H
#define CG_RUN_H

#include <stdint.h>
#include <stdio.h>

#include "cg_opts.h"
#include "status.h"

/* The 1D profile, or with o->axis2 >= 0 the 2D grid (cg2d_run.h). */
ekm_status cg_run(const cg_run_opts *o, ekm_error *err);

#endif
