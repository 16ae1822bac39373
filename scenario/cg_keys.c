/* cg_keys.c: the typed table of `ekmcompare cg`'s options (cg_keys.h). */
#include "cg_keys.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const ekm_cg_key CG_KEYS[] = {
    {"-o", EKM_CG_OUT, 1, 0, "HDF5 output"},
    {"--csv", EKM_CG_CSV, 1, 0, "CSV output"},
    {"--axis", EKM_CG_AXIS, 1, 1, "profile axis x, y or z"},
    {"--axes", EKM_CG_AXES, 1, 1, "z (a 1D profile) or x,z (a 2D grid)"},
    {"--ensemble", EKM_CG_ENSEMBLE, 0, 1, "2D: every input an independent run"},
    {"--kernel", EKM_CG_KERNEL, 1, 1, "gauss, lucy or bins"},
    {"--width", EKM_CG_WIDTH, 1, 1, "kernel width [m]"},
    {"--bins", EKM_CG_BINS, 1, 1, "number of bins (NX,NZ in 2D)"},
    {"--dz", EKM_CG_DZ, 1, 1, "bin spacing [m]"},
    {"--range", EKM_CG_RANGE, 1, 1, "LO:HI of the grid [m]"},
    {"--rho-p", EKM_CG_RHO_P, 1, 1, "grain density [kg/m^3]"},
    {"--dt", EKM_CG_DT, 1, 0, "engine time step [s]"},
    {"--from", EKM_CG_FROM, 1, 1, "first time [s]"},
    {"--to", EKM_CG_TO, 1, 1, "last time [s]"},
    {"--steps", EKM_CG_STEPS, 1, 1, "A:B, the steps kept"},
    {"--steady", EKM_CG_STEADY, 0, 1, "from the steady start (MSER-5)"},
    {"--exact-kernel", EKM_CG_EXACT, 0, 1, "the kernel per particle"},
    {"--every", EKM_CG_EVERY, 1, 1, "one profile per N snapshots"},
    {"--window", EKM_CG_WINDOW, 1, 1, "one profile per window [s]"},
    {"--temperature", EKM_CG_TEMPERATURE, 1, 1, "particle or consistent"},
    {"--stress", EKM_CG_STRESS, 1, 1, "per-atom stress: a prefix or six names"},
    {"--pairs", EKM_CG_PAIRS, 1, 0, "pair dump"},
    {"--pair-columns", EKM_CG_PAIR_COLUMNS, 1, 1, "the pair dump's 9 or 5 column names"},
    {"--types", EKM_CG_TYPES, 1, 1, "the atom types that count"},
    {"--expect-snapshots", EKM_CG_EXPECT_SNAPSHOTS, 1, 1, "the snapshots the dumps must hold"},
    {"--quiet", EKM_CG_QUIET, 0, 0, "no notes on stderr"},
};
#define N_CG_KEYS (sizeof CG_KEYS / sizeof CG_KEYS[0])

const ekm_cg_key *ekm_cg_keys_find(const char *option)
{
    for (size_t i = 0; i < N_CG_KEYS; i++)
        if (strcmp(CG_KEYS[i].option, option) == 0)
            return &CG_KEYS[i];
    return NULL;
}

static ekm_status cg_number(const char *opt, const char *s, double *out, ekm_error *err)
{
    char *end;
    const double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v))
        return EKM_FAIL(err, EKM_EUSAGE, "%s: expected a number, got '%s'", opt, s);
    *out = v;
    return EKM_OK;
}

static ekm_status cg_count(const char *opt, const char *s, size_t *out, ekm_error *err)
{
    char *end;
    const long long v = strtoll(s, &end, 10);
    if (end == s || *end || v < 1)
        return EKM_FAIL(err, EKM_EUSAGE, "%s: expected a positive integer, got '%s'", opt, s);
    *out = (size_t)v;
    return EKM_OK;
}

static ekm_status cg_pair(const char *opt, const char *s, double *a, double *b, ekm_error *err)
{
    const char *c = strchr(s, ':');
    char *end;
    if (c) {
        *a = strtod(s, &end);
        if (end == c) {
            *b = strtod(c + 1, &end);
            if (end != c + 1 && !*end && isfinite(*a) && isfinite(*b))
                return EKM_OK;
        }
    }
    return EKM_FAIL(err, EKM_EUSAGE, "%s: expected A:B, got '%s'", opt, s);
}

/* A number > 0, or "OPT: expected WHAT, got 'S'". */
static ekm_status cg_positive(const char *opt, const char *s, const char *what, double *out, ekm_error *err)
{
    ekm_status rc = cg_number(opt, s, out, err);
    if (!rc && !(*out > 0))
        rc = EKM_FAIL(err, EKM_EUSAGE, "%s: expected %s, got '%s'", opt, what, s);
    return rc;
}

/* n comma-separated non-empty names (n_lo or n_hi of them) into v->names. */
static int cg_names(const char *s, size_t n_lo, size_t n_hi, ekm_cg_value *v)
{
    size_t n = 0;
    for (const char *p = s;;) {
        const char *q = strchr(p, ',');
        const size_t len = q ? (size_t)(q - p) : strlen(p);
        if (len == 0 || len >= EKM_CG_NAME_MAX || n == n_hi)
            return 0;
        memcpy(v->names[n], p, len);
        v->names[n++][len] = '\0';
        if (!q) {
            v->n_names = n;
            return n == n_lo || n == n_hi;
        }
        p = q + 1;
    }
}

static ekm_status cg_stress(const char *s, ekm_cg_value *v, ekm_error *err)
{
    if (!strchr(s, ',')) {
        for (int c = 0; c < 6; c++)
            if ((size_t)snprintf(v->names[c], EKM_CG_NAME_MAX, "%s[%d]", s, c + 1) >= EKM_CG_NAME_MAX)
                return EKM_FAIL(err, EKM_EUSAGE, "--stress: name too long: '%s'", s);
        v->n_names = 6;
        return EKM_OK;
    }
    if (!cg_names(s, 6, 6, v))
        return EKM_FAIL(err, EKM_EUSAGE, "--stress: expected a prefix or six comma-separated names, got '%s'",
                        s);
    return EKM_OK;
}

static ekm_status cg_types(const char *s, ekm_cg_value *v, ekm_error *err)
{
    v->n_types = 0;
    for (const char *p = s;;) {
        char *end;
        const long t = strtol(p, &end, 10);
        if (end == p || t < 0 || t > 1000000 || (*end && *end != ','))
            return EKM_FAIL(err, EKM_EUSAGE,
                            "--types: expected comma-separated atom types (integers), got '%s'", s);
        if (v->n_types == EKM_CG_TYPES_MAX)
            return EKM_FAIL(err, EKM_EUSAGE, "--types: at most 16 types, got '%s'", s);
        v->types[v->n_types++] = (int)t;
        if (!*end)
            return EKM_OK;
        p = end + 1;
    }
}

static ekm_status cg_bins(const char *s, ekm_cg_value *v, ekm_error *err)
{
    const char *comma = strchr(s, ',');
    if (!comma)
        return cg_count("--bins", s, &v->count, err);
    char nx[32];
    size_t len = (size_t)(comma - s);
    if (len >= sizeof nx)
        len = sizeof nx - 1;
    memcpy(nx, s, len);
    nx[len] = '\0';
    ekm_status rc = cg_count("--bins", nx, &v->count_x, err);
    if (!rc)
        rc = cg_count("--bins", comma + 1, &v->count, err);
    if (rc)
        rc = EKM_FAIL(err, EKM_EUSAGE, "--bins: expected N, or NX,NZ with --axes x,z, got '%s'", s);
    return rc;
}

static int word_in(const char *list, const char *w)
{
    const size_t n = strlen(w);
    for (const char *p = list + strspn(list, " "); *p; p += strspn(p, " ")) {
        const size_t len = strcspn(p, " ");
        if (len == n && strncmp(p, w, n) == 0)
            return 1;
        p += len;
    }
    return 0;
}

ekm_status ekm_cg_keys_parse(const ekm_cg_key *k, const char *s, ekm_cg_value *v, ekm_error *err)
{
    memset(v, 0, sizeof *v);
    v->id = k->id;
    v->text = s;
    v->axis2 = -1;
    const char *opt = k->option;
    switch (k->id) {
    case EKM_CG_OUT:
    case EKM_CG_CSV:
    case EKM_CG_PAIRS:
    case EKM_CG_ENSEMBLE:
    case EKM_CG_STEADY:
    case EKM_CG_EXACT:
    case EKM_CG_QUIET: return EKM_OK;
    case EKM_CG_AXIS:
        if (s[0] >= 'x' && s[0] <= 'z' && !s[1]) {
            v->axis = s[0] - 'x';
            return EKM_OK;
        }
        return EKM_FAIL(err, EKM_EUSAGE, "--axis: expected x, y or z, got '%s'", s);
    case EKM_CG_AXES:
        if (!strcmp(s, "x,z")) {
            v->axis = 2;
            v->axis2 = 0;
            return EKM_OK;
        }
        if (s[0] >= 'x' && s[0] <= 'z' && !s[1]) {
            v->axis = s[0] - 'x';
            return EKM_OK;
        }
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--axes: expected z (a 1D profile, the default; or x, y) or x,z (a 2D grid averaged "
                        "over y), got '%s'",
                        s);
    case EKM_CG_KERNEL:
        if (word_in(EKM_CG_KERNELS, s))
            return EKM_OK;
        return EKM_FAIL(err, EKM_EUSAGE, "--kernel: expected gauss, lucy or bins, got '%s'", s);
    case EKM_CG_WIDTH: return cg_positive(opt, s, "a positive width", &v->x, err);
    case EKM_CG_BINS: return cg_bins(s, v, err);
    case EKM_CG_DZ: return cg_positive(opt, s, "a positive spacing", &v->x, err);
    case EKM_CG_RANGE: {
        ekm_status rc = cg_pair(opt, s, &v->x, &v->y, err);
        if (!rc && !(v->y > v->x))
            rc = EKM_FAIL(err, EKM_EUSAGE, "--range: expected LO < HI, got '%s'", s);
        return rc;
    }
    case EKM_CG_RHO_P: return cg_positive(opt, s, "a positive density", &v->x, err);
    case EKM_CG_DT: return cg_positive(opt, s, "a positive time step", &v->x, err);
    case EKM_CG_FROM:
    case EKM_CG_TO: return cg_number(opt, s, &v->x, err);
    case EKM_CG_STEPS: {
        ekm_status rc = cg_pair(opt, s, &v->x, &v->y, err);
        if (!rc && (v->x != floor(v->x) || v->y != floor(v->y) || v->y < v->x))
            rc = EKM_FAIL(err, EKM_EUSAGE, "--steps: expected integers A:B with A <= B, got '%s'", s);
        return rc;
    }
    case EKM_CG_EVERY:
    case EKM_CG_EXPECT_SNAPSHOTS: return cg_count(opt, s, &v->count, err);
    case EKM_CG_WINDOW: return cg_positive(opt, s, "a positive duration", &v->x, err);
    case EKM_CG_TEMPERATURE:
        if (!strcmp(s, "particle") || !strcmp(s, "consistent")) {
            v->flag = !strcmp(s, "consistent");
            return EKM_OK;
        }
        return EKM_FAIL(err, EKM_EUSAGE, "--temperature: expected particle or consistent, got '%s'", s);
    case EKM_CG_STRESS: return cg_stress(s, v, err);
    case EKM_CG_PAIR_COLUMNS:
        if (cg_names(s, 5, 9, v))
            return EKM_OK;
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--pair-columns: expected 9 names (x1,y1,z1,x2,y2,z2,fx,fy,fz) or 5 "
                        "(id1,id2,fx,fy,fz), got '%s'",
                        s);
    case EKM_CG_TYPES: return cg_types(s, v, err);
    }
    return EKM_FAIL(err, EKM_EINTERNAL, "%s: no parser", opt);
}

int ekm_cg_keys_check_line(const char *line, char *why, size_t size)
{
    char word[EKM_CG_NAME_MAX * 10], value[EKM_CG_NAME_MAX * 10];
    const char *blanks = " \t";
    for (const char *p = line + strspn(line, blanks); *p; p += strspn(p, blanks)) {
        size_t len = strcspn(p, blanks);
        snprintf(word, sizeof word, "%.*s", (int)len, p);
        p += len;
        const ekm_cg_key *k = word[0] == '-' ? ekm_cg_keys_find(word) : NULL;
        if (!k) {
            snprintf(why, size, "%s: %s (expected options of `ekmcompare cg`)", word,
                     word[0] == '-' ? "unknown option" : "not an option");
            return 0;
        }
        if (!k->in_scenario) {
            snprintf(why, size, "%s: not here (the campaign adds the dumps, -o, --csv, --dt and --quiet)",
                     word);
            return 0;
        }
        const char *v = NULL;
        if (k->takes_value) {
            p += strspn(p, blanks);
            len = strcspn(p, blanks);
            if (!len) {
                snprintf(why, size, "%s: expected a value", word);
                return 0;
            }
            snprintf(value, sizeof value, "%.*s", (int)len, p);
            p += len;
            v = value;
        }
        ekm_cg_value parsed;
        ekm_error err = {0};
        if (ekm_cg_keys_parse(k, v, &parsed, &err) != EKM_OK) {
            snprintf(why, size, "%s", err.message);
            return 0;
        }
    }
    return 1;
}
