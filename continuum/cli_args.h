/* cli_args.h: the command line `ekm run` and `ekm steady` share:
 * FILE.ini [-o OUT.h5] [--material FIT.ini] [--set S.K=V ...] [--quiet]
 * (and for steady [--from RUN.h5]; for run [--checkpoint CKPT.h5
 * [--checkpoint-every S]] and [-- PETSc options]: "--" ends ekm's
 * options, the words after it are kept for the 2D solver's PETSc);
 * the default output is the scenario file's name with .h5 in the current
 * directory. */
#ifndef EKM_CLI_ARGS_H
#define EKM_CLI_ARGS_H

#include <stddef.h>

#include "status.h"

typedef struct {
    const char *ini, *out, *material, *from; /* from: NULL unless given */
    int quiet;
    const char *checkpoint;    /* run: the 2D restart file, NULL unless given */
    double checkpoint_every_s; /* run: wall time between checkpoints [s] (default 600) */
    const char **sets;         /* the --set values, n_sets of them */
    size_t n_sets;
    int dashdash;      /* 1: a "--" was given (with_petsc) */
    char **petsc_args; /* the words after "--" (into argv), n_petsc_args of them */
    int n_petsc_args;
    char out_buf[1024]; /* the default output's name */
} ekm_cli_args;

/* Parse argv (the words after the subcommand CMD, "run" or "steady");
 * with_from: accept --from; with_petsc: accept "--" and keep the rest,
 * and --checkpoint, --checkpoint-every.
 * 0, or the exit code (docs/exit-codes.md) after one error line "ekm CMD:
 * ..." on stderr.  ekm_cli_args_free() in every case. */
int ekm_cli_args_parse(const char *cmd, int argc, char **argv, int with_from, int with_petsc,
                       ekm_cli_args *a);
void ekm_cli_args_free(ekm_cli_args *a);

/* The output and its XDMF sidecar (and a checkpoint) may be written:
 * their folder is writable and none is an input (the scenario,
 * --material, --from) or, for the checkpoint, the output. */
ekm_status ekm_cli_args_check_outputs(const ekm_cli_args *a, ekm_error *err);

#endif
