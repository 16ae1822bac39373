/* fuzz_scenario.c: fuzz target for the scenario reader (scenario/scenario.c,
 * resolve.c, the JSON of `ekm scenario`) and --set parsing.
 *
 * libFuzzer entry point: the input's first line is one --set override
 * (none when the line is empty), the rest the scenario file's text; a line
 * "%%" in it ends the scenario file and starts a --material file. The texts
 * go through the public reader API in memory (ekm_scenario_load_texts: no
 * file is opened or written); a scenario that loads is then resolved for an
 * engine and size picked by the input's length, its defaults formatted and
 * its resolved JSON written to memory. Any crash, hang or sanitizer report
 * is a bug; errors are the expected outcome for most inputs.
 *
 * Built with -DEKM_FUZZ_MAIN it is a replay driver instead: every file named
 * on the command line (or found in a named directory) is run once; a file
 * whose name ends in ".ini" is a plain scenario file (no --set), so the
 * shipped scenarios replay as they are. ctest runs it over scenarios/,
 * fuzz/scenario_seeds and fuzz/corpus_scenario under ASan/UBSan with
 * `ulimit -f 0` (the reader must write no file).
 * See fuzz/run.sh (--target scenario) for the libFuzzer build.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "resolve.h"
#include "scenario.h"
#include "scenario_json.h"

/* Load, resolve and print one input; returns nothing (a crash is the bug). */
static void read_scenario(const char *override, const char *text, size_t size)
{
    ekm_scenario_text file = {.name = "fuzz.ini", .text = text, .size = size};
    ekm_scenario_text material = {.name = "fuzz_material.ini"};
    for (size_t i = 0; i + 3 <= size; i++)
        if ((i == 0 || text[i - 1] == '\n') && memcmp(text + i, "%%", 2) == 0 && text[i + 2] == '\n') {
            file.size = i;
            material.text = text + i + 3;
            material.size = size - i - 3;
            break;
        }
    const char *sets[1] = {override};
    ekm_scenario sc;
    ekm_error err = {0};
    ekm_status st =
        ekm_scenario_load_texts(&sc, &file, material.text ? &material : NULL, sets, override ? 1 : 0, &err);
    if (st == EKM_OK) {
        static const char *const engines[] = {NULL, "liggghts", "lammps"};
        static const char *const sizes[] = {NULL, "smoke", "ref"};
        char value[200];
        for (size_t i = 0; i < ekm_scenario_key_count(); i++)
            (void)ekm_scenario_key_default(&sc, i, value, sizeof value);
        ekm_resolved r = {0};
        if (ekm_resolve(&sc, engines[size % 3], sizes[(size / 3) % 3], &r, &err) == EKM_OK) {
            char *json = NULL;
            size_t json_size = 0;
            FILE *mem = open_memstream(&json, &json_size);
            if (mem) {
                (void)ekm_json_write_resolved(mem, &sc, &r, &err);
                fclose(mem);
            }
            free(json);
        }
        ekm_resolve_free(&r);
    } else {
        /* every error is one line naming the file or the --set, and bad input
         * (no file is read: never an I/O error) */
        const int named = strncmp(err.message, "fuzz.ini", 8) == 0 ||
                          strncmp(err.message, "fuzz_material.ini", 17) == 0 ||
                          strncmp(err.message, "--set ", 6) == 0;
        if (strchr(err.message, '\n') || !named || st != EKM_EINPUT) {
            fprintf(stderr, "fuzz_scenario: status %d, error not one line naming the input: %s\n", (int)st,
                    err.message);
            abort();
        }
    }
    ekm_scenario_free(&sc);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *text = (const char *)data;
    const char *nl = memchr(text, '\n', size);
    const size_t first = nl ? (size_t)(nl - text) : size;
    /* the override is a C string (argv has no NUL inside): up to a NUL */
    char *override = malloc(first + 1);
    if (!override)
        return 0;
    memcpy(override, text, first);
    override[first] = '\0';
    const size_t rest = nl ? first + 1 : size;
    read_scenario(first > 0 ? override : NULL, text + rest, size - rest);
    free(override);
    return 0;
}

#ifdef EKM_FUZZ_MAIN
#include "replay.h"

static int replay_file(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return 1;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap + 1);
    for (size_t got; buf && (got = fread(buf + 1 + n, 1, cap - n, fp)) > 0;) {
        n += got;
        if (n == cap) {
            char *b = realloc(buf, 2 * cap + 1);
            if (!b) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = b;
            cap *= 2;
        }
    }
    fclose(fp);
    if (!buf)
        return 1;
    const size_t len = strlen(path);
    if (len > 4 && strcmp(path + len - 4, ".ini") == 0) {
        buf[0] = '\n'; /* a plain scenario file: no override */
        LLVMFuzzerTestOneInput((const uint8_t *)buf, n + 1);
    } else {
        LLVMFuzzerTestOneInput((const uint8_t *)buf + 1, n);
    }
    free(buf);
    return 0;
}

int main(int argc, char **argv)
{
    return fuzz_replay("fuzz_scenario", argv + 1, argc - 1, replay_file);
}
#endif
