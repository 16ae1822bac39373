/* scenario.c: defaults, INI reading (inih) and validation of a scenario. */
#include "scenario.h"

#include "closure.h"
#include "number.h"
#include "tool_keys.h"
#include "utf8.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#define DEG (3.14159265358979323846 / 180.0)

/* KEY_DOUBLES: numbers separated by blanks into a double array of
 * EKM_INLETS_MAX (the only one: [bottom]/[top] inlet_x, its count in the
 * ekm_bc's n_inlets) */
typedef enum { KEY_DOUBLE, KEY_INT, KEY_STRING, KEY_DOUBLES } key_type;

/* Registry of ekm's keys: where each is stored and whether it is required. */
typedef struct {
    const char *section;
    const char *key;
    key_type type;
    size_t offset; /* into ekm_scenario */
    size_t size;   /* for strings: buffer size */
    int required;
    const char *only_for_bc; /* BC keys: the bc type they belong to, or NULL */
} key_spec;

/* The key registry reads as a table: */
/* clang-format off */
#define SC(field) offsetof(ekm_scenario, field)
#define MAT(k) {"material", #k, KEY_DOUBLE, SC(material.k), 0, 1, NULL}
#define BC(side, k, t, only) {#side, #k, t, SC(side.k), 0, 0, only}
#define BC_KEYS(side)                                  \
    {#side, "type", KEY_STRING, 0, 0, 1, NULL},        \
    BC(side, velocity, KEY_DOUBLE, "wall"),            \
    BC(side, slip_length, KEY_DOUBLE, "wall"),         \
    BC(side, phi, KEY_DOUBLE, "inflow"),               \
    BC(side, w, KEY_DOUBLE, "inflow piston"),          \
    BC(side, u, KEY_DOUBLE, "inflow"),                 \
    BC(side, T, KEY_DOUBLE, "inflow"),                 \
    BC(side, t_stop, KEY_DOUBLE, "inflow"),            \
    BC(side, t_start, KEY_DOUBLE, "inflow"),           \
    BC(side, inlet_x, KEY_DOUBLES, "inflow"),          \
    BC(side, inlet_width, KEY_DOUBLE, "inflow"),       \
    BC(side, plate_x, KEY_DOUBLE, "wall"),             \
    BC(side, plate_width, KEY_DOUBLE, "wall"),         \
    BC(side, period, KEY_DOUBLE, "piston"),            \
    BC(side, w_return, KEY_DOUBLE, "piston"),          \
    BC(side, pressure, KEY_DOUBLE, "wall"),            \
    BC(side, pressure_rate, KEY_DOUBLE, "wall"),       \
    BC(side, shear_rate, KEY_DOUBLE, "wall")
/* the side walls of a 2D box (periodic_x = 0) */
#define SIDE_KEYS(side)                                \
    {#side, "type", KEY_STRING, 0, 0, 0, NULL},        \
    BC(side, slip_length, KEY_DOUBLE, "wall")

static const key_spec KEYS[] = {
    {"scenario", "name", KEY_STRING, SC(name), sizeof(((ekm_scenario *)0)->name), 0, NULL},
    {"scenario", "description", KEY_STRING, SC(description), sizeof(((ekm_scenario *)0)->description), 0,
     NULL},
    MAT(rho_p),
    MAT(phi_co),
    MAT(phi_cp),
    MAT(T0),
    MAT(eta0),
    MAT(zeta0),
    MAT(lambda0),
    MAT(eps0),
    MAT(nu),
    MAT(A_h),
    MAT(B_h),
    MAT(alpha),
    {"model", "variant", KEY_STRING, 0, 0, 0, NULL},
    {"model", "closure", KEY_STRING, 0, 0, 0, NULL},
    {"domain", "length", KEY_DOUBLE, SC(length), 0, 1, NULL},
    {"domain", "cells", KEY_INT, SC(cells), 0, 1, NULL},
    {"domain", "width", KEY_DOUBLE, SC(width), 0, 0, NULL},
    {"domain", "cells_x", KEY_INT, SC(cells_x), 0, 0, NULL},
    {"domain", "periodic_x", KEY_INT, SC(periodic_x), 0, 0, NULL},
    {"gravity", "magnitude", KEY_DOUBLE, SC(gravity), 0, 0, NULL},
    {"gravity", "angle", KEY_DOUBLE, SC(angle_deg), 0, 0, NULL},
    {"gravity", "angle_rate", KEY_DOUBLE, SC(angle_rate), 0, 0, NULL},
    {"gravity", "angle_start", KEY_DOUBLE, SC(angle_start), 0, 0, NULL},
    {"initial", "phi", KEY_DOUBLE, SC(phi_init), 0, 1, NULL},
    {"initial", "T", KEY_DOUBLE, SC(T_init), 0, 0, NULL},
    {"initial", "u", KEY_DOUBLE, SC(u_init), 0, 0, NULL},
    {"initial", "shear_rate", KEY_DOUBLE, SC(shear_rate_init), 0, 0, NULL},
    {"initial", "layer_height", KEY_DOUBLE, SC(layer_height), 0, 0, NULL},
    {"initial", "solid", KEY_INT, SC(hypo.initial_solid), 0, 0, NULL},
    {"initial", "stress_ratio", KEY_DOUBLE, SC(hypo.initial_stress_ratio), 0, 0, NULL},
    {"initial", "settled", KEY_INT, SC(hypo.initial_settled), 0, 0, NULL},
    BC_KEYS(bottom),
    BC_KEYS(top),
    SIDE_KEYS(left),
    SIDE_KEYS(right),
    {"run", "t_end", KEY_DOUBLE, SC(t_end), 0, 1, NULL},
    {"run", "output_dt", KEY_DOUBLE, SC(output_dt), 0, 0, NULL},
    {"run", "stop", KEY_STRING, 0, 0, 0, NULL},
    {"run", "steady_tol", KEY_DOUBLE, SC(steady_tol), 0, 0, NULL},
    {"run", "steady_window", KEY_DOUBLE, SC(steady_window), 0, 0, NULL},
    {"numerics", "cfl", KEY_DOUBLE, SC(numerics.cfl), 0, 0, NULL},
    {"numerics", "convection", KEY_STRING, 0, 0, 0, NULL},
    {"numerics", "limiter", KEY_STRING, SC(numerics.limiter), sizeof(((ekm_numerics *)0)->limiter), 0, NULL},
    {"numerics", "dt_max", KEY_DOUBLE, SC(numerics.dt_max), 0, 0, NULL},
    {"numerics", "dt_min", KEY_DOUBLE, SC(numerics.dt_min), 0, 0, NULL},
    {"numerics", "phi_dry", KEY_DOUBLE, SC(numerics.phi_dry), 0, 0, NULL},
    {"numerics", "phi_vacuum", KEY_DOUBLE, SC(numerics.phi_vacuum), 0, 0, NULL},
    {"numerics", "T_floor", KEY_DOUBLE, SC(numerics.T_floor), 0, 0, NULL},
    {"numerics", "phi_step_max", KEY_DOUBLE, SC(numerics.phi_step_max), 0, 0, NULL},
    {"numerics", "solid_relax_step", KEY_DOUBLE, SC(numerics.solid_relax_step), 0, 0, NULL},
    {"numerics", "newton_tol", KEY_DOUBLE, SC(numerics.newton_tol), 0, 0, NULL},
    {"numerics", "newton_max", KEY_INT, SC(numerics.newton_max), 0, 0, NULL},
    {"numerics", "normal_coupling", KEY_STRING, 0, 0, 0, NULL},
    {"numerics", "thermal_relax_step", KEY_DOUBLE, SC(numerics.thermal_relax_step), 0, 0, NULL},
    {"numerics", "surface_fill", KEY_INT, SC(numerics.surface_fill), 0, 0, NULL},
    {"numerics", "solid_lag_tol", KEY_DOUBLE, SC(numerics.solid_lag_tol), 0, 0, NULL},
    {"numerics", "gdot_min", KEY_DOUBLE, SC(numerics.gdot_min), 0, 0, NULL},
    {"hypo", "enabled", KEY_INT, SC(hypo.enabled), 0, 0, NULL},
    {"hypo", "T_ratio", KEY_DOUBLE, SC(hypo.T_ratio), 0, 0, NULL},
    {"hypo", "phi_margin", KEY_DOUBLE, SC(hypo.phi_margin), 0, 0, NULL},
    {"hypo", "phi_loose", KEY_DOUBLE, SC(hypo.phi_loose), 0, 0, NULL},
    {"hypo", "rest_rate", KEY_DOUBLE, SC(hypo.rest_rate), 0, 0, NULL},
    {"hypo", "yield_tol", KEY_DOUBLE, SC(hypo.yield_tol), 0, 0, NULL},
    {"hypo", "jump_tol", KEY_DOUBLE, SC(hypo.jump_tol), 0, 0, NULL},
    {"hypo", "phi_fixed", KEY_DOUBLE, SC(hypo.phi_fixed), 0, 0, NULL},
    {"hypo", "log", KEY_INT, SC(hypo.log), 0, 0, NULL},
};
/* clang-format on */
#define N_KEYS (sizeof KEYS / sizeof KEYS[0])

void ekm_scenario_init_defaults(ekm_scenario *s)
{
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "unnamed");
    s->material = ekm_material_thesis();
    s->variant = EKM_VARIANT_FULL;
    s->closure = &ekm_closure_ekm_full;
    s->gravity = 0.0;
    s->angle_deg = 0.0;
    s->T_init = 0.0;
    s->layer_height = INFINITY;
    s->width = NAN; /* the 1D column: no x extent */
    s->cells_x = 1;
    s->periodic_x = 0;
    s->bottom.kind = s->top.kind = EKM_BC_WALL;
    s->bottom.t_stop = s->top.t_stop = INFINITY;
    s->bottom.inlet_x[0] = s->top.inlet_x[0] = NAN;   /* the middle of the end (set by the reader) */
    s->bottom.n_inlets = s->top.n_inlets = 1;         /* one segment */
    s->bottom.inlet_width = s->top.inlet_width = NAN; /* the whole end */
    s->bottom.plate_x = s->top.plate_x = NAN;         /* the middle of the end (set by the reader) */
    s->bottom.plate_width = s->top.plate_width = NAN; /* a wall over the whole end */
    s->bottom.w_return = s->top.w_return = NAN;       /* piston: -w */
    s->bottom.pressure = s->top.pressure = NAN;       /* the wall stays put */
    s->bottom.pressure_rate = s->top.pressure_rate = 1.0;
    s->bottom.shear_rate = s->top.shear_rate = NAN; /* the wall moves at its velocity */
    s->left = s->right = s->bottom;                 /* the side walls: resting, no slip */
    s->output_dt = 0.0;                             /* not given: t_end / 100 (check_scenario) */
    s->stop = EKM_STOP_T_END;
    s->steady_tol = 1e-3;
    s->steady_window = 0.0; /* not given: 10 output_dt (check_scenario) */
    s->numerics = (ekm_numerics){
        .cfl = 0.4,
        .convection = EKM_CONVECTION_UPWIND,
        .limiter = "vanleer",
        .dt_max = INFINITY,
        .dt_min = 1e-12,
        .phi_dry = 1e-9,
        .phi_vacuum = 0.0,
        .T_floor = 1e-16,
        .phi_step_max = 0.05,
        .solid_relax_step = 1e-4,
        .solid_lag_tol = 1e-3,
        .newton_tol = 1e-9,
        .newton_max = 30,
        .normal_coupling = EKM_COUPLING_IMPLICIT,
        .thermal_relax_step = 0.05,
        .gdot_min = NAN,
    };
    s->hypo = (ekm_hypo_params){
        .enabled = 0,
        .T_ratio = 1e-6,
        .phi_margin = 0.0,
        .phi_loose = 0.1,
        .rest_rate = 1e-4,
        .yield_tol = 1e-4,
        .jump_tol = 5e-4,
        .log = 0,
        .carry_over = 1,
        .initial_solid = 0,
        .initial_stress_ratio = 1.0,
    };
}

/* The sections a file may have, ekm's (the registry's) and the other
 * tools' (15), fewer than N_SECTIONS_MAX, each name shorter than
 * SECTION_NAME_MAX. */
#define N_SECTIONS_MAX   20
#define SECTION_NAME_MAX 16

typedef struct {
    ekm_scenario *s;
    const char *file;  /* file name or "--set" */
    const char *text;  /* the file's text being read (not NUL-terminated) */
    size_t size;       /* its length [B] */
    size_t pos;        /* where the next line starts [B] */
    int line;          /* current line number */
    ekm_origin origin; /* EKM_FROM_FILE, or EKM_FROM_SET while reading the --set overrides */
    int skip_material; /* 1: [material] of this file is ignored (a material file replaces it) */
    int material_only; /* 1: reading the material file: [material] only */
    int failed;
    ekm_status failed_status; /* the status of the failure recorded in err */
    ekm_error *err;
    int seen[N_KEYS]; /* 1 if the key was set */
    int seen_line[N_KEYS];
    char set_name[140]; /* "section.key" of the --set being read (messages: "--set section.key: ...") */
    struct {
        char name[SECTION_NAME_MAX];
        int line;
    } sections[N_SECTIONS_MAX]; /* the section headers of this file (each known, each once) */
    size_t n_sections;
} parse_ctx;

static int fail_at_line(parse_ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Record "FILE:LINE: message" (the line being read) and stop reading. */
static int fail_at_line(parse_ctx *c, const char *fmt, ...)
{
    if (!c->failed) {
        char buf[700];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(buf, sizeof buf, fmt, ap);
        va_end(ap);
        c->failed = 1;
        c->failed_status = EKM_EINPUT;
        EKM_FAIL(c->err, EKM_EINPUT, "%s:%d: %s", c->file, c->line, buf);
    }
    return 0;
}

static int section_known(const char *section)
{
    for (size_t i = 0; i < N_KEYS; i++)
        if (strcmp(KEYS[i].section, section) == 0)
            return 1;
    return 0;
}

#define SECTION_LIST                                                                                      \
    "scenario material model domain gravity initial bottom top left right run numerics hypo dem compare " \
    "campaign figures"

/* Where inih ends a name or a header: at one of chars, at an inline comment
 * (';' after a blank) or at the end (inih's find_chars_or_comment). */
static size_t span_to(const char *s, const char *chars)
{
    size_t i = 0;
    int was_space = 0;
    while (s[i] && !strchr(chars, s[i]) && !(was_space && s[i] == ';')) {
        was_space = isspace((unsigned char)s[i]);
        i++;
    }
    return i;
}

/* A section header line "[name]" (s starts with '['; blanks stripped):
 * a known section, given once, nothing after it but a comment. */
static int check_header(parse_ctx *c, const char *s)
{
    const size_t close = span_to(s + 1, "]") + 1;
    if (s[close] != ']')
        return fail_at_line(c, "malformed section header \"%s\" (expected [name])", s);
    const char *rest = s + close + 1;
    rest += strspn(rest, " \t\v\f\r");
    if (*rest && *rest != ';')
        return fail_at_line(
            c, "text after the section header \"%s\" (expected [name] alone, or a ';' comment)", s);
    const int len = (int)close - 1;
    char name[SECTION_NAME_MAX] = "";
    if (len < (int)sizeof name)
        snprintf(name, sizeof name, "%.*s", len, s + 1);
    if (len >= (int)sizeof name || (!section_known(name) && !ekm_tool_keys_is_section(name)))
        return fail_at_line(c, "[%.*s]: unknown section (the sections are " SECTION_LIST ")", len, s + 1);
    for (size_t i = 0; i < c->n_sections; i++)
        if (strcmp(c->sections[i].name, name) == 0)
            return fail_at_line(c, "[%s]: duplicate section (first at line %d)", name, c->sections[i].line);
    /* known sections are fewer than N_SECTIONS_MAX and each is here once */
    snprintf(c->sections[c->n_sections].name, sizeof c->sections[0].name, "%s", name);
    c->sections[c->n_sections++].line = c->line;
    return 1;
}

/* Check one line before inih parses it, so that a malformed line is the
 * error reported (inih goes on after one, and a later key of the wrong
 * section would be blamed instead). The line loses its leading blanks
 * (indentation means nothing; inih would take an indented line for the
 * continuation of the value above) and a UTF-8 byte-order mark. */
static int check_line(parse_ctx *c, char *str)
{
    char *s = str;
    if (c->line == 1 && strncmp(s, "\xEF\xBB\xBF", 3) == 0)
        s += 3;
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        n--;
    memmove(str, s, n);
    str[n] = '\0';
    if (n == 0 || str[0] == ';' || str[0] == '#')
        return 1;
    if (str[0] == '[')
        return check_header(c, str);
    const size_t name_end = span_to(str, "=:");
    if ((str[name_end] != '=' && str[name_end] != ':') || name_end == 0)
        return fail_at_line(c, "expected '[section]' or 'key = value'");
    if (c->n_sections == 0)
        return fail_at_line(c, "'%s': a key before the first [section]", str);
    return 1;
}

/* inih's line reader over the text in memory: one line (without its '\n')
 * at a time, each checked (check_line); a line longer than inih's buffer
 * is an error at that line. */
static char *reader(char *str, int num, void *stream)
{
    parse_ctx *c = stream;
    if (c->failed || c->pos >= c->size || num < 3)
        return NULL;
    const char *p = c->text + c->pos;
    const char *nl = memchr(p, '\n', c->size - c->pos);
    const size_t len = nl ? (size_t)(nl - p) : c->size - c->pos;
    c->pos += len + (nl != NULL);
    c->line++;
    if (len > (size_t)num - 2) {
        fail_at_line(c, "line longer than %d characters", num - 2);
        return NULL;
    }
    memcpy(str, p, len);
    str[len] = '\0';
    return check_line(c, str) ? str : NULL;
}

/* The first byte of t[0, size) that is a control character: any but tab;
 * with newlines, also not LF, nor CR before LF or at the end. Returns its
 * offset, or size. */
static size_t first_control(const unsigned char *t, size_t size, int newlines)
{
    for (size_t i = 0; i < size; i++) {
        const unsigned char b = t[i];
        if (b >= 0x20 && b != 0x7f)
            continue;
        if (b == '\t' || (newlines && b == '\n') ||
            (newlines && b == '\r' && (i + 1 == size || t[i + 1] == '\n')))
            continue;
        return i;
    }
    return size;
}

static void describe_byte(unsigned char b, char *buf, size_t size)
{
    if (b == 0)
        snprintf(buf, size, "a NUL byte");
    else
        snprintf(buf, size, "control character 0x%02x", b);
}

static int fail_once(parse_ctx *c, ekm_status code, const char *fmt, const char *section, const char *key,
                     const char *detail)
{
    if (!c->failed) {
        c->failed = 1;
        c->failed_status = code;
        char buf[700];
        snprintf(buf, sizeof buf, fmt, section, key, detail);
        if (c->origin == EKM_FROM_SET)
            EKM_FAIL(c->err, code, "--set %s: %s", c->set_name, buf);
        else
            EKM_FAIL(c->err, code, "%s:%d: %s", c->file, c->line, buf);
    }
    return 0;
}

static int parse_double(const char *v, double *out)
{
    return ekm_number_parse(v, out);
}

static int parse_int(const char *v, int *out)
{
    long long x;
    if (!ekm_number_parse_integer(v, &x) || x < -2147483647LL || x > 2147483647LL)
        return 0;
    *out = (int)x;
    return 1;
}

/* [bottom]/[top] inlet_x: 1 to EKM_INLETS_MAX numbers separated by blanks
 * (the sweep lists' syntax, number.h) into x[], their count into the
 * end's n_inlets; 0 after recording the error. */
static int parse_inlets(parse_ctx *c, const char *section, const char *key, const char *value, double *x)
{
    size_t n = 0;
    if (!ekm_number_parse_list(value, x, EKM_INLETS_MAX, &n))
        return fail_once(c, EKM_EINPUT,
                         "[%s] %s: expected a number or numbers separated by blanks (the "
                         "inlet centres [m]), got '%s'",
                         section, key, value);
    if (n > EKM_INLETS_MAX) {
        char detail[64];
        snprintf(detail, sizeof detail, "expected at most %d inlet centres, got %zu", EKM_INLETS_MAX, n);
        return fail_once(c, EKM_EINPUT, "[%s] %s: %s", section, key, detail);
    }
    ekm_bc *bc = strcmp(section, "bottom") == 0 ? &c->s->bottom : &c->s->top;
    bc->n_inlets = (int)n;
    return 1;
}

/* Set "section.key" = value in list (in place when it is there already). */
static ekm_status record_entry(ekm_entry **list, size_t *n, const char *section, const char *key,
                               const char *value, ekm_origin origin, int line, ekm_error *err)
{
    char name[sizeof((ekm_entry *)0)->name];
    snprintf(name, sizeof name, "%s.%s", section, key);
    ekm_entry *e = (ekm_entry *)ekm_scenario_entry_find(*list, *n, name);
    if (!e) {
        e = realloc(*list, (*n + 1) * sizeof *e);
        if (!e)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory reading the scenario");
        *list = e;
        e += (*n)++;
        snprintf(e->name, sizeof e->name, "%s", name);
    }
    snprintf(e->value, sizeof e->value, "%s", value);
    e->origin = origin;
    e->line = line;
    return EKM_OK;
}

const ekm_entry *ekm_scenario_entry_find(const ekm_entry *list, size_t n, const char *name)
{
    for (size_t i = 0; i < n; i++)
        if (strcmp(list[i].name, name) == 0)
            return &list[i];
    return NULL;
}

/* A key of a file already given in it: an error naming both lines (a
 * --set overrides a file's key: no error). */
static int refuse_duplicate(parse_ctx *c, const ekm_entry *list, size_t n, const char *section,
                            const char *key)
{
    if (c->origin == EKM_FROM_SET)
        return 0;
    char name[sizeof((ekm_entry *)0)->name], first[32];
    snprintf(name, sizeof name, "%s.%s", section, key);
    const ekm_entry *e = ekm_scenario_entry_find(list, n, name);
    if (!e)
        return 0;
    snprintf(first, sizeof first, "%d", e->line);
    fail_once(c, EKM_EINPUT, "[%s] %s: duplicate key (first at line %s)", section, key, first);
    return 1;
}

static int record_failed(parse_ctx *c)
{
    c->failed = 1;
    c->failed_status = c->err->code;
    return 0;
}

#define VALUE_MAX (sizeof(((ekm_entry *)0)->value) - 1)

/* A [material] key of a closure style other than the EKM (closure.h):
 * its number into its law_p slot, recorded like every key; whether the
 * scenario's closure reads it is checked after reading (check_closure). */
static int closure_param(parse_ctx *c, const char *section, const char *key, const char *value,
                         const ekm_closure *owner, size_t k)
{
    if (refuse_duplicate(c, c->s->entries, c->s->n_entries, section, key))
        return 0;
    double v;
    if (!parse_double(value, &v))
        return fail_once(c, EKM_EINPUT, "[%s] %s: expected a number, got '%s'", section, key, value);
    *ekm_closure_param_ptr(owner, k, &c->s->material) = v;
    if (record_entry(&c->s->entries, &c->s->n_entries, section, key, value, c->origin, c->line, c->err) !=
        EKM_OK)
        return record_failed(c);
    return 1;
}

static int handler(void *user, const char *section, const char *key, const char *value)
{
    parse_ctx *c = user;
    if (c->failed)
        return 0;
    if (c->skip_material && strcmp(section, "material") == 0)
        return 1;
    if (c->material_only && strcmp(section, "material") != 0)
        return fail_once(c, EKM_EINPUT, "[%s] %s: a material file holds only [material] (and comments)%s",
                         section, key, "");
    if (ekm_tool_keys_is_section(section)) {
        /* the other tools' keys: checked here, resolved by resolve.c */
        char why[700];
        if (!ekm_utf8_valid(value))
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected UTF-8 text%s", section, key, "");
        if (!ekm_tool_keys_check(section, key, value, why, sizeof why))
            return fail_once(c, EKM_EINPUT, "%s%s%s", why, "", "");
        if (refuse_duplicate(c, c->s->tool_entries, c->s->n_tool_entries, section, key))
            return 0;
        if (record_entry(&c->s->tool_entries, &c->s->n_tool_entries, section, key, value, c->origin, c->line,
                         c->err) != EKM_OK)
            return record_failed(c);
        return 1;
    }
    if (!section_known(section))
        return fail_once(c, EKM_EINPUT, "[%s]%s: unknown section (the sections are " SECTION_LIST ")%s",
                         section, "", "");
    size_t k;
    for (k = 0; k < N_KEYS; k++)
        if (strcmp(KEYS[k].section, section) == 0 && strcmp(KEYS[k].key, key) == 0)
            break;
    const ekm_closure *owner = NULL;
    size_t owner_k = 0;
    if (k == N_KEYS && strcmp(section, "material") == 0 && ekm_closure_param_find(key, &owner, &owner_k) == 0)
        return closure_param(c, section, key, value, owner, owner_k);
    if (k == N_KEYS)
        return fail_once(c, EKM_EINPUT, "[%s] %s: unknown key%s", section, key, "");
    if (refuse_duplicate(c, c->s->entries, c->s->n_entries, section, key))
        return 0;
    if (!ekm_utf8_valid(value))
        return fail_once(c, EKM_EINPUT, "[%s] %s: expected UTF-8 text%s", section, key, "");
    if (strlen(value) > VALUE_MAX) {
        char limit[32];
        snprintf(limit, sizeof limit, "%zu", VALUE_MAX);
        return fail_once(c, EKM_EINPUT, "[%s] %s: value longer than %s characters", section, key, limit);
    }
    const key_spec *ks = &KEYS[k];
    char *base = (char *)c->s;
    if (strcmp(key, "closure") == 0) {
        ekm_error cerr;
        const ekm_closure *cl = ekm_closure_find(value, &cerr);
        if (!cl)
            return fail_once(c, EKM_EINPUT, "[%s] %s: %s", section, key, cerr.message);
        c->s->closure = cl;
    } else if (strcmp(key, "variant") == 0) {
        if (strcmp(value, "full") == 0)
            c->s->variant = EKM_VARIANT_FULL;
        else if (strcmp(value, "thesis") == 0)
            c->s->variant = EKM_VARIANT_THESIS;
        else
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected 'full' or 'thesis', got '%s'", section, key,
                             value);
    } else if (strcmp(key, "convection") == 0) {
        if (strcmp(value, "upwind") == 0)
            c->s->numerics.convection = EKM_CONVECTION_UPWIND;
        else if (strcmp(value, "tvd") == 0)
            c->s->numerics.convection = EKM_CONVECTION_TVD;
        else
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected 'upwind' or 'tvd', got '%s'", section, key,
                             value);
    } else if (strcmp(key, "normal_coupling") == 0) {
        if (strcmp(value, "implicit") == 0)
            c->s->numerics.normal_coupling = EKM_COUPLING_IMPLICIT;
        else if (strcmp(value, "explicit") == 0)
            c->s->numerics.normal_coupling = EKM_COUPLING_EXPLICIT;
        else
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected 'implicit' or 'explicit', got '%s'", section,
                             key, value);
    } else if (strcmp(key, "stop") == 0) {
        if (strcmp(value, "t_end") == 0)
            c->s->stop = EKM_STOP_T_END;
        else if (strcmp(value, "steady") == 0)
            c->s->stop = EKM_STOP_STEADY;
        else
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected 't_end' or 'steady', got '%s'", section, key,
                             value);
    } else if (strcmp(key, "type") == 0) {
        ekm_bc *bc = strcmp(section, "bottom") == 0 ? &c->s->bottom
                     : strcmp(section, "top") == 0  ? &c->s->top
                     : strcmp(section, "left") == 0 ? &c->s->left
                                                    : &c->s->right;
        if (!ekm_boundary_kind_of(value, &bc->kind))
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected one of " EKM_BOUNDARY_KIND_NAMES ", got '%s'",
                             section, key, value);
    } else if ((strcmp(key, "pressure") == 0 || strcmp(key, "shear_rate") == 0) &&
               strcmp(value, "none") == 0) {
        *(double *)(base + ks->offset) = NAN; /* the wall stays put / moves at its velocity (the defaults) */
    } else if (ks->type == KEY_DOUBLE) {
        if (!parse_double(value, (double *)(base + ks->offset)))
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected a number, got '%s'", section, key, value);
    } else if (ks->type == KEY_DOUBLES) {
        if (!parse_inlets(c, section, key, value, (double *)(base + ks->offset)))
            return 0;
    } else if (ks->type == KEY_INT) {
        if (!parse_int(value, (int *)(base + ks->offset)))
            return fail_once(c, EKM_EINPUT, "[%s] %s: expected an integer, got '%s'", section, key, value);
    } else {
        if (strlen(value) >= ks->size)
            return fail_once(c, EKM_EINPUT, "[%s] %s: value longer than allowed: '%s'", section, key, value);
        snprintf(base + ks->offset, ks->size, "%s", value);
    }
    c->seen[k] = 1;
    c->seen_line[k] = c->line;
    if (record_entry(&c->s->entries, &c->s->n_entries, section, key, value, c->origin, c->line, c->err) !=
        EKM_OK)
        return record_failed(c);
    return 1;
}

/* Range checks after reading; each names the key and where it was set. */
typedef struct {
    const parse_ctx *c;
    ekm_error *err;
} check_ctx;

static const char *where(const parse_ctx *c, const char *section, const char *key, char *buf, size_t n)
{
    for (size_t k = 0; k < N_KEYS; k++)
        if (strcmp(KEYS[k].section, section) == 0 && strcmp(KEYS[k].key, key) == 0 && c->seen[k]) {
            const char *file = strcmp(section, "material") == 0 && c->s->material_source[0]
                                   ? c->s->material_source
                                   : c->file;
            if (c->seen_line[k] > 0)
                snprintf(buf, n, "%s:%d", file, c->seen_line[k]);
            else
                snprintf(buf, n, "--set %s.%s", section, key);
            return buf;
        }
    snprintf(buf, n, "%s", c->file);
    return buf;
}

/* Whether section.key was given (in a file or a --set). */
static int given(const parse_ctx *c, const char *section, const char *key)
{
    for (size_t k = 0; k < N_KEYS; k++)
        if (strcmp(KEYS[k].section, section) == 0 && strcmp(KEYS[k].key, key) == 0)
            return c->seen[k];
    return 0;
}

#define RANGE(cond, section, key, expect, value)                                                           \
    do {                                                                                                   \
        if (!(cond)) {                                                                                     \
            char w_[600];                                                                                  \
            return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] %s: expected %s, got %g",                           \
                            where(c, section, key, w_, sizeof w_), section, key, expect, (double)(value)); \
        }                                                                                                  \
    } while (0)

/* Whether `type` is one of the space-separated words of `list`. */
static int type_in(const char *list, const char *type)
{
    const size_t n = strlen(type);
    for (const char *p = list; (p = strstr(p, type)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == '\0' || p[n] == ' '))
            return 1;
    return 0;
}

static ekm_status check_bc(const parse_ctx *c, const ekm_scenario *s, const char *side, const ekm_bc *bc,
                           ekm_error *err)
{
    const char *type = ekm_boundary_kind_name(bc->kind);
    for (size_t k = 0; k < N_KEYS; k++)
        if (strcmp(KEYS[k].section, side) == 0 && KEYS[k].only_for_bc && c->seen[k] &&
            !type_in(KEYS[k].only_for_bc, type)) {
            char w_[600];
            return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] %s: only allowed with type = %s (this side is %s)",
                            where(c, side, KEYS[k].key, w_, sizeof w_), side, KEYS[k].key,
                            KEYS[k].only_for_bc, type);
        }
    /* the keys a type needs (no default): missing, named at the type's line */
    static const struct {
        ekm_bc_kind kind;
        const char *key;
    } needs[] = {
        {EKM_BC_INFLOW, "phi"}, {EKM_BC_INFLOW, "w"}, {EKM_BC_PISTON, "w"}, {EKM_BC_PISTON, "period"}};
    for (size_t i = 0; i < sizeof needs / sizeof needs[0]; i++)
        if (bc->kind == needs[i].kind && !given(c, side, needs[i].key)) {
            char w_[600];
            return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] %s: missing (required with type = %s)",
                            where(c, side, "type", w_, sizeof w_), side, needs[i].key, type);
        }
    const double phi_cp = s->material.phi_cp;
    if (bc->kind == EKM_BC_WALL)
        RANGE(bc->slip_length >= 0.0, side, "slip_length", "a length >= 0 [m]", bc->slip_length);
    if (bc->kind == EKM_BC_INFLOW) {
        RANGE(bc->phi > 0.0 && bc->phi < phi_cp, side, "phi", "a volume fraction in (0, phi_cp)", bc->phi);
        int bottom = strcmp(side, "bottom") == 0;
        RANGE(bottom ? bc->w > 0.0 : bc->w < 0.0, side, "w",
              bottom ? "a velocity > 0 (into the domain)" : "a velocity < 0 (into the domain)", bc->w);
        RANGE(bc->T >= 0.0, side, "T", "a temperature >= 0 [m^2/s^2]", bc->T);
        RANGE(bc->t_stop > 0.0, side, "t_stop", "a time > 0 [s]", bc->t_stop);
    }
    if (bc->kind == EKM_BC_WALL && !isnan(bc->pressure)) {
        RANGE(strcmp(side, "top") == 0, side, "pressure",
              "no pressure on the bottom wall (only the top wall moves)", bc->pressure);
        RANGE(bc->pressure > 0.0, side, "pressure", "a pressure > 0 [Pa]", bc->pressure);
        RANGE(bc->pressure_rate > 0.0, side, "pressure_rate", "a rate > 0 [1/s]", bc->pressure_rate);
    }
    if (bc->kind == EKM_BC_WALL && !isnan(bc->shear_rate)) {
        char w_[600];
        RANGE(strcmp(side, "top") == 0, side, "shear_rate",
              "no shear_rate on the bottom wall (the top wall's speed follows the gap)", bc->shear_rate);
        if (isnan(bc->pressure))
            return EKM_FAIL(
                err, EKM_EINPUT,
                "%s: [top] shear_rate: only with [top] pressure (the wall held at a pressure, its "
                "gap moving; at a fixed gap the rate is ([top] velocity - [bottom] velocity) / "
                "[domain] length)",
                where(c, side, "shear_rate", w_, sizeof w_));
        RANGE(bc->shear_rate > 0.0, side, "shear_rate", "a rate > 0 [1/s]", bc->shear_rate);
        for (size_t k = 0; k < N_KEYS; k++)
            if (strcmp(KEYS[k].section, "top") == 0 && strcmp(KEYS[k].key, "velocity") == 0 && c->seen[k])
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: [top] velocity: not with [top] shear_rate (the top wall then moves at "
                                "[bottom] velocity + shear_rate * gap)",
                                where(c, side, "velocity", w_, sizeof w_));
        if (s->bottom.kind != EKM_BC_WALL)
            return EKM_FAIL(
                err, EKM_EINPUT,
                "%s: [top] shear_rate: needs [bottom] type = wall (the top wall moves at [bottom] "
                "velocity + shear_rate * gap), got %s",
                where(c, side, "shear_rate", w_, sizeof w_), ekm_boundary_kind_name(s->bottom.kind));
    }
    if (bc->kind == EKM_BC_PISTON) {
        RANGE(bc->w != 0.0, side, "w", "a velocity != 0 [m/s]", bc->w);
        RANGE(bc->period > 0.0, side, "period", "a time > 0 [s]", bc->period);
    }
    return EKM_OK;
}

/* A segment of an end, [centre - width/2, centre + width/2] ("inlet" or
 * "plate": its keys WHAT_x, WHAT_width): inside the end and holding a
 * face centre of the cells_x along x. */
static ekm_status check_segment(const parse_ctx *c, const ekm_scenario *s, const char *end, const char *what,
                                double centre, double width, ekm_error *err)
{
    char w_[600], key_x[32], key_w[32];
    snprintf(key_x, sizeof key_x, "%s_x", what);
    snprintf(key_w, sizeof key_w, "%s_width", what);
    const double lo = centre - 0.5 * width, hi = centre + 0.5 * width;
    const double slack = 1e-12 * s->width;
    if (!(lo >= -slack && hi <= s->width + slack)) {
        const char *key = given(c, end, key_x) ? key_x : key_w;
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [%s] %s: the %s [%g, %g] m is outside the %s boundary [0, %g] m "
                        "(%s +- %s/2 must lie in [0, [domain] width])",
                        where(c, end, key, w_, sizeof w_), end, key, what, lo, hi, end, s->width, key_x,
                        key_w);
    }
    int faces = 0;
    for (int i = 0; i < s->cells_x; i++) {
        const double xc = (i + 0.5) * s->width / s->cells_x;
        faces += xc >= lo && xc <= hi;
    }
    if (faces == 0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [%s] %s: the %s [%g, %g] m holds no face centre of the %d cells "
                        "along x (%g m wide): widen it or refine cells_x",
                        where(c, end, key_w, w_, sizeof w_), end, key_w, what, lo, hi, s->cells_x,
                        s->width / s->cells_x);
    return EKM_OK;
}

/* The inlet segments of an inflow end with an inlet_width: several only
 * in a 2D domain (cells_x > 1), each inside the end and holding a face
 * centre (check_inlet), no two overlapping (touching is allowed). */
static ekm_status check_inlets(const parse_ctx *c, const ekm_scenario *s, const char *end, const ekm_bc *bc,
                               ekm_error *err)
{
    char w_[600];
    if (bc->n_inlets > 1 && s->cells_x < 2)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [%s] inlet_x: %d inlets need a 2D domain ([domain] cells_x > 1; the 1D column "
                        "has one face per end)",
                        where(c, end, "inlet_x", w_, sizeof w_), end, bc->n_inlets);
    const double half = 0.5 * bc->inlet_width, slack = 1e-12 * s->width;
    for (int q = 0; q < bc->n_inlets; q++) {
        const ekm_status st = check_segment(c, s, end, "inlet", bc->inlet_x[q], bc->inlet_width, err);
        if (st != EKM_OK)
            return st;
        for (int p = 0; p < q; p++)
            if (fabs(bc->inlet_x[q] - bc->inlet_x[p]) < bc->inlet_width - slack)
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: [%s] inlet_x: the inlets [%g, %g] m and [%g, %g] m overlap (expected "
                                "centres at least inlet_width = %g m apart)",
                                where(c, end, "inlet_x", w_, sizeof w_), end, bc->inlet_x[p] - half,
                                bc->inlet_x[p] + half, bc->inlet_x[q] - half, bc->inlet_x[q] + half,
                                bc->inlet_width);
    }
    return EKM_OK;
}

/* A wall end's plate ([bottom]/[top] plate_x, plate_width; 2D): inside the
 * end, holding a face centre, on a wall that stays put (a moving wall
 * with openings is not a model here). */
static ekm_status check_plate(const parse_ctx *c, ekm_scenario *s, const char *end, ekm_bc *bc,
                              ekm_error *err)
{
    char w_[600];
    if (given(c, end, "plate_x") && !given(c, end, "plate_width"))
        return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] plate_x: needs [%s] plate_width (the plate's width [m])",
                        where(c, end, "plate_x", w_, sizeof w_), end, end);
    if (!given(c, end, "plate_width"))
        return EKM_OK;
    if (!given(c, end, "plate_x"))
        bc->plate_x = 0.5 * s->width; /* centred */
    RANGE(bc->plate_width > 0.0, end, "plate_width", "a width > 0 [m]", bc->plate_width);
    if (isfinite(bc->pressure) || isfinite(bc->shear_rate))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [%s] plate_width: a wall with openings must stay put (no pressure, no "
                        "shear_rate on the same end)",
                        where(c, end, "plate_width", w_, sizeof w_), end);
    return check_segment(c, s, end, "plate", bc->plate_x, bc->plate_width, err);
}

/* The keys of a 2D domain's boundaries: the side walls ([left], [right]:
 * a box with walls, not periodic in x) and an inflow's opening time and
 * inlet segments (a domain with a width): check_inlets. */
static ekm_status check_boundaries_2d(const parse_ctx *c, ekm_scenario *s, ekm_error *err)
{
    char w_[600];
    const char *sides[2] = {"left", "right"};
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < N_KEYS; i++) {
            if (strcmp(KEYS[i].section, sides[k]) != 0 || !c->seen[i])
                continue;
            const char *where_ = where(c, sides[k], KEYS[i].key, w_, sizeof w_);
            if (!isfinite(s->width))
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: [%s] %s: needs [domain] width (the side walls of a 2D box)", where_,
                                sides[k], KEYS[i].key);
            if (s->periodic_x)
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: [%s] %s: [domain] periodic_x = 1 has no side walls (set periodic_x = 0 "
                                "for a box with walls at x = 0 and x = width)",
                                where_, sides[k], KEYS[i].key);
        }
    const ekm_bc *sw[2] = {&s->left, &s->right};
    for (int k = 0; k < 2; k++)
        if (sw[k]->kind != EKM_BC_WALL) {
            char key_at[600];
            snprintf(key_at, sizeof key_at, "%s", where(c, sides[k], "type", w_, sizeof w_));
            return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] type: expected wall (a side of a 2D box), got %s",
                            key_at, sides[k], ekm_boundary_kind_name(sw[k]->kind));
        }
    const char *keys_2d[2] = {"surface_fill", "solid_lag_tol"};
    for (int k = 0; k < 2; k++)
        if (given(c, "numerics", keys_2d[k]) && !isfinite(s->width))
            return EKM_FAIL(err, EKM_EINPUT, "%s: [numerics] %s: needs [domain] width (a key of a 2D domain)",
                            where(c, "numerics", keys_2d[k], w_, sizeof w_), keys_2d[k]);
    const char *ends[2] = {"bottom", "top"};
    ekm_bc *eb[2] = {&s->bottom, &s->top};
    const char *keys2d[5] = {"t_start", "inlet_x", "inlet_width", "plate_x", "plate_width"};
    for (int k = 0; k < 2; k++) {
        ekm_bc *bc = eb[k];
        for (int q = 0; q < 5; q++)
            if (given(c, ends[k], keys2d[q]) && !isfinite(s->width))
                return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] %s: needs [domain] width (a key of a 2D domain)",
                                where(c, ends[k], keys2d[q], w_, sizeof w_), ends[k], keys2d[q]);
        if (bc->kind == EKM_BC_WALL) {
            const ekm_status st = check_plate(c, s, ends[k], bc, err);
            if (st != EKM_OK)
                return st;
        }
        if (bc->kind != EKM_BC_INFLOW)
            continue;
        RANGE(bc->t_start >= 0.0 && bc->t_start < bc->t_stop, ends[k], "t_start",
              "a time >= 0 and before t_stop [s]", bc->t_start);
        if (given(c, ends[k], "inlet_x") && !given(c, ends[k], "inlet_width"))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [%s] inlet_x: needs [%s] inlet_width (the inlet segment [m])",
                            where(c, ends[k], "inlet_x", w_, sizeof w_), ends[k], ends[k]);
        if (!given(c, ends[k], "inlet_width"))
            continue;
        if (!given(c, ends[k], "inlet_x"))
            bc->inlet_x[0] = 0.5 * s->width; /* centred */
        RANGE(bc->inlet_width > 0.0, ends[k], "inlet_width", "a width > 0 [m]", bc->inlet_width);
        const ekm_status st = check_inlets(c, s, ends[k], bc, err);
        if (st != EKM_OK)
            return st;
    }
    return EKM_OK;
}

/* 1 if word is one of the blank-separated words of list. */
static int word_listed(const char *list, const char *word)
{
    const size_t n = strlen(word);
    for (const char *p = list + strspn(list, " "); *p; p += strspn(p, " ")) {
        const size_t len = strcspn(p, " ");
        if (len == n && strncmp(p, word, n) == 0)
            return 1;
        p += len;
    }
    return 0;
}

/* Where a [material] key outside the registry's KEYS (a closure's) was
 * given: FILE:LINE or --set. */
static const char *where_entry(const parse_ctx *c, const ekm_entry *e, char *buf, size_t n)
{
    if (e->origin == EKM_FROM_SET)
        snprintf(buf, n, "--set %s", e->name);
    else
        snprintf(buf, n, "%s:%d", e->origin == EKM_FROM_MATERIAL ? c->s->material_source : c->s->source,
                 e->line);
    return buf;
}

/* The closure: [model] closure and the older [model] variant agree; the
 * closure's own [material] keys are all given and no other closure's is;
 * an EKM [material] key it does not read is not given (closure.h). */
static ekm_status check_closure(const parse_ctx *c, ekm_scenario *s, ekm_error *err)
{
    char w_[600];
    int has_closure = given(c, "model", "closure"), has_variant = given(c, "model", "variant");
    if (has_closure && has_variant && !(s->closure->is_ekm && s->closure->variant == s->variant)) {
        /* a --set overrides the file's key of the other spelling */
        const ekm_entry *ec = ekm_scenario_entry_find(s->entries, s->n_entries, "model.closure");
        const ekm_entry *ev = ekm_scenario_entry_find(s->entries, s->n_entries, "model.variant");
        if (ec && ev && (ec->origin == EKM_FROM_SET) != (ev->origin == EKM_FROM_SET)) {
            if (ec->origin == EKM_FROM_SET)
                has_variant = 0;
            else
                has_closure = 0;
        }
    }
    if (has_closure && has_variant && !(s->closure->is_ekm && s->closure->variant == s->variant))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [model] variant = %s disagrees with [model] closure = %s (variant is the older "
                        "spelling of closure = ekm_full | ekm_thesis: give one of them)",
                        where(c, "model", "variant", w_, sizeof w_),
                        s->variant == EKM_VARIANT_THESIS ? "thesis" : "full", s->closure->name);
    if (!has_closure)
        s->closure = ekm_closure_of_variant(s->variant);
    else if (s->closure->ekm_transport)
        s->variant = s->closure->variant;
    for (size_t i = 0; i < s->n_entries; i++) {
        const ekm_entry *e = &s->entries[i];
        if (strncmp(e->name, "material.", 9) != 0)
            continue;
        const char *key = e->name + 9;
        const ekm_closure *owner;
        size_t k;
        if (ekm_closure_param_find(key, &owner, &k) == 0) {
            if (owner != s->closure)
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: [material] %s: a parameter of closure %s, but [model] closure = %s",
                                where_entry(c, e, w_, sizeof w_), key, owner->name, s->closure->name);
        } else if (!ekm_closure_reads_ekm_key(s->closure, key)) {
            char list[300] = "";
            for (const char *const *q = s->closure->ekm_keys; *q; q++) {
                const size_t n = strlen(list);
                snprintf(list + n, sizeof list - n, "%s%s", n ? ", " : "", *q);
            }
            for (size_t j = 0; j < s->closure->nparams; j++) {
                const size_t n = strlen(list);
                snprintf(list + n, sizeof list - n, ", %s", s->closure->params[j].key);
            }
            return EKM_FAIL(err, EKM_EINPUT, "%s: [material] %s: closure %s does not read it (its keys: %s)",
                            where_entry(c, e, w_, sizeof w_), key, s->closure->name, list);
        }
    }
    for (size_t j = 0; j < s->closure->nparams; j++) {
        const ekm_closure_param *p = &s->closure->params[j];
        char name[80];
        snprintf(name, sizeof name, "material.%s", p->key);
        if (!ekm_scenario_entry_find(s->entries, s->n_entries, name))
            return EKM_FAIL(err, EKM_EINPUT, "%s: [material] %s: missing (closure %s needs it: %s [%s])",
                            s->material_source[0] ? s->material_source : c->file, p->key, s->closure->name,
                            p->about, p->unit);
    }
    return EKM_OK;
}

static ekm_status check_scenario(const parse_ctx *c, ekm_scenario *s, ekm_error *err)
{
    const char *material_file = s->material_source[0] ? s->material_source : c->file;
    ekm_status cst = check_closure(c, s, err);
    if (cst != EKM_OK)
        return cst;
    for (size_t k = 0; k < N_KEYS; k++)
        if (KEYS[k].required && !c->seen[k] &&
            !(strcmp(KEYS[k].section, "material") == 0 &&
              !ekm_closure_reads_ekm_key(s->closure, KEYS[k].key)))
            return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] %s: missing (a required key)",
                            strcmp(KEYS[k].section, "material") == 0 ? material_file : c->file,
                            KEYS[k].section, KEYS[k].key);
    ekm_error merr;
    if (ekm_closure_check(s->closure, &s->material, &merr) != EKM_OK) {
        /* merr says "[material] KEY: ..."; prefix where KEY came from (FILE:LINE of the
         * scenario or material file, or --set) */
        char key[64] = "", w_[600], name[80];
        if (sscanf(merr.message, "[material] %63[^:]", key) != 1)
            key[0] = '\0';
        snprintf(name, sizeof name, "material.%s", key);
        const ekm_entry *ce =
            s->closure->nparams ? ekm_scenario_entry_find(s->entries, s->n_entries, name) : NULL;
        return EKM_FAIL(err, EKM_EINPUT, "%s: %s",
                        ce ? where_entry(c, ce, w_, sizeof w_) : where(c, "material", key, w_, sizeof w_),
                        merr.message);
    }
    RANGE(s->length > 0.0, "domain", "length", "a length > 0 [m]", s->length);
    RANGE(s->cells >= 1 && s->cells <= 10000000, "domain", "cells", "an integer in [1, 1e7]", s->cells);
    /* the 2D domain: width, cells_x and periodic_x only with a width */
    if (given(c, "domain", "width"))
        RANGE(s->width > 0.0, "domain", "width", "a width > 0 [m]", s->width);
    RANGE(s->cells_x >= 1 && s->cells_x <= 10000000, "domain", "cells_x", "an integer in [1, 1e7]",
          s->cells_x);
    RANGE(s->periodic_x == 0 || s->periodic_x == 1, "domain", "periodic_x", "0 or 1", s->periodic_x);
    for (int k = 0; k < 2; k++) {
        const char *key = k == 0 ? "cells_x" : "periodic_x";
        if (given(c, "domain", key) && !given(c, "domain", "width")) {
            char w_[600];
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [domain] %s: needs [domain] width (the 2D domain's x extent [m])",
                            where(c, "domain", key, w_, sizeof w_), key);
        }
    }
    RANGE(s->gravity >= 0.0, "gravity", "magnitude", "a number >= 0 [m/s^2]", s->gravity);
    RANGE(fabs(s->angle_deg) <= 180.0, "gravity", "angle", "an angle in [-180, 180] degrees", s->angle_deg);
    RANGE(s->phi_init >= 0.0 && s->phi_init < s->material.phi_cp, "initial", "phi",
          "a volume fraction in [0, phi_cp)", s->phi_init);
    RANGE(s->T_init >= 0.0, "initial", "T", "a temperature >= 0 [m^2/s^2]", s->T_init);
    RANGE(s->layer_height > 0.0, "initial", "layer_height", "a height > 0 [m]", s->layer_height);
    RANGE(s->t_end > 0.0, "run", "t_end", "a time > 0 [s]", s->t_end);
    /* output_dt and steady_window: given, a time > 0; not given, their defaults */
    if (!given(c, "run", "output_dt"))
        s->output_dt = s->t_end / 100.0;
    RANGE(s->output_dt > 0.0, "run", "output_dt", "a time > 0 [s]", s->output_dt);
    /* the frames written: the initial state and one every output_dt to t_end */
    if (!(s->t_end / s->output_dt <= EKM_SCENARIO_MAX_FRAMES - 1)) {
        char w_[600];
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [run] output_dt: expected a time >= t_end / %d = %g s (at most %d output "
                        "frames), got %g",
                        where(c, "run", "output_dt", w_, sizeof w_), EKM_SCENARIO_MAX_FRAMES - 1,
                        s->t_end / (EKM_SCENARIO_MAX_FRAMES - 1), EKM_SCENARIO_MAX_FRAMES, s->output_dt);
    }
    RANGE(s->steady_tol > 0.0, "run", "steady_tol", "a rate > 0 [1/s]", s->steady_tol);
    if (!given(c, "run", "steady_window"))
        s->steady_window = 10.0 * s->output_dt;
    RANGE(s->steady_window > 0.0, "run", "steady_window", "a time > 0 [s]", s->steady_window);
    const ekm_numerics *n = &s->numerics;
    RANGE(n->cfl > 0.0 && n->cfl <= 1.0, "numerics", "cfl", "a number in (0, 1]", n->cfl);
    RANGE(n->dt_max > 0.0, "numerics", "dt_max", "a time > 0 [s]", n->dt_max);
    RANGE(n->dt_min > 0.0, "numerics", "dt_min", "a time > 0 [s]", n->dt_min);
    if (!(n->dt_min < n->dt_max)) {
        /* blame the one given (dt_min's default is 1e-12 s, dt_max's none) */
        char w_[600];
        if (given(c, "numerics", "dt_min"))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [numerics] dt_min: expected a time in (0, dt_max = %g) [s], got %g",
                            where(c, "numerics", "dt_min", w_, sizeof w_), n->dt_max, n->dt_min);
        return EKM_FAIL(err, EKM_EINPUT, "%s: [numerics] dt_max: expected a time > dt_min = %g s, got %g",
                        where(c, "numerics", "dt_max", w_, sizeof w_), n->dt_min, n->dt_max);
    }
    RANGE(n->phi_dry > 0.0 && n->phi_dry < 1e-3, "numerics", "phi_dry", "a number in (0, 1e-3)", n->phi_dry);
    RANGE(n->phi_vacuum >= 0.0 && n->phi_vacuum < 0.1, "numerics", "phi_vacuum", "a number in [0, 0.1)",
          n->phi_vacuum);
    RANGE(n->T_floor > 0.0, "numerics", "T_floor", "a temperature > 0 [m^2/s^2]", n->T_floor);
    RANGE(n->phi_step_max > 0.0 && n->phi_step_max < 1.0, "numerics", "phi_step_max", "a number in (0, 1)",
          n->phi_step_max);
    RANGE(n->surface_fill == 0 || n->surface_fill == 1, "numerics", "surface_fill", "0 or 1",
          (double)n->surface_fill);
    RANGE(n->solid_relax_step > 0.0 && n->solid_relax_step <= 1.0, "numerics", "solid_relax_step",
          "a number in (0, 1]", n->solid_relax_step);
    RANGE(n->solid_lag_tol > 0.0 && n->solid_lag_tol <= 1.0, "numerics", "solid_lag_tol",
          "a number in (0, 1]", n->solid_lag_tol);
    RANGE(n->thermal_relax_step > 0.0 && n->thermal_relax_step <= 10.0, "numerics", "thermal_relax_step",
          "a number in (0, 10]", n->thermal_relax_step);
    RANGE(n->newton_tol > 0.0 && n->newton_tol < 1e-2, "numerics", "newton_tol", "a number in (0, 1e-2)",
          n->newton_tol);
    RANGE(n->newton_max >= 1, "numerics", "newton_max", "an integer >= 1", n->newton_max);
    RANGE(isnan(n->gdot_min) || (n->gdot_min > 0.0 && isfinite(n->gdot_min)), "numerics", "gdot_min",
          "a shear rate > 0 [1/s]", n->gdot_min);
    if (!word_listed(EKM_SCENARIO_LIMITERS, n->limiter)) {
        char w_[600];
        return EKM_FAIL(err, EKM_EINPUT, "%s: [numerics] limiter: unknown limiter '%s' (known: %s)",
                        where(c, "numerics", "limiter", w_, sizeof w_), n->limiter, EKM_SCENARIO_LIMITERS);
    }
    const ekm_hypo_params *h = &s->hypo;
    RANGE(h->enabled == 0 || h->enabled == 1, "hypo", "enabled", "0 or 1", h->enabled);
    RANGE(h->log == 0 || h->log == 1, "hypo", "log", "0 or 1", h->log);
    RANGE(h->T_ratio > 0.0, "hypo", "T_ratio", "a number > 0", h->T_ratio);
    RANGE(h->phi_margin >= 0.0 && h->phi_margin < s->material.phi_cp - s->material.phi_co, "hypo",
          "phi_margin", "a number in [0, phi_cp - phi_co)", h->phi_margin);
    if (!given(c, "hypo", "phi_loose") && !(h->phi_loose <= s->material.phi_co)) {
        /* the default against a given phi_co: blame phi_co */
        char w_[600];
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [material] phi_co: expected a number >= [hypo] phi_loose = %g (its default; "
                        "give a smaller [hypo] phi_loose), got %g",
                        where(c, "material", "phi_co", w_, sizeof w_), h->phi_loose, s->material.phi_co);
    }
    RANGE(h->phi_loose > 0.0 && h->phi_loose <= s->material.phi_co, "hypo", "phi_loose",
          "a number in (0, phi_co]", h->phi_loose);
    RANGE(h->rest_rate >= 0.0, "hypo", "rest_rate", "a rate >= 0 [1/s]", h->rest_rate);
    RANGE(h->yield_tol > 0.0 && h->yield_tol < 0.1, "hypo", "yield_tol", "a number in (0, 0.1)",
          h->yield_tol);
    RANGE(h->jump_tol > 0.0 && h->jump_tol < 1.0, "hypo", "jump_tol", "a number in (0, 1)", h->jump_tol);
    RANGE(h->phi_fixed == 0.0 || (h->phi_fixed > s->material.phi_co && h->phi_fixed < s->material.phi_cp),
          "hypo", "phi_fixed", "0 (the cell's phi) or a number in (phi_co, phi_cp)", h->phi_fixed);
    RANGE(h->initial_solid == 0 || h->initial_solid == 1, "initial", "solid", "0 or 1", h->initial_solid);
    RANGE(!h->initial_solid || h->enabled, "initial", "solid", "0 unless [hypo] enabled = 1",
          h->initial_solid);
    RANGE(h->initial_settled == 0 || h->initial_settled == 1, "initial", "settled", "0 or 1",
          h->initial_settled);
    RANGE(!h->initial_settled || h->initial_solid, "initial", "settled", "0 unless [initial] solid = 1",
          h->initial_settled);
    RANGE(h->initial_stress_ratio >= 0.0, "initial", "stress_ratio", "a number >= 0",
          h->initial_stress_ratio);
    RANGE(isfinite(s->angle_rate), "gravity", "angle_rate", "a rate [deg/s]", s->angle_rate);
    ekm_status st = check_bc(c, s, "bottom", &s->bottom, err);
    if (st == EKM_OK)
        st = check_bc(c, s, "top", &s->top, err);
    if (st == EKM_OK)
        st = check_boundaries_2d(c, s, err);
    if (st == EKM_OK)
        st = check_bc(c, s, "left", &s->left, err);
    if (st == EKM_OK)
        st = check_bc(c, s, "right", &s->right, err);
    if (st == EKM_OK && ekm_boundary_rate_wall(&s->top))
        s->top.velocity = s->bottom.velocity; /* its speed at zero gap (bc.h) */
    return st;
}

ekm_status ekm_scenario_set_material(ekm_scenario *s, const ekm_material *m, ekm_error *err)
{
    /* the reader's context rebuilt from the keys s was read with: which
     * keys were given, and where (the messages name FILE:LINE or --set) */
    parse_ctx c = {.s = s, .file = s->source, .err = err};
    for (size_t i = 0; i < s->n_entries; i++) {
        const ekm_entry *e = &s->entries[i];
        for (size_t k = 0; k < N_KEYS; k++) {
            const size_t ls = strlen(KEYS[k].section);
            if (strncmp(e->name, KEYS[k].section, ls) == 0 && e->name[ls] == '.' &&
                strcmp(e->name + ls + 1, KEYS[k].key) == 0) {
                c.seen[k] = 1;
                c.seen_line[k] = e->origin == EKM_FROM_SET ? 0 : e->line;
            }
        }
    }
    const ekm_material keep = s->material;
    s->material = *m;
    const ekm_status st = check_scenario(&c, s, err);
    if (st != EKM_OK)
        s->material = keep;
    return st;
}

/* Parse one text into c (t->name names it in the messages). */
static ekm_status parse_text(parse_ctx *c, const ekm_scenario_text *t, ekm_error *err)
{
    c->file = t->name;
    c->text = t->text;
    c->size = t->size;
    c->pos = 0;
    c->line = 0;
    c->n_sections = 0;
    const size_t bad = first_control((const unsigned char *)t->text, t->size, 1);
    if (bad < t->size) {
        int line = 1;
        size_t line_start = 0;
        for (size_t i = 0; i < bad; i++)
            if (t->text[i] == '\n')
                line++, line_start = i + 1;
        char what[64];
        describe_byte((unsigned char)t->text[bad], what, sizeof what);
        return EKM_FAIL(err, EKM_EINPUT, "%s:%d:%zu: %s: expected text (no control characters but tab)",
                        t->name, line, bad - line_start + 1, what);
    }
    const int rc = ini_parse_stream(reader, c, handler, c);
    if (c->failed)
        return c->failed_status;
    if (rc > 0) /* not reached: check_line refuses what inih would */
        return EKM_FAIL(err, EKM_EINPUT, "%s:%d: expected '[section]' or 'key = value'", t->name, rc);
    if (rc < 0)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: inih failed (%d)", t->name, rc);
    return EKM_OK;
}

/* Read a whole file into *buf (malloc'd, *size bytes): a regular file
 * (opened without blocking, so that a FIFO is refused, not waited on) of
 * at most EKM_SCENARIO_MAX_BYTES. */
static ekm_status read_file(const char *path, const char *what, char **buf, size_t *size, ekm_error *err)
{
    *buf = NULL;
    *size = 0;
    const int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open %s: %s", path, what, strerror(errno));
    struct stat fst;
    if (fstat(fd, &fst) != 0 || !S_ISREG(fst.st_mode)) {
        close(fd);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot read %s: not a regular file", path, what);
    }
    if (fst.st_size > EKM_SCENARIO_MAX_BYTES) {
        close(fd);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot read %s: %lld bytes, more than the %d a scenario may have",
                        path, what, (long long)fst.st_size, EKM_SCENARIO_MAX_BYTES);
    }
    /* room for one byte more than the limit: a file that grew meanwhile */
    char *b = malloc((size_t)EKM_SCENARIO_MAX_BYTES + 1);
    if (!b) {
        close(fd);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory reading %s", path);
    }
    size_t got = 0;
    while (got <= (size_t)EKM_SCENARIO_MAX_BYTES) {
        const ssize_t n = read(fd, b + got, (size_t)EKM_SCENARIO_MAX_BYTES + 1 - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            const int e = errno;
            close(fd);
            free(b);
            return EKM_FAIL(err, EKM_EIO, "%s: cannot read %s: %s", path, what, strerror(e));
        }
        if (n == 0)
            break;
        got += (size_t)n;
    }
    close(fd);
    if (got > (size_t)EKM_SCENARIO_MAX_BYTES) {
        free(b);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot read %s: more than the %d bytes a scenario may have", path,
                        what, EKM_SCENARIO_MAX_BYTES);
    }
    *buf = b;
    *size = got;
    return EKM_OK;
}

ekm_status ekm_scenario_load(ekm_scenario *s, const char *path, const char *const *overrides,
                             size_t n_overrides, ekm_error *err)
{
    return ekm_scenario_load_material(s, path, NULL, overrides, n_overrides, err);
}

ekm_status ekm_scenario_load_material(ekm_scenario *s, const char *path, const char *material_path,
                                      const char *const *overrides, size_t n_overrides, ekm_error *err)
{
    ekm_scenario_init_defaults(s);
    char *text = NULL, *material_text = NULL;
    ekm_scenario_text file = {.name = path}, material = {.name = material_path};
    ekm_status st = read_file(path, "scenario file", &text, &file.size, err);
    if (st == EKM_OK && material_path)
        st = read_file(material_path, "material file", &material_text, &material.size, err);
    if (st == EKM_OK) {
        file.text = text;
        material.text = material_text;
        st = ekm_scenario_load_texts(s, &file, material_path ? &material : NULL, overrides, n_overrides, err);
    } else
        snprintf(s->source, sizeof s->source, "%s", path);
    free(text);
    free(material_text);
    return st;
}

/* One --set "section.key=value" (the i-th, from 1) into c. */
static ekm_status apply_override(parse_ctx *c, const char *o, size_t i, ekm_error *err)
{
    const size_t len = strlen(o), bad = first_control((const unsigned char *)o, len, 0);
    if (bad < len) {
        char what[64];
        describe_byte((unsigned char)o[bad], what, sizeof what);
        return EKM_FAIL(err, EKM_EINPUT,
                        "--set number %zu: %s at character %zu: expected section.key=value (one line of "
                        "text)",
                        i, what, bad + 1);
    }
    const char *dot = strchr(o, '.');
    const char *eq = strchr(o, '=');
    if (!dot || !eq || dot > eq || dot == o || eq == dot + 1)
        return EKM_FAIL(err, EKM_EINPUT, "--set %s: expected section.key=value", o);
    char section[64], key[64];
    if ((size_t)(dot - o) >= sizeof section || (size_t)(eq - dot - 1) >= sizeof key)
        return EKM_FAIL(err, EKM_EINPUT,
                        "--set %.*s: expected section.key=value (a key of at most %zu characters)",
                        (int)(eq - o), o, sizeof key - 1);
    snprintf(section, sizeof section, "%.*s", (int)(dot - o), o);
    snprintf(key, sizeof key, "%.*s", (int)(eq - dot - 1), dot + 1);
    c->file = "--set";
    c->line = (int)i;
    c->origin = EKM_FROM_SET;
    snprintf(c->set_name, sizeof c->set_name, "%s.%s", section, key);
    if (!handler(c, section, key, eq + 1))
        return c->failed_status;
    /* --set entries are marked with line 0 so messages say "--set". */
    for (size_t k = 0; k < N_KEYS; k++)
        if (strcmp(KEYS[k].section, section) == 0 && strcmp(KEYS[k].key, key) == 0)
            c->seen_line[k] = 0;
    return EKM_OK;
}

ekm_status ekm_scenario_load_texts(ekm_scenario *s, const ekm_scenario_text *file,
                                   const ekm_scenario_text *material, const char *const *overrides,
                                   size_t n_overrides, ekm_error *err)
{
    ekm_scenario_init_defaults(s);
    snprintf(s->source, sizeof s->source, "%s", file->name);
    parse_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory reading %s", file->name);
    *c = (parse_ctx){.s = s, .file = file->name, .err = err, .skip_material = material != NULL};
    ekm_status st = parse_text(c, file, err);
    if (st == EKM_OK && material) {
        snprintf(s->material_source, sizeof s->material_source, "%s", material->name);
        c->skip_material = 0;
        c->material_only = 1;
        c->origin = EKM_FROM_MATERIAL;
        st = parse_text(c, material, err);
        c->material_only = 0;
    }
    for (size_t i = 0; i < n_overrides && st == EKM_OK; i++)
        st = apply_override(c, overrides[i], i + 1, err);
    c->file = file->name;
    /* Messages about --set keys say where they came from. */
    if (st == EKM_OK)
        st = check_scenario(c, s, err);
    free(c);
    return st;
}

void ekm_scenario_free(ekm_scenario *s)
{
    if (!s)
        return;
    free(s->entries);
    s->entries = NULL;
    s->n_entries = 0;
    free(s->tool_entries);
    s->tool_entries = NULL;
    s->n_tool_entries = 0;
}

size_t ekm_scenario_key_count(void)
{
    return N_KEYS;
}

void ekm_scenario_key_name(size_t i, const char **section, const char **key)
{
    *section = KEYS[i].section;
    *key = KEYS[i].key;
}

/* The shortest "%.*g" that reads back as x. */
static void format_shortest(double x, char *buf, size_t size)
{
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(buf, size, "%.*g", digits, x);
        if (strtod(buf, NULL) == x)
            return;
    }
}

/* An end's inlet centres separated by blanks (as inlet_x is written);
 * 0 when there is none to show (no segment: the whole end). */
static int format_inlets(const ekm_bc *bc, char *value, size_t size)
{
    size_t used = 0;
    value[0] = '\0';
    for (int q = 0; q < bc->n_inlets; q++) {
        char one[32];
        if (!isfinite(bc->inlet_x[q]))
            return 0;
        format_shortest(bc->inlet_x[q], one, sizeof one);
        const int w = snprintf(value + used, size - used, "%s%s", q ? " " : "", one);
        if (w < 0 || (size_t)w >= size - used)
            return 0;
        used += (size_t)w;
    }
    return 1;
}

int ekm_scenario_key_default(const ekm_scenario *s, size_t i, char *value, size_t size)
{
    const key_spec *ks = &KEYS[i];
    const char *base = (const char *)s;
    const ekm_bc *bc = strcmp(ks->section, "bottom") == 0  ? &s->bottom
                       : strcmp(ks->section, "top") == 0   ? &s->top
                       : strcmp(ks->section, "left") == 0  ? &s->left
                       : strcmp(ks->section, "right") == 0 ? &s->right
                                                           : NULL;
    if (ks->only_for_bc && !type_in(ks->only_for_bc, ekm_boundary_kind_name(bc->kind)))
        return 0;
    const int box_2d = isfinite(s->width) && s->cells_x > 1;
    if ((strcmp(ks->section, "left") == 0 || strcmp(ks->section, "right") == 0) && (!box_2d || s->periodic_x))
        return 0; /* the side walls of a 2D box only */
    if (bc && (strcmp(ks->key, "t_start") == 0 || strcmp(ks->key, "inlet_x") == 0) && !isfinite(s->width))
        return 0; /* keys of a 2D domain only */
    if (bc && strcmp(ks->key, "velocity") == 0 && ekm_boundary_rate_wall(bc))
        return 0; /* not a key: the speed follows the gap */
    if (((strcmp(ks->section, "domain") == 0 &&
          (strcmp(ks->key, "cells_x") == 0 || strcmp(ks->key, "periodic_x") == 0)) ||
         strcmp(ks->key, "surface_fill") == 0 || strcmp(ks->key, "solid_lag_tol") == 0) &&
        !isfinite(s->width))
        return 0; /* keys of a 2D domain only (a width given) */
    if (strcmp(ks->key, "variant") == 0) {
        if (!s->closure->is_ekm)
            return 0; /* not a key of this closure */
        snprintf(value, size, "%s", s->variant == EKM_VARIANT_THESIS ? "thesis" : "full");
    } else if (strcmp(ks->key, "closure") == 0)
        snprintf(value, size, "%s", s->closure->name);
    else if (strcmp(ks->key, "convection") == 0)
        snprintf(value, size, "%s", s->numerics.convection == EKM_CONVECTION_TVD ? "tvd" : "upwind");
    else if (strcmp(ks->key, "normal_coupling") == 0)
        snprintf(value, size, "%s",
                 s->numerics.normal_coupling == EKM_COUPLING_EXPLICIT ? "explicit" : "implicit");
    else if (strcmp(ks->key, "stop") == 0)
        snprintf(value, size, "%s", s->stop == EKM_STOP_STEADY ? "steady" : "t_end");
    else if (bc && strcmp(ks->key, "type") == 0)
        snprintf(value, size, "%s", ekm_boundary_kind_name(bc->kind));
    else if (ks->type == KEY_DOUBLE) {
        const double x = *(const double *)(base + ks->offset);
        if (!isfinite(x))
            return 0;
        format_shortest(x, value, size);
    } else if (ks->type == KEY_DOUBLES)
        return format_inlets(bc, value, size);
    else if (ks->type == KEY_INT)
        snprintf(value, size, "%d", *(const int *)(base + ks->offset));
    else
        snprintf(value, size, "%s", base + ks->offset);
    return 1;
}

ekm_status ekm_scenario_require_1d(const ekm_scenario *s, const char *why, ekm_error *err)
{
    if (s->cells_x <= 1)
        return EKM_OK;
    const ekm_entry *e = ekm_scenario_entry_find(s->entries, s->n_entries, "domain.cells_x");
    char from[600];
    if (e && e->origin == EKM_FROM_SET)
        snprintf(from, sizeof from, "--set domain.cells_x");
    else
        snprintf(from, sizeof from, "%s:%d", s->source, e ? e->line : 0);
    return EKM_FAIL(err, EKM_EUNAVAILABLE, "%s: [domain] cells_x = %d: %s", from, s->cells_x, why);
}

double ekm_scenario_angle_at(const ekm_scenario *s, double t)
{
    return s->angle_deg + (t > s->angle_start ? s->angle_rate * (t - s->angle_start) : 0.0);
}

double ekm_scenario_law_phi(const ekm_scenario *s, double phi)
{
    return s->hypo.phi_fixed > 0.0 ? s->hypo.phi_fixed : phi;
}

double ekm_scenario_gravity_x(const ekm_scenario *s)
{
    return s->gravity * sin(s->angle_deg * DEG);
}

double ekm_scenario_gravity_z(const ekm_scenario *s)
{
    return -s->gravity * cos(s->angle_deg * DEG);
}
