#include "cli_args.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "status.h"
#include "xdmf.h"

static void default_output(const char *ini, char *out, size_t size)
{
    const char *base = strrchr(ini, '/');
    base = base ? base + 1 : ini;
    size_t len = strlen(base);
    if (len > 4 && strcmp(base + len - 4, ".ini") == 0)
        len -= 4;
    snprintf(out, size, "%.*s.h5", (int)len, base);
}

int ekm_cli_args_parse(const char *cmd, int argc, char **argv, int with_from, int with_petsc, ekm_cli_args *a)
{
    memset(a, 0, sizeof *a);
    a->checkpoint_every_s = 600.0;
    int every_given = 0;
    a->sets = calloc((size_t)argc + 1, sizeof *a->sets);
    if (!a->sets) {
        fprintf(stderr, "ekm %s: out of memory\n", cmd);
        return ekm_status_exit_code(EKM_ENOMEM);
    }
    for (int i = 0; i < argc; i++) {
        if (with_petsc && strcmp(argv[i], "--") == 0) {
            a->dashdash = 1;
            a->petsc_args = argv + i + 1;
            a->n_petsc_args = argc - i - 1;
            break;
        }
        if (strcmp(argv[i], "-o") == 0 && i + 1 < argc)
            a->out = argv[++i];
        else if (with_from && strcmp(argv[i], "--from") == 0 && i + 1 < argc)
            a->from = argv[++i];
        else if (strcmp(argv[i], "--material") == 0 && i + 1 < argc)
            a->material = argv[++i];
        else if (strcmp(argv[i], "--set") == 0 && i + 1 < argc)
            a->sets[a->n_sets++] = argv[++i];
        else if (strcmp(argv[i], "--quiet") == 0)
            a->quiet = 1;
        else if (with_petsc && strcmp(argv[i], "--checkpoint") == 0 && i + 1 < argc)
            a->checkpoint = argv[++i];
        else if (with_petsc && strcmp(argv[i], "--checkpoint-every") == 0 && i + 1 < argc) {
            char *end = NULL;
            const char *v = argv[++i];
            a->checkpoint_every_s = strtod(v, &end);
            if (end == v || *end || !(a->checkpoint_every_s >= 0.0) || !isfinite(a->checkpoint_every_s)) {
                fprintf(stderr, "ekm %s: --checkpoint-every '%s': expected a wall time >= 0 in seconds\n",
                        cmd, v);
                return ekm_status_exit_code(EKM_EUSAGE);
            }
            every_given = 1;
        } else if (argv[i][0] == '-' || a->ini) {
            fprintf(stderr, "ekm %s: unexpected argument '%s' (see ekm --help)\n", cmd, argv[i]);
            return ekm_status_exit_code(EKM_EUSAGE);
        } else
            a->ini = argv[i];
    }
    if (!a->ini) {
        fprintf(stderr, "ekm %s: missing scenario file (see ekm --help)\n", cmd);
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    if (!a->out) {
        default_output(a->ini, a->out_buf, sizeof a->out_buf);
        a->out = a->out_buf;
    }
    if (every_given && !a->checkpoint) {
        fprintf(stderr, "ekm %s: --checkpoint-every needs --checkpoint FILE (see ekm --help)\n", cmd);
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    return 0;
}

void ekm_cli_args_free(ekm_cli_args *a)
{
    free(a->sets);
    a->sets = NULL;
}

ekm_status ekm_cli_args_check_outputs(const ekm_cli_args *a, ekm_error *err)
{
    char xdmf[1100];
    ekm_xdmf_path(a->out, xdmf, sizeof xdmf);
    const char *inputs[3] = {a->ini};
    size_t n = 1;
    if (a->material)
        inputs[n++] = a->material;
    if (a->from)
        inputs[n++] = a->from;
    ekm_status st = ekm_xdmf_check_name(a->out, "-o", err);
    if (st == EKM_OK)
        st = ekm_atomic_check_target(a->out, err);
    if (st == EKM_OK)
        st = ekm_atomic_refuse_input(a->out, inputs, n, err);
    if (st == EKM_OK)
        st = ekm_atomic_refuse_input(xdmf, inputs, n, err);
    if (st == EKM_OK && a->checkpoint) {
        const char *taken[5] = {a->out, xdmf};
        size_t n_taken = 2;
        for (size_t i = 0; i < n; i++)
            taken[n_taken++] = inputs[i];
        st = ekm_atomic_check_target(a->checkpoint, err);
        if (st == EKM_OK)
            st = ekm_atomic_refuse_input(a->checkpoint, taken, n_taken, err);
    }
    return st;
}
