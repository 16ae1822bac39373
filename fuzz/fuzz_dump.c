/* fuzz_dump.c: fuzz target for the ekmcompare dump reader (compare/dump.c).
 *
 * libFuzzer entry point: the input bytes are written to a scratch file and
 * read as a dump (text, gzip or binary: the reader sniffs the format) with
 * the columns ekmcompare selects, until the end or the first error. Any
 * crash, hang or sanitizer report is a bug; errors and truncation are the
 * expected outcome for most inputs.
 *
 * Built with -DCG_FUZZ_MAIN it is a replay driver instead: every file named
 * on the command line (or found in a named directory) is run once; ctest
 * runs it over the fixtures and fuzz/corpus under ASan/UBSan.
 * See fuzz/run.sh for the libFuzzer build.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dump.h"

static const char *const cols[] = {
    "x",  "y",    "z",      "xu",       "zu",      "xs",      "ys",      "zs",      "zsu",     "vx",     "vy",
    "vz", "mass", "radius", "diameter", "c_sa[1]", "c_sa[2]", "c_sa[3]", "c_sa[4]", "c_sa[5]", "c_sa[6]"};

static void read_dump(const char *path)
{
    cg_dump *d;
    ekm_error err;
    if (cg_dump_open(&d, path, cols, sizeof cols / sizeof *cols, &err))
        return;
    /* the value checks cg_input.c asks for: velocities, mass, radius, diameter */
    for (size_t j = 9; j < 12; j++)
        cg_dump_expect(d, j, CG_DUMP_VELOCITY);
    cg_dump_expect(d, 12, CG_DUMP_POSITIVE);
    cg_dump_expect(d, 13, CG_DUMP_RADIUS);
    cg_dump_expect(d, 14, CG_DUMP_DIAMETER);
    cg_snapshot s;
    memset(&s, 0, sizeof s);
    double sum = 0;
    int n = 0;
    while (n++ < 1000 && cg_dump_next(d, &s, &err) == EKM_OK) {
        /* touch every value that was read */
        for (int64_t i = 0; i < s.natoms; i++)
            for (size_t j = 0; j < s.nsel; j++)
                if (s.present[j])
                    sum += s.data[(size_t)i * s.nsel + j];
    }
    if (sum == 12345.678)
        fprintf(stderr, "(unlikely)\n");
    cg_snapshot_free(&s);
    cg_dump_close(d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/cg_fuzz_%ld.dump", (long)getpid());
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return 0;
    fwrite(data, 1, size, fp);
    fclose(fp);
    read_dump(path);
    unlink(path);
    return 0;
}

#ifdef CG_FUZZ_MAIN
#include "replay.h"

static int replay_one(const char *path)
{
    read_dump(path);
    return 0;
}

int main(int argc, char **argv)
{
    return fuzz_replay("fuzz_dump", argv + 1, argc - 1, replay_one);
}
#endif
