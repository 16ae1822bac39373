/* tool_keys.c: the registry of the other tools' keys and their check
 * (tool_keys.h). */
#include "tool_keys.h"

#include "cg_keys.h"
#include "schema.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Registry of the other tools' keys (docs/scenario-format.md). */
static const ekm_tool_key TOOL_KEYS[] = {
    {"dem", "diameter", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "spread", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "youngs", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "poisson", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "restitution", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "restitution_input", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE}, /* default: restitution */
    {"dem", "friction", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "dt", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "seed", EKM_TOOL_INTEGER, NULL, "15485863", EKM_SWEEP_NONE},
    {"dem", "thermo_every", EKM_TOOL_INTEGER, NULL, "1000", EKM_SWEEP_NONE},
    {"dem", "dump_every", EKM_TOOL_INTEGER, NULL, "5000", EKM_SWEEP_NONE},
    {"dem", "lx", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "ly", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "t_end", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},      /* default: [run] t_end */
    {"dem", "settle_max", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE}, /* default: [dem] t_end */
    {"dem", "rest_ke", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "t_settle", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_THETA},
    {"dem", "t_flow", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_THETA},
    {"dem", "angles", EKM_TOOL_NUMBERS, NULL, NULL, EKM_SWEEP_THETA}, /* default: [gravity] angle */
    {"dem", "pressure", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE}, /* default: [top] pressure */
    {"dem", "wall_damping", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "t_compress", EKM_TOOL_NUMBER, NULL, "0", EKM_SWEEP_NONE},
    {"dem", "t_run", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "strain", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_SHEAR},
    {"dem", "phis", EKM_TOOL_NUMBERS, NULL, NULL, EKM_SWEEP_PHI_RATE},    /* default: [initial] phi */
    {"dem", "pressures", EKM_TOOL_NUMBERS, NULL, NULL, EKM_SWEEP_P_RATE}, /* no default */
    {"dem", "rates", EKM_TOOL_NUMBERS, NULL, NULL, EKM_SWEEP_SHEAR},      /* default: the walls' rate */
    {"dem", "p_gain", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_NONE},
    {"dem", "dump_strain", EKM_TOOL_NUMBER, NULL, NULL,
     EKM_SWEEP_NONE}, /* per point dump_every of a shear sweep */
    /* the sand pile: poured from a source of each width over the floor */
    {"dem", "pile_mass", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_SOURCE},
    {"dem", "pour_rate", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_SOURCE},
    {"dem", "pour_speed", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_SOURCE},
    {"dem", "pour_height", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_SOURCE},
    {"dem", "source_widths", EKM_TOOL_NUMBERS, NULL, NULL, EKM_SWEEP_SOURCE},
    {"dem", "plate_width", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_SOURCE},    /* the floor's extent [d] */
    {"dem", "hopper_gap", EKM_TOOL_NUMBER, NULL, NULL, EKM_SWEEP_SOURCE},     /* hopper above the apex [d] */
    {"dem", "hopper_stages", EKM_TOOL_INTEGER, NULL, NULL, EKM_SWEEP_SOURCE}, /* times the hopper is raised */
    {"dem", "rolling_friction", EKM_TOOL_NUMBER, NULL, "0",
     EKM_SWEEP_NONE}, /* mu_r: torque limit mu_r R* F_n */
    {"dem", "seeds", EKM_TOOL_INTEGER, NULL, NULL,
     EKM_SWEEP_NONE}, /* ensemble size (scripts/dem/ensemble.sh) */
    {"dem", "timeout", EKM_TOOL_INTEGER, NULL, "900", EKM_SWEEP_NONE},
    {"dem", "require_steady", EKM_TOOL_FLAG, NULL, "0", EKM_SWEEP_NONE},
    {"dem", "steady_tol", EKM_TOOL_NUMBER, NULL, "0.05", EKM_SWEEP_NONE},
    {"compare", "cg_options", EKM_TOOL_CG, NULL, NULL, EKM_SWEEP_NONE},
    {"compare", "fields", EKM_TOOL_FIELDS, NULL, NULL, EKM_SWEEP_NONE},
    {"compare", "ekm_time", EKM_TOOL_ENUM, "last interp", "interp", EKM_SWEEP_NONE},
    {"compare", "shift", EKM_TOOL_NUMBER, NULL, "0", EKM_SWEEP_NONE},
    {"compare", "support", EKM_TOOL_NUMBER, NULL, "0.1", EKM_SWEEP_NONE},
    {"compare", "scalars", EKM_TOOL_FIELDS, NULL, NULL, EKM_SWEEP_NONE},
    /* se: the cg output's SEs are the DEM's noise; none: it has no noise
     * estimate (a 2D pile: one run at rest), noise-normalised errors n/a */
    {"compare", "noise", EKM_TOOL_ENUM, "se none", "se", EKM_SWEEP_NONE},
    /* the calibration (docs/campaign.md "Calibration"): the training set
     * the scenario's points belong to, and how that set is fitted */
    {"campaign", "train", EKM_TOOL_WORD, NULL, "none", EKM_SWEEP_NONE},
    {"campaign", "fit", EKM_TOOL_ENUM, "rheology scenario", NULL, EKM_SWEEP_NONE},
    {"campaign", "fit_params", EKM_TOOL_FIELDS, NULL, NULL, EKM_SWEEP_NONE},
    {"campaign", "fit_fields", EKM_TOOL_FIELDS, NULL, NULL, EKM_SWEEP_NONE},
    {"campaign", "fit_engine", EKM_TOOL_ENUM, "lammps liggghts", "lammps", EKM_SWEEP_NONE},
    {"campaign", "fit_starts", EKM_TOOL_INTEGER, NULL, NULL, EKM_SWEEP_NONE},
    /* the closure styles fitted on the set beside the EKM, each a parameter
     * set <train>_<closure> started from scenarios/closures/<closure>.ini */
    {"campaign", "fit_closures", EKM_TOOL_FIELDS, NULL, NULL, EKM_SWEEP_NONE},
    /* the closures' own constants fitted (each closure takes its own; none
     * given: all of them) */
    {"campaign", "fit_closure_params", EKM_TOOL_FIELDS, NULL, NULL, EKM_SWEEP_NONE},
};
#define N_TOOL_KEYS (sizeof TOOL_KEYS / sizeof TOOL_KEYS[0])

/* The sections of the other tools; [figures] has no keys yet. */
static const char *const TOOL_SECTIONS[] = {"dem", "compare", "campaign", "figures"};
static const char *const ENGINES[] = {"liggghts", "lammps"};
static const char *const SIZES[] = {"smoke", "ref"};

int ekm_tool_keys_is_section(const char *section)
{
    for (size_t i = 0; i < sizeof TOOL_SECTIONS / sizeof TOOL_SECTIONS[0]; i++)
        if (strcmp(section, TOOL_SECTIONS[i]) == 0)
            return 1;
    return 0;
}

static int word_in(const char *const *words, size_t n, const char *w, size_t len)
{
    for (size_t i = 0; i < n; i++)
        if (strlen(words[i]) == len && strncmp(words[i], w, len) == 0)
            return 1;
    return 0;
}

int ekm_tool_keys_is_engine(const char *word)
{
    return word_in(ENGINES, 2, word, strlen(word));
}

int ekm_tool_keys_is_size(const char *word)
{
    return word_in(SIZES, 2, word, strlen(word));
}

size_t ekm_tool_keys_count(void)
{
    return N_TOOL_KEYS;
}

const ekm_tool_key *ekm_tool_keys_at(size_t i)
{
    return i < N_TOOL_KEYS ? &TOOL_KEYS[i] : NULL;
}

int ekm_tool_keys_split(const char *written, const char **base)
{
    const char *d1 = strchr(written, '.');
    if (!d1) {
        *base = written;
        return 1;
    }
    const size_t n1 = (size_t)(d1 - written);
    const char *d2 = strchr(d1 + 1, '.');
    if (!d2) {
        *base = d1 + 1;
        return word_in(ENGINES, 2, written, n1) || word_in(SIZES, 2, written, n1);
    }
    *base = d2 + 1;
    return word_in(ENGINES, 2, written, n1) && word_in(SIZES, 2, d1 + 1, (size_t)(d2 - d1 - 1)) &&
           !strchr(d2 + 1, '.');
}

const ekm_tool_key *ekm_tool_keys_find(const char *section, const char *base)
{
    for (size_t i = 0; i < N_TOOL_KEYS; i++)
        if (strcmp(TOOL_KEYS[i].section, section) == 0 && strcmp(TOOL_KEYS[i].key, base) == 0)
            return &TOOL_KEYS[i];
    return NULL;
}

static int is_number_list(const char *v)
{
    size_t n;
    return ekm_number_parse_list(v, NULL, 0, &n);
}

static int is_field_list(const char *v)
{
    const char *p = v;
    for (;;) {
        const size_t len = strcspn(p, ",");
        if (len == 0 || !((p[0] >= 'A' && p[0] <= 'Z') || (p[0] >= 'a' && p[0] <= 'z')))
            return 0;
        for (size_t i = 1; i < len; i++)
            if (!((p[i] >= 'A' && p[i] <= 'Z') || (p[i] >= 'a' && p[i] <= 'z') ||
                  (p[i] >= '0' && p[i] <= '9') || p[i] == '_'))
                return 0;
        if (p[len] == '\0')
            return 1;
        p += len + 1;
    }
}

/* Whether every name of a valid field list is a field of common/schema.h;
 * otherwise 0 and what was expected, naming the first unknown one. */
static int fields_in_schema(const char *v, char *expected, size_t size)
{
    for (const char *p = v; *p;) {
        const size_t len = strcspn(p, ",");
        char name[64];
        snprintf(name, sizeof name, "%.*s", (int)len, p);
        if (!ekm_field_lookup(name)) {
            snprintf(expected, size, "field names of the schema (common/schema.c), not '%s'", name);
            return 0;
        }
        p += len + (p[len] == ',');
    }
    return 1;
}

static int is_choice(const char *choices, const char *v)
{
    const size_t n = strlen(v);
    for (const char *p = choices; *p; p += strspn(p, " ")) {
        const size_t len = strcspn(p, " ");
        if (len == n && n > 0 && strncmp(p, v, n) == 0)
            return 1;
        p += len;
    }
    return 0;
}

/* The range of a [dem] key whose value has its type, or NULL when the
 * value is in range (or the key has no range): docs/scenario-format.md. */
static const char *dem_range(const char *base, const char *value)
{
    const double x = strtod(value, NULL);
    static const struct {
        const char *key, *expected;
        double lo, hi;
        int lo_open, hi_open; /* 1: the bound itself is outside; hi = HUGE_VAL: none */
    } R[] = {
        {"diameter", "a diameter > 0 [m]", 0, HUGE_VAL, 1, 1},
        {"dt", "a time step > 0 [s]", 0, HUGE_VAL, 1, 1},
        {"youngs", "a modulus > 0 [Pa]", 0, HUGE_VAL, 1, 1},
        {"friction", "a friction coefficient >= 0", 0, HUGE_VAL, 0, 1},
        {"poisson", "a Poisson ratio in (-1, 0.5)", -1, 0.5, 1, 1},
        {"restitution", "a restitution in (0, 1]", 0, 1, 1, 0},
        {"restitution_input", "a restitution in (0, 1]", 0, 1, 1, 0},
        {"timeout", "a timeout >= 1 [s]", 1, HUGE_VAL, 0, 1},
        {"dump_every", "an interval >= 1 [steps]", 1, HUGE_VAL, 0, 1},
        {"thermo_every", "an interval >= 1 [steps]", 1, HUGE_VAL, 0, 1},
        {"steady_tol", "a tolerance > 0", 0, HUGE_VAL, 1, 1},
        {"spread", "a size spread in [0, 1)", 0, 1, 0, 1},
        {"lx", "a length > 0 [d]", 0, HUGE_VAL, 1, 1},
        {"ly", "a length > 0 [d]", 0, HUGE_VAL, 1, 1},
        {"t_end", "a time > 0 [s]", 0, HUGE_VAL, 1, 1},
        {"settle_max", "a time > 0 [s]", 0, HUGE_VAL, 1, 1},
        {"t_settle", "a time >= 0 [s]", 0, HUGE_VAL, 0, 1},
        {"t_flow", "a time > 0 [s]", 0, HUGE_VAL, 1, 1},
        {"t_run", "a time > 0 [s]", 0, HUGE_VAL, 1, 1},
        {"t_compress", "a time >= 0 [s]", 0, HUGE_VAL, 0, 1},
        {"rest_ke", "a kinetic energy per mass > 0 [J/kg]", 0, HUGE_VAL, 1, 1},
        {"pressure", "a normal stress > 0 [Pa]", 0, HUGE_VAL, 1, 1},
        {"wall_damping", "a damping rate >= 0 [1/s]", 0, HUGE_VAL, 0, 1},
        {"strain", "a strain > 0", 0, HUGE_VAL, 1, 1},
        {"p_gain", "a gain > 0", 0, HUGE_VAL, 1, 1},
        {"pile_mass", "a mass > 0 [kg]", 0, HUGE_VAL, 1, 1},
        {"pour_rate", "a mass rate > 0 [kg/s]", 0, HUGE_VAL, 1, 1},
        {"pour_speed", "a speed > 0 [m/s]", 0, HUGE_VAL, 1, 1},
        {"pour_height", "a height > 0 [d]", 0, HUGE_VAL, 1, 1},
        {"plate_width", "a width > 0 [d]", 0, HUGE_VAL, 1, 1},
        {"hopper_gap", "a gap >= 0 [d]", 0, HUGE_VAL, 0, 1},
        {"hopper_stages", "a number of stages >= 1", 1, HUGE_VAL, 0, 1},
        {"rolling_friction", "a rolling friction coefficient >= 0", 0, HUGE_VAL, 0, 1},
        {"seeds", "an ensemble size >= 1", 1, HUGE_VAL, 0, 1},
    };
    for (size_t i = 0; i < sizeof R / sizeof R[0]; i++)
        if (strcmp(R[i].key, base) == 0) {
            const int low_ok = R[i].lo_open ? x > R[i].lo : x >= R[i].lo;
            const int high_ok = R[i].hi_open ? x < R[i].hi : x <= R[i].hi;
            return low_ok && high_ok ? NULL : R[i].expected;
        }
    return NULL;
}

int ekm_tool_keys_check(const char *section, const char *key, const char *value, char *why, size_t size)
{
    const char *base;
    if (!ekm_tool_keys_split(key, &base)) {
        snprintf(why, size,
                 "[%s] %s: unknown prefix (expected k, <engine>.k, <size>.k or <engine>.<size>.k; "
                 "engine liggghts or lammps, size smoke or ref)",
                 section, key);
        return 0;
    }
    const ekm_tool_key *tk = ekm_tool_keys_find(section, base);
    if (!tk) {
        snprintf(why, size, "[%s] %s: unknown key", section, key);
        return 0;
    }
    if (strlen(value) >= EKM_VALUE_MAX) {
        snprintf(why, size, "[%s] %s: value longer than allowed: '%s'", section, key, value);
        return 0;
    }
    const char *expected = NULL;
    char choices[128];
    switch (tk->type) {
    case EKM_TOOL_NUMBER:
        if (!ekm_number_parse(value, NULL))
            expected = "a number";
        break;
    case EKM_TOOL_INTEGER:
        if (!ekm_number_parse_integer(value, NULL))
            expected = "an integer";
        break;
    case EKM_TOOL_FLAG:
        if (strcmp(value, "0") != 0 && strcmp(value, "1") != 0)
            expected = "0 or 1";
        break;
    case EKM_TOOL_NUMBERS:
        if (!is_number_list(value))
            expected = "numbers separated by blanks";
        break;
    case EKM_TOOL_STRING: break;
    case EKM_TOOL_WORD:
        if (!((value[0] >= 'A' && value[0] <= 'Z') || (value[0] >= 'a' && value[0] <= 'z')) ||
            strspn(value, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_") != strlen(value))
            expected = "a name (a letter, then letters, digits or '_')";
        else if (strcmp(section, "campaign") == 0 && strcmp(base, "train") == 0 &&
                 strcmp(value, "thesis") == 0)
            expected = "a training-set name other than 'thesis' (the scenarios' own [material])";
        break;
    case EKM_TOOL_FIELDS:
        if (!is_field_list(value))
            expected = "field names separated by commas (e.g. phi,vx,T)";
        else if (strcmp(section, "compare") == 0 && strcmp(base, "fields") == 0 &&
                 !fields_in_schema(value, choices, sizeof choices))
            expected = choices; /* [compare] scalars names scalars and sets, not fields */
        break;
    case EKM_TOOL_CG: {
        char cg_why[600];
        if (!ekm_cg_keys_check_line(value, cg_why, sizeof cg_why)) {
            snprintf(why, size, "[%s] %s: %s", section, key, cg_why);
            return 0;
        }
        break;
    }
    case EKM_TOOL_ENUM:
        if (!is_choice(tk->choices, value)) {
            snprintf(choices, sizeof choices, "one of %s", tk->choices);
            expected = choices;
        }
        break;
    }
    if (!expected && strcmp(section, "dem") == 0)
        expected = dem_range(base, value);
    if (expected) {
        snprintf(why, size, "[%s] %s: expected %s, got '%s'", section, key, expected, value);
        return 0;
    }
    return 1;
}
