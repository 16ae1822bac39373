/* scenario_cli.h: the command that prints a resolved scenario as JSON
 * (docs/resolved-scenario.md), shared by `ekmscenario` (scenario/main.c,
 * the small program the DEM runner and the campaign call without building
 * the solvers) and `ekm scenario` (its front in continuum/main.c).
 *
 *   FILE.ini [--engine liggghts|lammps] [--size smoke|ref] [--point TAG]
 *            [--material FIT.ini] [--set section.key=value ...] --json
 */
#ifndef EKM_SCENARIO_CLI_H
#define EKM_SCENARIO_CLI_H

#include <stdio.h>

/* The options' help, for a program's --help. */
void ekm_scenario_cli_help(FILE *fp);

/* Run the command on argv[0 .. argc) (the arguments after the command's
 * name). prog names the program in error lines ("ekm: ..."), cmd the
 * command in usage errors ("ekm scenario: missing scenario file").
 * Returns the exit code (docs/exit-codes.md): 0, or the code of the status
 * whose one line it printed on stderr. */
int ekm_scenario_cli_main(int argc, char **argv, const char *prog, const char *cmd);

#endif
