/* scenario_cli.c: print a resolved scenario as JSON (scenario_cli.h). */
#include "scenario_cli.h"

#include <stdlib.h>
#include <string.h>

#include "resolve.h"
#include "scenario.h"
#include "scenario_json.h"
#include "status.h"

void ekm_scenario_cli_help(FILE *fp)
{
    fprintf(fp, "Prints the resolved scenario as one JSON object on stdout\n"
                "(docs/resolved-scenario.md): every key of every section with its value as\n"
                "written and where it came from (FILE:LINE, --set or default), [dem] and\n"
                "[compare] looked up for the engine and size, and the sweep points with\n"
                "their tags and the --set overrides of `ekm run` for each.\n"
                "  --engine E       liggghts or lammps: choose the <engine>.k variants\n"
                "  --size S         smoke or ref: choose the <size>.k variants and the sweep\n"
                "  --point TAG      keep only that sweep point\n"
                "  --material F     take [material] from F (a fit's FIT.ini)\n"
                "  --set s.k=v      override one key (repeatable)\n"
                "  --json           the output format (required)\n");
}

int ekm_scenario_cli_main(int argc, char **argv, const char *prog, const char *cmd)
{
    const char *ini = NULL, *engine = NULL, *size = NULL, *point = NULL, *material = NULL;
    int json = 0;
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    size_t n_sets = 0;
    if (!sets) {
        fprintf(stderr, "%s: out of memory\n", prog);
        return ekm_status_exit_code(EKM_ENOMEM);
    }
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--engine") == 0 && i + 1 < argc)
            engine = argv[++i];
        else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc)
            size = argv[++i];
        else if (strcmp(argv[i], "--point") == 0 && i + 1 < argc)
            point = argv[++i];
        else if (strcmp(argv[i], "--material") == 0 && i + 1 < argc)
            material = argv[++i];
        else if (strcmp(argv[i], "--set") == 0 && i + 1 < argc)
            sets[n_sets++] = argv[++i];
        else if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (argv[i][0] == '-' || ini) {
            fprintf(stderr, "%s: unexpected argument '%s' (see %s --help)\n", cmd, argv[i], prog);
            free(sets);
            return ekm_status_exit_code(EKM_EUSAGE);
        } else
            ini = argv[i];
    }
    if (!ini || !json) {
        fprintf(stderr, "%s: %s (see %s --help)\n", cmd,
                !ini ? "missing scenario file" : "missing --json (the output format)", prog);
        free(sets);
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    ekm_error err = {0};
    ekm_scenario sc;
    ekm_resolved res = {0};
    ekm_status st = ekm_scenario_load_material(&sc, ini, material, sets, n_sets, &err);
    free(sets);
    if (st == EKM_OK)
        st = ekm_resolve(&sc, engine, size, &res, &err);
    if (st == EKM_OK && point)
        st = ekm_resolve_keep_point(&res, point, &err);
    if (st == EKM_OK)
        st = ekm_json_write_resolved(stdout, &sc, &res, &err);
    ekm_resolve_free(&res);
    ekm_scenario_free(&sc);
    if (st == EKM_OK)
        return 0;
    ekm_error_print(prog, &err);
    return ekm_status_exit_code(st);
}
