/* h5kind.h: which tool wrote an HDF5 input, from its root attributes, so
 * that a file given to the wrong option (`score --dem RUN.h5 --ekm CG.h5`)
 * is refused before it is read as the other kind.
 *
 * An `ekmcompare cg` output has the root attributes `kernel` and
 * `snapshots_used` (cg_output.c); an `ekm run` output has `stats.steps` and
 * `variant` (continuum/h5out.c, docs/output-format.md). Both have always
 * been written, so every committed file under results/ is recognised.
 */
#ifndef CG_H5KIND_H
#define CG_H5KIND_H

#include "h5.h"
#include "status.h"

typedef enum {
    CG_H5KIND_CG = 1u,  /* ekmcompare cg output */
    CG_H5KIND_EKM = 2u, /* ekm run output */
} cg_h5kind;

/* The kind of f: CG_H5KIND_CG, CG_H5KIND_EKM, or 0 (neither). */
unsigned cg_h5kind_of(ekm_h5_file *f);

/* EKM_EINPUT unless f is one of the kinds in `allowed` (a mask of
 * cg_h5kind): "CMD: OPTION PATH: not an ekmcompare cg output (written by
 * ekm run?)". cmd and option name the subcommand and its option. */
ekm_status cg_h5kind_check(ekm_h5_file *f, const char *cmd, const char *option, unsigned allowed,
                           ekm_error *err);

/* The same, opening the file at path (closed again). */
ekm_status cg_h5kind_check_path(const char *path, const char *cmd, const char *option, unsigned allowed,
                                ekm_error *err);

#endif
