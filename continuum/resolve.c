/* resolve.c: the keys of the other tools' sections, their lookup rule and
 * defaults, and the sweep points (resolve.h, docs/resolved-scenario.md). */
#include "resolve.h"
#include "schema.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum {
    TYPE_NUMBER,  /* a decimal floating-point literal */
    TYPE_INTEGER, /* a decimal integer */
    TYPE_FLAG,    /* 0 or 1 */
    TYPE_NUMBERS, /* numbers separated by blanks (a sweep list) */
    TYPE_STRING,  /* free text */
    TYPE_WORD,    /* a name: a letter, then letters, digits, '_' */
    TYPE_FIELDS,  /* field names separated by commas */
    TYPE_ENUM     /* one of the words of `choices` */
} tool_type;

/* The sweep a [dem] key belongs to: its keys make the scenario one.
 * SWEEP_SHEAR: a key of both simple-shear sweeps (phis x rates, or
 * pressures x rates); without phis or pressures it is the phi sweep. */
typedef enum {
    SWEEP_NONE = 0,
    SWEEP_THETA,
    SWEEP_SHEAR,
    SWEEP_PHI_RATE,
    SWEEP_P_RATE,
    SWEEP_SOURCE
} sweep_kind;

typedef struct {
    const char *section;
    const char *key;
    tool_type type;
    const char *choices; /* TYPE_ENUM: the allowed words, blank-separated */
    const char *dflt;    /* default as written, or NULL (none, or derived below) */
    sweep_kind sweep;    /* the sweep this key belongs to, or SWEEP_NONE */
} tool_key;

/* Registry of the other tools' keys (docs/scenario-format.md). */
static const tool_key TOOL_KEYS[] = {
    {"dem", "diameter", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "spread", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "youngs", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "poisson", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "restitution", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "restitution_input", TYPE_NUMBER, NULL, NULL, SWEEP_NONE}, /* default: restitution */
    {"dem", "friction", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "dt", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "seed", TYPE_INTEGER, NULL, "15485863", SWEEP_NONE},
    {"dem", "thermo_every", TYPE_INTEGER, NULL, "1000", SWEEP_NONE},
    {"dem", "dump_every", TYPE_INTEGER, NULL, "5000", SWEEP_NONE},
    {"dem", "lx", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "ly", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "t_end", TYPE_NUMBER, NULL, NULL, SWEEP_NONE}, /* default: [run] t_end */
    {"dem", "rest_ke", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "t_settle", TYPE_NUMBER, NULL, NULL, SWEEP_THETA},
    {"dem", "t_flow", TYPE_NUMBER, NULL, NULL, SWEEP_THETA},
    {"dem", "angles", TYPE_NUMBERS, NULL, NULL, SWEEP_THETA}, /* default: [gravity] angle */
    {"dem", "pressure", TYPE_NUMBER, NULL, NULL, SWEEP_NONE}, /* default: [top] pressure */
    {"dem", "wall_damping", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "t_compress", TYPE_NUMBER, NULL, "0", SWEEP_NONE},
    {"dem", "t_run", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "strain", TYPE_NUMBER, NULL, NULL, SWEEP_SHEAR},
    {"dem", "phis", TYPE_NUMBERS, NULL, NULL, SWEEP_PHI_RATE},    /* default: [initial] phi */
    {"dem", "pressures", TYPE_NUMBERS, NULL, NULL, SWEEP_P_RATE}, /* no default */
    {"dem", "rates", TYPE_NUMBERS, NULL, NULL, SWEEP_SHEAR},      /* default: the walls' rate */
    {"dem", "p_gain", TYPE_NUMBER, NULL, NULL, SWEEP_NONE},
    {"dem", "dump_strain", TYPE_NUMBER, NULL, NULL, SWEEP_NONE}, /* per point dump_every of a shear sweep */
    /* the sand pile: poured from a source of each width over the floor */
    {"dem", "pile_mass", TYPE_NUMBER, NULL, NULL, SWEEP_SOURCE},
    {"dem", "pour_rate", TYPE_NUMBER, NULL, NULL, SWEEP_SOURCE},
    {"dem", "pour_speed", TYPE_NUMBER, NULL, NULL, SWEEP_SOURCE},
    {"dem", "pour_height", TYPE_NUMBER, NULL, NULL, SWEEP_SOURCE},
    {"dem", "source_widths", TYPE_NUMBERS, NULL, NULL, SWEEP_SOURCE},
    {"dem", "plate_width", TYPE_NUMBER, NULL, NULL, SWEEP_SOURCE},    /* the floor's extent [d] */
    {"dem", "hopper_gap", TYPE_NUMBER, NULL, NULL, SWEEP_SOURCE},     /* hopper above the apex [d] */
    {"dem", "hopper_stages", TYPE_INTEGER, NULL, NULL, SWEEP_SOURCE}, /* times the hopper is raised */
    {"dem", "rolling_friction", TYPE_NUMBER, NULL, "0", SWEEP_NONE},  /* mu_r: torque limit mu_r R* F_n */
    {"dem", "seeds", TYPE_INTEGER, NULL, NULL, SWEEP_NONE}, /* ensemble size (scripts/dem/ensemble.sh) */
    {"dem", "timeout", TYPE_INTEGER, NULL, "900", SWEEP_NONE},
    {"dem", "require_steady", TYPE_FLAG, NULL, "0", SWEEP_NONE},
    {"dem", "steady_tol", TYPE_NUMBER, NULL, "0.05", SWEEP_NONE},
    {"compare", "cg_options", TYPE_STRING, NULL, NULL, SWEEP_NONE},
    {"compare", "fields", TYPE_FIELDS, NULL, NULL, SWEEP_NONE},
    {"compare", "ekm_time", TYPE_ENUM, "last interp", "interp", SWEEP_NONE},
    {"compare", "shift", TYPE_NUMBER, NULL, "0", SWEEP_NONE},
    {"compare", "support", TYPE_NUMBER, NULL, "0.1", SWEEP_NONE},
    {"compare", "scalars", TYPE_FIELDS, NULL, NULL, SWEEP_NONE},
    /* the calibration (docs/campaign.md "Calibration"): the training set
     * the scenario's points belong to, and how that set is fitted */
    {"campaign", "train", TYPE_WORD, NULL, "none", SWEEP_NONE},
    {"campaign", "fit", TYPE_ENUM, "rheology scenario", NULL, SWEEP_NONE},
    {"campaign", "fit_params", TYPE_FIELDS, NULL, NULL, SWEEP_NONE},
    {"campaign", "fit_fields", TYPE_FIELDS, NULL, NULL, SWEEP_NONE},
    {"campaign", "fit_engine", TYPE_ENUM, "lammps liggghts", "lammps", SWEEP_NONE},
    {"campaign", "fit_starts", TYPE_INTEGER, NULL, NULL, SWEEP_NONE},
};
#define N_TOOL_KEYS (sizeof TOOL_KEYS / sizeof TOOL_KEYS[0])

/* The sections of the other tools; [figures] has no keys yet. */
static const char *const TOOL_SECTIONS[] = {"dem", "compare", "campaign", "figures"};
static const char *const ENGINES[] = {"liggghts", "lammps"};
static const char *const SIZES[] = {"smoke", "ref"};

#define VALUE_SIZE sizeof(((ekm_entry *)0)->value)

int ekm_resolve_is_tool_section(const char *section)
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

/* Split a key as written into its prefix (engine., size. or engine.size.)
 * and its base name. Returns 0 for any other prefix. */
static int split_key(const char *written, const char **base)
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

static const tool_key *find_key(const char *section, const char *base)
{
    for (size_t i = 0; i < N_TOOL_KEYS; i++)
        if (strcmp(TOOL_KEYS[i].section, section) == 0 && strcmp(TOOL_KEYS[i].key, base) == 0)
            return &TOOL_KEYS[i];
    return NULL;
}

/* A decimal floating-point literal: [-+]? (digits [. digits*] | . digits)
 * ([eE] [-+]? digits)?, representable (no overflow or underflow). */
static int is_number(const char *v, size_t len, double *out)
{
    size_t i = 0, digits = 0;
    if (i < len && (v[i] == '-' || v[i] == '+'))
        i++;
    while (i < len && v[i] >= '0' && v[i] <= '9')
        i++, digits++;
    if (i < len && v[i] == '.') {
        i++;
        while (i < len && v[i] >= '0' && v[i] <= '9')
            i++, digits++;
    }
    if (digits == 0)
        return 0;
    if (i < len && (v[i] == 'e' || v[i] == 'E')) {
        i++;
        if (i < len && (v[i] == '-' || v[i] == '+'))
            i++;
        size_t exp_digits = 0;
        while (i < len && v[i] >= '0' && v[i] <= '9')
            i++, exp_digits++;
        if (exp_digits == 0)
            return 0;
    }
    if (i != len)
        return 0;
    char buf[VALUE_SIZE];
    if (len >= sizeof buf)
        return 0;
    memcpy(buf, v, len);
    buf[len] = '\0';
    char *end;
    errno = 0;
    const double x = strtod(buf, &end);
    if (*end != '\0' || errno == ERANGE || !isfinite(x))
        return 0;
    if (out)
        *out = x;
    return 1;
}

/* A decimal integer: [-+]? digits, within long long. */
static int is_integer(const char *v, long long *out)
{
    const char *p = v + (*v == '-' || *v == '+');
    if (!*p || strspn(p, "0123456789") != strlen(p))
        return 0;
    char *end;
    errno = 0;
    const long long x = strtoll(v, &end, 10);
    if (errno == ERANGE)
        return 0;
    if (out)
        *out = x;
    return 1;
}

int ekm_resolve_parse_number(const char *value, double *out)
{
    return is_number(value, strlen(value), out);
}

int ekm_resolve_parse_integer(const char *value, long long *out)
{
    return is_integer(value, out);
}

#define BLANKS " \t"

int ekm_resolve_parse_numbers(const char *value, double *out, size_t max, size_t *n)
{
    *n = 0;
    for (const char *p = value + strspn(value, BLANKS); *p; p += strspn(p, BLANKS)) {
        const size_t len = strcspn(p, BLANKS);
        double x;
        if (!is_number(p, len, &x))
            return 0;
        if (out && *n < max)
            out[*n] = x;
        p += len;
        (*n)++;
    }
    return *n > 0;
}

static int is_number_list(const char *v)
{
    size_t n;
    return ekm_resolve_parse_numbers(v, NULL, 0, &n);
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

int ekm_resolve_check_key(const char *section, const char *key, const char *value, char *why, size_t size)
{
    const char *base;
    if (!split_key(key, &base)) {
        snprintf(why, size,
                 "[%s] %s: unknown prefix (expected k, <engine>.k, <size>.k or <engine>.<size>.k; "
                 "engine liggghts or lammps, size smoke or ref)",
                 section, key);
        return 0;
    }
    const tool_key *tk = find_key(section, base);
    if (!tk) {
        snprintf(why, size, "[%s] %s: unknown key", section, key);
        return 0;
    }
    if (strlen(value) >= VALUE_SIZE) {
        snprintf(why, size, "[%s] %s: value longer than allowed: '%s'", section, key, value);
        return 0;
    }
    const char *expected = NULL;
    char choices[128];
    switch (tk->type) {
    case TYPE_NUMBER:
        if (!is_number(value, strlen(value), NULL))
            expected = "a number";
        break;
    case TYPE_INTEGER:
        if (!is_integer(value, NULL))
            expected = "an integer";
        break;
    case TYPE_FLAG:
        if (strcmp(value, "0") != 0 && strcmp(value, "1") != 0)
            expected = "0 or 1";
        break;
    case TYPE_NUMBERS:
        if (!is_number_list(value))
            expected = "numbers separated by blanks";
        break;
    case TYPE_STRING: break;
    case TYPE_WORD:
        if (!((value[0] >= 'A' && value[0] <= 'Z') || (value[0] >= 'a' && value[0] <= 'z')) ||
            strspn(value, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_") != strlen(value))
            expected = "a name (a letter, then letters, digits or '_')";
        else if (strcmp(section, "campaign") == 0 && strcmp(base, "train") == 0 &&
                 strcmp(value, "thesis") == 0)
            expected = "a training-set name other than 'thesis' (the scenarios' own [material])";
        break;
    case TYPE_FIELDS:
        if (!is_field_list(value))
            expected = "field names separated by commas (e.g. phi,vx,T)";
        else if (strcmp(section, "compare") == 0 && strcmp(base, "fields") == 0 &&
                 !fields_in_schema(value, choices, sizeof choices))
            expected = choices; /* [compare] scalars names scalars and sets, not fields */
        break;
    case TYPE_ENUM:
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

/* --- resolving --------------------------------------------------------------------- */

static ekm_status add_key(ekm_resolved *r, const char *name, const char *value, const char *from,
                          const char *as, ekm_error *err)
{
    ekm_resolve_key *k = realloc(r->keys, (r->n_keys + 1) * sizeof *k);
    if (!k)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory resolving the scenario");
    r->keys = k;
    k += r->n_keys++;
    snprintf(k->name, sizeof k->name, "%s", name);
    snprintf(k->value, sizeof k->value, "%s", value);
    snprintf(k->from, sizeof k->from, "%s", from);
    snprintf(k->as, sizeof k->as, "%s", as ? as : "");
    return EKM_OK;
}

static void entry_from(const ekm_scenario *s, const ekm_entry *e, char *buf, size_t size)
{
    if (e->origin == EKM_FROM_SET)
        snprintf(buf, size, "--set");
    else
        snprintf(buf, size, "%s:%d", e->origin == EKM_FROM_MATERIAL ? s->material_source : s->source,
                 e->line);
}

/* The entry of tool key section.base by the lookup rule: a --set of the
 * plain key, then <engine>.<size>.k, <size>.k, <engine>.k, k (a variant
 * only when its engine and size were given). */
static const ekm_entry *pick(const ekm_scenario *s, const char *section, const char *base, const char *engine,
                             const char *size)
{
    char name[4][64];
    snprintf(name[0], sizeof name[0], "%s.%s.%s.%s", section, engine, size, base);
    snprintf(name[1], sizeof name[1], "%s.%s.%s", section, size, base);
    snprintf(name[2], sizeof name[2], "%s.%s.%s", section, engine, base);
    snprintf(name[3], sizeof name[3], "%s.%s", section, base);
    const ekm_entry *plain = ekm_scenario_entry_find(s->tool_entries, s->n_tool_entries, name[3]);
    if (plain && plain->origin == EKM_FROM_SET)
        return plain;
    const int allowed[4] = {*engine && *size, *size != '\0', *engine != '\0', 1};
    for (int i = 0; i < 4; i++) {
        const ekm_entry *e =
            allowed[i] ? ekm_scenario_entry_find(s->tool_entries, s->n_tool_entries, name[i]) : NULL;
        if (e)
            return e;
    }
    return NULL;
}

static int section_given(const ekm_scenario *s, const char *section)
{
    const size_t n = strlen(section);
    for (size_t i = 0; i < s->n_tool_entries; i++)
        if (strncmp(s->tool_entries[i].name, section, n) == 0 && s->tool_entries[i].name[n] == '.')
            return 1;
    return 0;
}

/* The family of a sweep, for the one-sweep-only rule, and its name. */
static int sweep_family(sweep_kind k)
{
    return k == SWEEP_THETA ? 1 : k == SWEEP_SOURCE ? 3 : k == SWEEP_NONE ? 0 : 2;
}

static const char *sweep_family_name(sweep_kind k)
{
    return k == SWEEP_THETA ? "inclined-flow" : k == SWEEP_SOURCE ? "sand-pile" : "simple-shear";
}

/* Which sweep the scenario's [dem] keys (any variant) make it: an inclined
 * flow (t_settle t_flow angles: over the angles), a simple shear at fixed
 * volume (strain rates phis: over phis x rates), a simple shear at fixed
 * pressure (strain rates pressures: over pressures x rates), a sand pile
 * (pile_mass pour_rate pour_speed pour_height source_widths: over the
 * source widths), or none. */
static ekm_status sweep_of(const ekm_scenario *s, sweep_kind *kind, ekm_error *err)
{
    *kind = SWEEP_NONE;
    const char *first = NULL, *list = NULL; /* the first sweep key; the phis or pressures key */
    for (size_t i = 0; i < s->n_tool_entries; i++) {
        const ekm_entry *e = &s->tool_entries[i];
        const char *base;
        if (strncmp(e->name, "dem.", 4) != 0 || !split_key(e->name + 4, &base))
            continue;
        const tool_key *tk = find_key("dem", base);
        if (!tk || tk->sweep == SWEEP_NONE)
            continue;
        char from[600];
        entry_from(s, e, from, sizeof from);
        if (*kind != SWEEP_NONE && sweep_family(tk->sweep) != sweep_family(*kind)) {
            const int pile = tk->sweep == SWEEP_SOURCE || *kind == SWEEP_SOURCE;
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [dem] %s: a key of the %s sweep, but [dem] %s is one of the %s sweep: "
                            "expected the keys of one sweep only (inclined flow: t_settle t_flow angles; "
                            "simple shear: strain rates, and phis or pressures%s)",
                            from, e->name + 4, sweep_family_name(tk->sweep), first, sweep_family_name(*kind),
                            pile ? "; sand pile: pile_mass pour_rate pour_speed pour_height source_widths"
                                 : "");
        }
        if ((tk->sweep == SWEEP_PHI_RATE && *kind == SWEEP_P_RATE) ||
            (tk->sweep == SWEEP_P_RATE && *kind == SWEEP_PHI_RATE))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [dem] %s: a list of the %s sweep, but [dem] %s is one of the %s sweep: "
                            "expected phis (shear at fixed volume) or pressures (shear at fixed pressure), "
                            "not both",
                            from, e->name + 4, tk->sweep == SWEEP_P_RATE ? "pressure x rate" : "phi x rate",
                            list, *kind == SWEEP_P_RATE ? "pressure x rate" : "phi x rate");
        if (!first)
            first = e->name + 4;
        if (tk->sweep == SWEEP_PHI_RATE || tk->sweep == SWEEP_P_RATE) {
            *kind = tk->sweep;
            list = e->name + 4;
        } else if (*kind == SWEEP_NONE) {
            *kind = tk->sweep;
        }
    }
    if (*kind == SWEEP_SHEAR)
        *kind = SWEEP_PHI_RATE;
    return EKM_OK;
}

static ekm_status resolve_tool_section(const ekm_scenario *s, ekm_resolved *r, const char *section,
                                       sweep_kind sweep, ekm_error *err)
{
    for (size_t i = 0; i < N_TOOL_KEYS; i++) {
        const tool_key *tk = &TOOL_KEYS[i];
        if (strcmp(tk->section, section) != 0)
            continue;
        char name[64], from[600], value[VALUE_SIZE];
        snprintf(name, sizeof name, "%s.%s", section, tk->key);
        const ekm_entry *e = pick(s, section, tk->key, r->engine, r->size);
        ekm_status st = EKM_OK;
        if (e) {
            entry_from(s, e, from, sizeof from);
            const char *written = e->name + strlen(section) + 1;
            st = add_key(r, name, e->value, from, strcmp(written, tk->key) != 0 ? written : NULL, err);
        } else {
            /* defaults: documented, or derived from another key */
            const ekm_resolve_key *src = NULL;
            value[0] = '\0';
            if (tk->dflt)
                snprintf(value, sizeof value, "%s", tk->dflt);
            else if (strcmp(name, "dem.restitution_input") == 0)
                src = ekm_resolve_find(r, "dem.restitution");
            else if (strcmp(name, "dem.t_end") == 0)
                src = ekm_resolve_find(r, "run.t_end");
            else if (strcmp(name, "dem.pressure") == 0)
                src = ekm_resolve_find(r, "top.pressure");
            else if (strcmp(name, "dem.angles") == 0 && sweep == SWEEP_THETA)
                src = ekm_resolve_find(r, "gravity.angle");
            else if (strcmp(name, "dem.phis") == 0 && sweep == SWEEP_PHI_RATE)
                src = ekm_resolve_find(r, "initial.phi");
            else if (strcmp(name, "dem.rates") == 0 && (sweep == SWEEP_PHI_RATE || sweep == SWEEP_P_RATE))
                /* the imposed rate of a rate-held top wall, else the walls'
                 * (as scripts/dem/run.sh computed it: awk printf "%.10g") */
                snprintf(value, sizeof value, "%.10g",
                         !isnan(s->top.shear_rate) ? s->top.shear_rate
                                                   : (s->top.velocity - s->bottom.velocity) / s->length);
            if (src)
                snprintf(value, sizeof value, "%s", src->value);
            if (value[0])
                st = add_key(r, name, value, "default", NULL, err);
        }
        if (st != EKM_OK)
            return st;
    }
    return EKM_OK;
}

/* The blank-separated items of a list, each at most 63 characters. */
typedef struct {
    size_t n;
    char item[VALUE_SIZE / 2][64];
} item_list;

static ekm_status split_list(const ekm_resolve_key *k, item_list *out, ekm_error *err)
{
    out->n = 0;
    for (const char *p = k->value + strspn(k->value, BLANKS); *p; p += strspn(p, BLANKS)) {
        const size_t len = strcspn(p, BLANKS);
        const char *key = k->as[0] ? k->as : k->name + 4;
        if (len >= sizeof out->item[0])
            return EKM_FAIL(err, EKM_EINPUT, "%s: [dem] %s: list item longer than %zu characters", k->from,
                            key, sizeof out->item[0] - 1);
        for (size_t j = 0; j < out->n; j++)
            if (strlen(out->item[j]) == len && strncmp(out->item[j], p, len) == 0)
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: [dem] %s: value '%s' given twice (each point needs its own tag)",
                                k->from, key, out->item[j]);
        snprintf(out->item[out->n++], sizeof out->item[0], "%.*s", (int)len, p);
        p += len;
    }
    return EKM_OK;
}

/* Where the value of a sweep list came from, for a message blaming it: its
 * FILE:LINE or --set; a derived default (dem.phis: [initial] phi, dem.rates:
 * the walls' rate) names the key it was derived from, and says so in why. */
static void blame_of(const ekm_scenario *s, const ekm_resolved *r, const ekm_resolve_key *k, char *from,
                     size_t from_size, char *why, size_t why_size)
{
    snprintf(from, from_size, "%s", k->from);
    why[0] = '\0';
    if (strcmp(k->from, "default") != 0)
        return;
    const char *source = NULL;
    if (strcmp(k->name, "dem.phis") == 0) {
        source = "initial.phi";
        snprintf(why, why_size, " (the default: [initial] phi)");
    } else if (strcmp(k->name, "dem.rates") == 0) {
        source = !isnan(s->top.shear_rate) ? "top.shear_rate" : "top.velocity";
        snprintf(why, why_size, "%s",
                 !isnan(s->top.shear_rate)
                     ? " (the default: [top] shear_rate)"
                     : " (the default: ([top] velocity - [bottom] velocity) / [domain] length)");
        if (isnan(s->top.shear_rate) && !ekm_scenario_entry_find(s->entries, s->n_entries, "top.velocity"))
            source = "bottom.velocity";
    }
    const ekm_resolve_key *src = source ? ekm_resolve_find(r, source) : NULL;
    if (src && strcmp(src->from, "--set") == 0)
        snprintf(from, from_size, "--set %s", source);
    else
        snprintf(from, from_size, "%s", src && strcmp(src->from, "default") != 0 ? src->from : s->source);
}

/* Every item of a [dem] sweep list in (lo, hi) (hi <= 0: no upper bound). */
static ekm_status check_sweep_items(const ekm_scenario *s, const ekm_resolved *r, const ekm_resolve_key *k,
                                    const item_list *l, double lo, double hi, const char *expected,
                                    ekm_error *err)
{
    const char *key = k->as[0] ? k->as : k->name + 4;
    for (size_t i = 0; i < l->n; i++) {
        const double x = strtod(l->item[i], NULL);
        if (!(x > lo) || (hi > 0 && !(x < hi))) {
            char from[600], why[96];
            blame_of(s, r, k, from, sizeof from, why, sizeof why);
            return EKM_FAIL(err, EKM_EINPUT, "%s: [dem] %s: expected %s, got '%s'%s", from, key, expected,
                            l->item[i], why);
        }
    }
    return EKM_OK;
}

static ekm_resolve_point *add_point(ekm_resolved *r, ekm_error *err)
{
    ekm_resolve_point *p = realloc(r->points, (r->n_points + 1) * sizeof *p);
    if (!p) {
        EKM_FAIL(err, EKM_ENOMEM, "out of memory resolving the scenario");
        return NULL;
    }
    r->points = p;
    p += r->n_points++;
    memset(p, 0, sizeof *p);
    return p;
}

/* One point per item of a one-variable sweep: tag PREFIX<item> (none for a
 * single item), the variable VAR = item and, with KEY, the EKM set
 * KEY=item. */
static ekm_status add_list_points(ekm_resolved *r, const item_list *items, const char *prefix,
                                  const char *var, const char *key, ekm_error *err)
{
    for (size_t i = 0; i < items->n; i++) {
        ekm_resolve_point *p = add_point(r, err);
        if (!p)
            return EKM_ENOMEM;
        if (items->n > 1)
            snprintf(p->tag, sizeof p->tag, "%s%s", prefix, items->item[i]);
        p->n_vars = 1;
        snprintf(p->var_name[0], sizeof p->var_name[0], "%s", var);
        snprintf(p->var_value[0], sizeof p->var_value[0], "%s", items->item[i]);
        if (key) {
            p->n_sets = 1;
            snprintf(p->set[0], sizeof p->set[0], "%s=%s", key, items->item[i]);
        }
    }
    return EKM_OK;
}

/* The dump_every of a shear point with [dem] dump_strain: one frame every
 * dump_strain of shear, int(dump_strain / (rate dt) + 0.5) steps, at least
 * 1 (the arithmetic of the awk line run.sh had). */
static ekm_status dump_every_of(const ekm_resolve_key *dump_strain, const ekm_resolve_key *dt,
                                const ekm_resolve_key *rates, const char *rate, char *out, size_t size,
                                ekm_error *err)
{
    const char *key = dump_strain->as[0] ? dump_strain->as : "dump_strain";
    if (!dt)
        return EKM_FAIL(err, EKM_EINPUT, "%s: [dem] %s: needs [dem] dt (dump_every = %s / (rate dt))",
                        dump_strain->from, key, key);
    const double strain = strtod(dump_strain->value, NULL), r = strtod(rate, NULL),
                 step = strtod(dt->value, NULL);
    if (!(strain > 0) || !(r > 0) || !(step > 0))
        return EKM_FAIL(
            err, EKM_EINPUT,
            "%s: [dem] %s: expected dump_strain, dt and every rate > 0 (got dump_strain %s, dt %s, "
            "rate %s of [dem] %s)",
            dump_strain->from, key, dump_strain->value, dt->value, rate, rates->as[0] ? rates->as : "rates");
    const double n = strain / (r * step) + 0.5;
    if (!(n < 2147483647.0))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [dem] %s: dump_every %s / (%s %s) exceeds the largest step count",
                        dump_strain->from, key, dump_strain->value, rate, dt->value);
    const long every = (long)n;
    snprintf(out, size, "%ld", every < 1 ? 1L : every);
    return EKM_OK;
}

static ekm_status build_points(const ekm_scenario *s, ekm_resolved *r, sweep_kind sweep, ekm_error *err)
{
    const ekm_resolve_key *angles = ekm_resolve_find(r, "dem.angles");
    const ekm_resolve_key *phis = ekm_resolve_find(r, "dem.phis"), *rates = ekm_resolve_find(r, "dem.rates");
    const ekm_resolve_key *pressures = ekm_resolve_find(r, "dem.pressures");
    const ekm_resolve_key *dump_strain = ekm_resolve_find(r, "dem.dump_strain"),
                          *dt = ekm_resolve_find(r, "dem.dt");
    item_list *a = calloc(2, sizeof *a);
    if (!a)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory resolving the scenario");
    ekm_status st = EKM_OK;
    if (sweep == SWEEP_THETA && angles) {
        st = split_list(angles, &a[0], err);
        if (st == EKM_OK)
            st = add_list_points(r, &a[0], "theta", "theta", "gravity.angle", err);
    } else if ((sweep == SWEEP_PHI_RATE && phis && rates) || (sweep == SWEEP_P_RATE && pressures && rates)) {
        const int by_p = sweep == SWEEP_P_RATE;
        st = split_list(by_p ? pressures : phis, &a[0], err);
        char phi_range[64];
        snprintf(phi_range, sizeof phi_range, "volume fractions in (0, phi_cp = %g)", s->material.phi_cp);
        if (st == EKM_OK)
            st = by_p ? check_sweep_items(s, r, pressures, &a[0], 0.0, 0.0, "normal stresses > 0 [Pa]", err)
                      : check_sweep_items(s, r, phis, &a[0], 0.0, s->material.phi_cp, phi_range, err);
        if (st == EKM_OK)
            st = split_list(rates, &a[1], err);
        if (st == EKM_OK)
            st = check_sweep_items(s, r, rates, &a[1], 0.0, 0.0, "shear rates > 0 [1/s]", err);
        const size_t n = a[0].n * a[1].n;
        for (size_t i = 0; i < a[0].n && st == EKM_OK; i++)
            for (size_t j = 0; j < a[1].n && st == EKM_OK; j++) {
                ekm_resolve_point *p = add_point(r, err);
                if (!p) {
                    st = EKM_ENOMEM;
                    break;
                }
                if (n > 1)
                    snprintf(p->tag, sizeof p->tag, "%s%s-rate%s", by_p ? "p" : "phi", a[0].item[i],
                             a[1].item[j]);
                p->n_vars = 2;
                snprintf(p->var_name[0], sizeof p->var_name[0], "%s", by_p ? "pressure" : "phi");
                snprintf(p->var_value[0], sizeof p->var_value[0], "%s", a[0].item[i]);
                snprintf(p->var_name[1], sizeof p->var_name[1], "rate");
                snprintf(p->var_value[1], sizeof p->var_value[1], "%s", a[1].item[j]);
                if (dump_strain) {
                    st = dump_every_of(dump_strain, dt, rates, a[1].item[j], p->var_value[2],
                                       sizeof p->var_value[2], err);
                    snprintf(p->var_name[2], sizeof p->var_name[2], "dump_every");
                    p->n_vars = 3;
                }
                /* the walls at -+ R L/2 (r * L / 2 printed "%.10g": the digits
                 * the DEM campaign has always used); a pressure point holds
                 * the top wall at P and its speed at [bottom] velocity + R gap
                 * (bc.h), the bottom at -R L/2 of the initial gap */
                const double v = strtod(a[1].item[j], NULL) * s->length / 2;
                p->n_sets = 0;
                if (by_p) {
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.pressure=%s", a[0].item[i]);
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.shear_rate=%s", a[1].item[j]);
                } else {
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "initial.phi=%s", a[0].item[i]);
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.velocity=%.10g", v);
                }
                snprintf(p->set[p->n_sets++], sizeof p->set[0], "bottom.velocity=%.10g", -v);
            }
    } else if (sweep == SWEEP_SOURCE) {
        const ekm_resolve_key *widths = ekm_resolve_find(r, "dem.source_widths");
        if (!widths)
            st = EKM_FAIL(err, EKM_EINPUT,
                          "%s: [dem] source_widths: missing for this engine and size (a sand pile needs "
                          "the widths of its sources [d])",
                          s->source);
        if (st == EKM_OK)
            st = split_list(widths, &a[0], err);
        if (st == EKM_OK)
            st = check_sweep_items(s, r, widths, &a[0], 0.0, 0.0, "source widths > 0 [d]", err);
        if (st == EKM_OK)
            st = add_list_points(r, &a[0], "source", "source_width", NULL, err);
    } else if (sweep == SWEEP_P_RATE) {
        st = EKM_FAIL(err, EKM_EINPUT,
                      "%s: [dem] pressures: missing for this engine and size (only other variants are given; "
                      "a pressure x rate sweep needs its list of normal stresses)",
                      s->source);
    } else if (!add_point(r, err)) {
        st = EKM_ENOMEM;
    }
    free(a);
    return st;
}

ekm_status ekm_resolve(const ekm_scenario *s, const char *engine, const char *size, ekm_resolved *r,
                       ekm_error *err)
{
    memset(r, 0, sizeof *r);
    if (engine && !word_in(ENGINES, 2, engine, strlen(engine)))
        return EKM_FAIL(err, EKM_EINPUT, "--engine %s: unknown engine (expected liggghts or lammps)", engine);
    if (size && !word_in(SIZES, 2, size, strlen(size)))
        return EKM_FAIL(err, EKM_EINPUT, "--size %s: unknown size (expected smoke or ref)", size);
    snprintf(r->engine, sizeof r->engine, "%s", engine ? engine : "");
    snprintf(r->size, sizeof r->size, "%s", size ? size : "");
    ekm_status st = EKM_OK;
    /* ekm's sections: the value given, else the default of the loaded scenario */
    for (size_t i = 0; i < ekm_scenario_key_count() && st == EKM_OK; i++) {
        const char *section, *key;
        ekm_scenario_key_name(i, &section, &key);
        char name[64], from[600], value[VALUE_SIZE];
        snprintf(name, sizeof name, "%s.%s", section, key);
        const ekm_entry *e = ekm_scenario_entry_find(s->entries, s->n_entries, name);
        if (e) {
            entry_from(s, e, from, sizeof from);
            st = add_key(r, name, e->value, from, NULL, err);
        } else if (ekm_scenario_key_default(s, i, value, sizeof value)) {
            st = add_key(r, name, value, "default", NULL, err);
        }
    }
    sweep_kind sweep = SWEEP_NONE;
    if (st == EKM_OK)
        st = sweep_of(s, &sweep, err);
    if (st == EKM_OK && section_given(s, "dem"))
        st = resolve_tool_section(s, r, "dem", sweep, err);
    if (st == EKM_OK && section_given(s, "compare"))
        st = resolve_tool_section(s, r, "compare", SWEEP_NONE, err);
    if (st == EKM_OK && section_given(s, "campaign"))
        st = resolve_tool_section(s, r, "campaign", SWEEP_NONE, err);
    if (st == EKM_OK)
        st = build_points(s, r, section_given(s, "dem") ? sweep : SWEEP_NONE, err);
    return st;
}

ekm_status ekm_resolve_keep_point(ekm_resolved *r, const char *tag, ekm_error *err)
{
    for (size_t i = 0; i < r->n_points; i++)
        if (strcmp(r->points[i].tag, tag) == 0) {
            r->points[0] = r->points[i];
            r->n_points = 1;
            return EKM_OK;
        }
    char tags[800] = "";
    size_t used = 0;
    for (size_t i = 0; i < r->n_points && used < sizeof tags; i++) {
        int n = snprintf(tags + used, sizeof tags - used, "%s%s", i ? " " : "",
                         r->points[i].tag[0] ? r->points[i].tag : "\"\"");
        if (n < 0)
            break;
        used += (size_t)n;
    }
    return EKM_FAIL(err, EKM_EINPUT, "--point %s: unknown point (the points are: %s)", tag, tags);
}

const ekm_resolve_key *ekm_resolve_find(const ekm_resolved *r, const char *name)
{
    for (size_t i = 0; i < r->n_keys; i++)
        if (strcmp(r->keys[i].name, name) == 0)
            return &r->keys[i];
    return NULL;
}

void ekm_resolve_free(ekm_resolved *r)
{
    if (!r)
        return;
    free(r->keys);
    free(r->points);
    r->keys = NULL;
    r->points = NULL;
    r->n_keys = r->n_points = 0;
}
