/* homog_cli.h: `ekm homog`, the EKM's steady homogeneous simple shear
 * (ekm_homog_shear, homogeneous.h) of a scenario's material on a grid of
 * volume fractions and shear rates, as one JSON object on stdout
 * (docs/model/law.md, "ekm homog"). */
#ifndef EKM_HOMOG_CLI_H
#define EKM_HOMOG_CLI_H

/* The command with its arguments after `homog` (argv[0] is the first of
 * them); returns the exit code of docs/exit-codes.md.  Prints nothing on
 * stdout unless every point was evaluated. */
int ekm_homog_cli_main(int argc, char **argv);

#endif
