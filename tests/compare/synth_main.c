/* cg_synth: write a synthetic dump (benchmark and manual tests).
 * usage: cg_synth OUT text|gz|bin NATOMS NSNAP [liggghts]
 *        cg_synth OUT pile|pile_nofz   (a synthetic pile, with or without fx fy fz) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "synth.h"

int main(int argc, char **argv)
{
    if (argc == 3 && (!strcmp(argv[2], "pile") || !strcmp(argv[2], "pile_nofz"))) {
        /* the synthetic hydrostatic pile of synth.h (ekmcompare base) */
        synth_pile_opts p = synth_pile_default();
        p.with_fz = !strcmp(argv[2], "pile");
        if (synth_pile_write(argv[1], &p)) {
            fprintf(stderr, "cg_synth: cannot write %s\n", argv[1]);
            return 1;
        }
        return 0;
    }
    if (argc < 5) {
        fprintf(stderr, "usage: cg_synth OUT text|gz|bin NATOMS NSNAP [liggghts]\n");
        return 2;
    }
    synth_opts o = synth_default();
    o.format = !strcmp(argv[2], "gz") ? SYNTH_GZ : !strcmp(argv[2], "bin") ? SYNTH_BIN : SYNTH_TEXT;
    o.natoms = (size_t)strtoull(argv[3], NULL, 10);
    o.nsnap = (size_t)strtoull(argv[4], NULL, 10);
    o.liggghts = argc > 5 && !strcmp(argv[5], "liggghts");
    o.lx = o.ly = 0.05;
    o.lz = 0.2;
    o.gdot = 10.0;
    if (synth_write(argv[1], &o)) {
        fprintf(stderr, "cg_synth: cannot write %s\n", argv[1]);
        return 1;
    }
    return 0;
}
