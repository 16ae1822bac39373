/* ekmscenario: print a scenario file's resolved scenario as JSON, without
 * the solvers (scenario_cli.h; `ekm scenario` is the same command). */
#include <stdio.h>
#include <string.h>

#include "ekm_version.h"
#include "scenario_cli.h"
#include "status.h"

int main(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("usage: ekmscenario FILE.ini [--engine liggghts|lammps] [--size smoke|ref]\n"
               "                   [--point TAG] [--material FIT.ini] [--set section.key=value ...] --json\n"
               "\n");
        ekm_scenario_cli_help(stdout);
        printf("\nExit codes (docs/exit-codes.md): 0 success; 1 usage error; 2 bad scenario\n"
               "file, material file or --set value; 3 a file could not be read or written;\n"
               "5 out of memory.\n");
        return 0;
    }
    if (argc == 2 && strcmp(argv[1], "--version") == 0) {
        printf("ekmscenario %s\n", EKMBENCH_VERSION);
        return 0;
    }
    return ekm_scenario_cli_main(argc - 1, argv + 1, "ekmscenario", "ekmscenario");
}
