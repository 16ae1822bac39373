/* steady_cli.h: `ekm steady FILE.ini [-o OUT.h5] [--from RUN.h5]
 * [--material FIT.ini] [--set S.K=V ...] [--quiet]`: the steady state of
 * the scenario by ekm_steady_solve (steady_solve.h), written as `ekm run`
 * writes its output (one time level) with the solver's report as root
 * attributes (docs/model/steady.md "Steady solver"). */
#ifndef EKM_STEADY_CLI_H
#define EKM_STEADY_CLI_H

#include "state.h"
#include "status.h"

/* argv excludes "ekm steady"; returns the exit code. */
int ekm_steady_cli_main(int argc, char **argv);

/* The guess from the last frame of an `ekm run` / `ekm steady` output:
 * phi, vx, T and the cell height (from /z) into s. EKM_EINPUT naming the
 * file and dataset when its grid is not the scenario's (cells; for a
 * fixed wall the cell centres), EKM_EIO when it cannot be read. */
ekm_status ekm_steady_read_guess(const char *path, const ekm_scenario *sc, ekm_state *s, ekm_error *err);

#endif
