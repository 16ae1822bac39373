/* cg_keys.h: the options of `ekmcompare cg` as one typed table, read by
 * both the command line (compare/main.c) and the scenario reader, which
 * checks a scenario's [compare] cg_options with it when the file is read
 * (docs/scenario-format.md), so that a bad option fails before any DEM run.
 *
 * ekm_cg_keys_parse turns one option's value into typed values with the
 * error lines `ekmcompare cg` prints ("--width: expected a positive width,
 * got '-1'"); what the values mean and the checks between options are
 * compare/'s (cg_opts.h, cg_run.h).
 */
#ifndef EKM_CG_KEYS_H
#define EKM_CG_KEYS_H

#include <stddef.h>

#include "status.h"

/* The option's value: its kind and its checks. */
typedef enum {
    EKM_CG_OUT,              /* -o FILE.h5 */
    EKM_CG_CSV,              /* --csv FILE.csv */
    EKM_CG_AXIS,             /* --axis x|y|z */
    EKM_CG_AXES,             /* --axes z|x|y|x,z */
    EKM_CG_ENSEMBLE,         /* --ensemble */
    EKM_CG_KERNEL,           /* --kernel gauss|lucy|bins */
    EKM_CG_WIDTH,            /* --width W > 0 [m] */
    EKM_CG_BINS,             /* --bins N or NX,NZ */
    EKM_CG_DZ,               /* --dz D > 0 [m] */
    EKM_CG_RANGE,            /* --range LO:HI, LO < HI [m] */
    EKM_CG_RHO_P,            /* --rho-p R > 0 [kg/m^3] */
    EKM_CG_DT,               /* --dt DT > 0 [s] */
    EKM_CG_FROM,             /* --from T [s] */
    EKM_CG_TO,               /* --to T [s] */
    EKM_CG_STEPS,            /* --steps A:B, integers A <= B */
    EKM_CG_STEADY,           /* --steady */
    EKM_CG_EXACT,            /* --exact-kernel */
    EKM_CG_EVERY,            /* --every N >= 1 */
    EKM_CG_WINDOW,           /* --window W > 0 [s] */
    EKM_CG_TEMPERATURE,      /* --temperature particle|consistent */
    EKM_CG_STRESS,           /* --stress PREFIX or six names */
    EKM_CG_PAIRS,            /* --pairs FILE */
    EKM_CG_PAIR_COLUMNS,     /* --pair-columns 9 or 5 names */
    EKM_CG_TYPES,            /* --types T[,T...] */
    EKM_CG_EXPECT_SNAPSHOTS, /* --expect-snapshots N >= 1 */
    EKM_CG_QUIET             /* --quiet */
} ekm_cg_key_id;

typedef struct {
    const char *option; /* "--width" */
    ekm_cg_key_id id;
    int takes_value;     /* 1: the next word is its value */
    int in_scenario;     /* 1: [compare] cg_options may hold it (not the outputs, --dt, --quiet:
                            the campaign adds those) */
    const char *summary; /* for the help */
} ekm_cg_key;

#define EKM_CG_NAME_MAX  64 /* a stress or pair column name, its NUL included */
#define EKM_CG_TYPES_MAX 16 /* atom types --types may list */

/* One option's value, typed. */
typedef struct {
    ekm_cg_key_id id;
    const char *text;               /* the value as written (paths, the kernel's name) */
    double x, y;                    /* numbers; --range LO:HI, --steps A:B */
    size_t count, count_x;          /* --bins N (NX,NZ: count_x NX, count NZ), --every, --expect-snapshots */
    int axis, axis2;                /* --axis, --axes: 0 x, 1 y, 2 z; axis2 -1: none */
    int flag;                       /* --temperature: 1 consistent */
    char names[9][EKM_CG_NAME_MAX]; /* --stress (6), --pair-columns (9 or 5) */
    size_t n_names;
    int types[EKM_CG_TYPES_MAX]; /* --types */
    size_t n_types;
} ekm_cg_value;

/* The kernels --kernel names (compare/kernel.c has each). */
#define EKM_CG_KERNELS "gauss lucy bins"

/* The table's entry for option, or NULL. */
const ekm_cg_key *ekm_cg_keys_find(const char *option);

/* Parse value (NULL for an option without one) of option k into *out.
 * A bad value is EKM_EUSAGE with the command line's one line. */
ekm_status ekm_cg_keys_parse(const ekm_cg_key *k, const char *value, ekm_cg_value *out, ekm_error *err);

/* Check a [compare] cg_options value: options of the table that a
 * scenario may hold, each with a valid value. Returns 1, or 0 and why
 * (the message without the file:line). */
int ekm_cg_keys_check_line(const char *line, char *why, size_t size);

#endif
