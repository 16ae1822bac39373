/* fit_cli.h: the `ekmcompare fit` subcommand (docs/compare.md). */
#ifndef CG_FIT_CLI_H
#define CG_FIT_CLI_H

/* Run `ekmcompare fit ARGS` (argv without "ekmcompare fit"); prints the
 * one error line itself and returns the exit code of docs/exit-codes.md. */
int cg_fit_main(int argc, char **argv);

#endif
