/* tool_keys.h: the registry of the other tools' keys in a scenario file
 * ([dem] [compare] [campaign] [figures]: docs/scenario-format.md), with
 * each key's type, default and sweep, and the check of one key as written.
 *
 * A key may be written plain (k) or with a prefix naming the DEM engine or
 * the size it holds for: <engine>.k, <size>.k, <engine>.<size>.k (engines
 * liggghts and lammps, sizes smoke and ref); resolve.h picks the value.
 */
#ifndef EKM_TOOL_KEYS_H
#define EKM_TOOL_KEYS_H

#include <stddef.h>

#include "number.h"

typedef enum {
    EKM_TOOL_NUMBER,  /* a decimal floating-point literal */
    EKM_TOOL_INTEGER, /* a decimal integer */
    EKM_TOOL_FLAG,    /* 0 or 1 */
    EKM_TOOL_NUMBERS, /* numbers separated by blanks (a sweep list) */
    EKM_TOOL_STRING,  /* free text */
    EKM_TOOL_WORD,    /* a name: a letter, then letters, digits, '_' */
    EKM_TOOL_FIELDS,  /* field names separated by commas */
    EKM_TOOL_ENUM,    /* one of the words of `choices` */
    EKM_TOOL_CG       /* options of `ekmcompare cg` (cg_keys.h) */
} ekm_tool_type;

/* The sweep a [dem] key belongs to: its keys make the scenario one.
 * EKM_SWEEP_SHEAR: a key of both simple-shear sweeps (phis x rates, or
 * pressures x rates); without phis or pressures it is the phi sweep. */
typedef enum {
    EKM_SWEEP_NONE = 0,
    EKM_SWEEP_THETA,
    EKM_SWEEP_SHEAR,
    EKM_SWEEP_PHI_RATE,
    EKM_SWEEP_P_RATE,
    EKM_SWEEP_SOURCE
} ekm_sweep_kind;

typedef struct {
    const char *section;
    const char *key;
    ekm_tool_type type;
    const char *choices;  /* EKM_TOOL_ENUM: the allowed words, blank-separated */
    const char *dflt;     /* default as written, or NULL (none, or derived below) */
    ekm_sweep_kind sweep; /* the sweep this key belongs to, or EKM_SWEEP_NONE */
} ekm_tool_key;

/* 1 if section is one of the other tools' sections: dem compare campaign figures. */
int ekm_tool_keys_is_section(const char *section);

/* 1 if word is a DEM engine name (liggghts, lammps); a size name (smoke, ref). */
int ekm_tool_keys_is_engine(const char *word);
int ekm_tool_keys_is_size(const char *word);

/* Split a key as written into its prefix (engine., size. or engine.size.)
 * and its base name (*base points into written). Returns 0 for any other
 * prefix. */
int ekm_tool_keys_split(const char *written, const char **base);

/* The registry entry of section's key base, or NULL. */
const ekm_tool_key *ekm_tool_keys_find(const char *section, const char *base);

/* The registry in order: its length, and entry i < ekm_tool_keys_count(). */
size_t ekm_tool_keys_count(void);
const ekm_tool_key *ekm_tool_keys_at(size_t i);

/* Check one key of a tool section as written (key with its prefix) and its
 * value. Returns 1 when they are valid; otherwise 0 and why holds the
 * message without the file:line, e.g. "[dem] ref.lx: expected a number, got '2x'". */
int ekm_tool_keys_check(const char *section, const char *key, const char *value, char *why, size_t size);

#endif
