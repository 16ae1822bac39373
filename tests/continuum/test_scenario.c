/* The scenario reader (scenario.c) and the resolved scenario (resolve.c):
 * every error message of docs/scenario-format.md with its file:line, section
 * and key; the [dem]/[compare] lookup rule and defaults; the sweep points of
 * the shipped scenarios with their tags and ekm overrides. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "resolve.h"
#include "scenario.h"

/* A valid scenario of 29 lines: a text appended to it starts at line 30. */
static const char BASE[] = "[scenario]\n"
                           "name = t\n"
                           "[material]\n"
                           "rho_p = 2500\n"
                           "phi_co = 0.60\n"
                           "phi_cp = 0.64\n"
                           "T0 = 1.5\n"
                           "eta0 = 3.55e-4\n"
                           "zeta0 = 1e-4\n"
                           "lambda0 = 3.4e-4\n"
                           "eps0 = 212.2\n"
                           "nu = 1\n"
                           "A_h = 200e6\n"
                           "B_h = 200e6\n"
                           "alpha = 0\n"
                           "[domain]\n"
                           "length = 0.06\n"
                           "cells = 60\n"
                           "[gravity]\n"
                           "magnitude = 9.81\n"
                           "angle = 24\n"
                           "[initial]\n"
                           "phi = 0.57\n"
                           "[bottom]\n"
                           "type = wall\n"
                           "[top]\n"
                           "type = free\n"
                           "[run]\n"
                           "t_end = 5\n";

#define FILE_NAME "scenario_test.ini"
/* 65 characters: longer than the 63 [scenario] name holds */
#define NAME_65 "abcdefghijklmnopqrstuvwxyzabcdefghijklmnopqrstuvwxyzabcdefghijklm"

static void write_file(const char *text)
{
    FILE *fp = fopen(FILE_NAME, "w");
    assert_non_null(fp);
    assert_true(fputs(text, fp) >= 0);
    assert_int_equal(fclose(fp), 0);
}

/* BASE with `edit`: a line "-key" removes the first line starting with
 * "key " from BASE, "=key:TEXT" replaces it by TEXT, "+key:TEXT" inserts
 * TEXT after it (a section of BASE is given once); the other lines are
 * appended. */
static void write_scenario(const char *edit)
{
    char text[8192];
    snprintf(text, sizeof text, "%s", BASE);
    const char *p = edit;
    char append[4096] = "";
    while (p && *p) {
        const char *nl = strchr(p, '\n');
        size_t len = nl ? (size_t)(nl - p) : strlen(p);
        if (p[0] == '-' || p[0] == '=' || p[0] == '+') {
            const char *colon = memchr(p, ':', len);
            const size_t key_len = p[0] == '-' ? len - 1 : (size_t)(colon - p - 1);
            assert_true(p[0] == '-' || colon);
            char key[64];
            snprintf(key, sizeof key, "\n%.*s ", (int)key_len, p + 1);
            char *at = strstr(text, key);
            assert_non_null(at);
            char *end = strchr(at + 1, '\n');
            char rest[8192];
            snprintf(rest, sizeof rest, "%s", end + 1);
            if (p[0] == '-')
                memmove(at, end, strlen(end) + 1);
            else
                snprintf(p[0] == '+' ? end : at, sizeof text - (size_t)((p[0] == '+' ? end : at) - text),
                         "\n%.*s\n%s", (int)(len - key_len - 2), colon + 1, rest);
        } else {
            strncat(append, p, len);
            strcat(append, "\n");
        }
        p = nl ? nl + 1 : NULL;
    }
    strncat(text, append, sizeof text - strlen(text) - 1);
    write_file(text);
}

typedef struct {
    const char *what;
    const char *edit;    /* write_scenario() edit */
    const char *sets[3]; /* --set overrides, NULL-terminated */
    ekm_status status;
    const char *message; /* the whole error line */
} error_case;

/* Reading errors of ekm's sections: docs/scenario-format.md. */
static const error_case EKM_ERRORS[] = {
    {"malformed number",
     "[numerics]\ncfl = 5x0",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] cfl: expected a number, got '5x0'"},
    {"infinite number",
     "[numerics]\ndt_max = inf",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] dt_max: expected a number, got 'inf'"},
    {"malformed integer",
     "[numerics]\nnewton_max = 3.5",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] newton_max: expected an integer, got '3.5'"},
    {"unknown key", "+alpha:foo = 1", {NULL}, EKM_EINPUT, FILE_NAME ":16: [material] foo: unknown key"},
    {"prefixed key of ekm",
     "+cells:ref.cells = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":19: [domain] ref.cells: unknown key"},
    {"unknown section",
     "[materal]\nrho_p = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME
     ":30: [materal]: unknown section (the sections are scenario material model domain gravity initial "
     "bottom top left right run numerics hypo dem compare campaign figures)"},
    {"section in capitals",
     "[DEM]\nlx = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":30: [DEM]: unknown section (the sections are scenario material model domain gravity initial "
               "bottom top left right run numerics hypo dem compare campaign figures)"},
    {"missing key", "-eps0", {NULL}, EKM_EINPUT, FILE_NAME ": [material] eps0: missing (a required key)"},
    {"value longer than allowed",
     "=name:name = " NAME_65,
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":2: [scenario] name: value longer than allowed: '" NAME_65 "'"},
    {"syntax", "this is not ini", {NULL}, EKM_EINPUT, FILE_NAME ":30: expected '[section]' or 'key = value'"},
    {"variant",
     "[model]\nvariant = half",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [model] variant: expected 'full' or 'thesis', got 'half'"},
    {"convection",
     "[numerics]\nconvection = weno",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] convection: expected 'upwind' or 'tvd', got 'weno'"},
    {"normal coupling",
     "[numerics]\nnormal_coupling = semi",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] normal_coupling: expected 'implicit' or 'explicit', got 'semi'"},
    {"boundary type",
     NULL,
     {"bottom.type=moving", NULL},
     EKM_EINPUT,
     "--set bottom.type: [bottom] type: expected one of wall inflow outflow free piston, got 'moving'"},
    {"material check",
     "=phi_cp:phi_cp = -0.64",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":6: [material] phi_cp: expected a positive number, got -0.64"},
    {"range in the file",
     "[numerics]\ncfl = 2",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] cfl: expected a number in (0, 1], got 2"},
    {"range of a --set",
     NULL,
     {"domain.length=-1", NULL},
     EKM_EINPUT,
     "--set domain.length: [domain] length: expected a length > 0 [m], got -1"},
    {"cells",
     NULL,
     {"domain.cells=0", NULL},
     EKM_EINPUT,
     "--set domain.cells: [domain] cells: expected an integer in [1, 1e7], got 0"},
    {"key of another boundary type",
     "+type:phi = 0.3",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":26: [bottom] phi: only allowed with type = inflow (this side is wall)"},
    {"limiter",
     NULL,
     {"numerics.limiter=foo", NULL},
     EKM_EINPUT,
     "--set numerics.limiter: [numerics] limiter: unknown limiter 'foo' (known: minmod vanleer superbee mc)"},
    {"solid without hypo",
     NULL,
     {"initial.solid=1", NULL},
     EKM_EINPUT,
     "--set initial.solid: [initial] solid: expected 0 unless [hypo] enabled = 1, got 1"},
    {"settled without solid",
     NULL,
     {"initial.settled=1", NULL},
     EKM_EINPUT,
     "--set initial.settled: [initial] settled: expected 0 unless [initial] solid = 1, got 1"},
    {"hypo yield_tol",
     NULL,
     {"hypo.enabled=1", "hypo.yield_tol=0.5", NULL},
     EKM_EINPUT,
     "--set hypo.yield_tol: [hypo] yield_tol: expected a number in (0, 0.1), got 0.5"},
    {"hypo phi_loose",
     "[hypo]\nphi_loose = 0.7",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [hypo] phi_loose: expected a number in (0, phi_co], got 0.7"},
    {"--set syntax", NULL, {"domain=1", NULL}, EKM_EINPUT, "--set domain=1: expected section.key=value"},
    {"--set unknown key",
     NULL,
     {"domain.size=1", NULL},
     EKM_EINPUT,
     "--set domain.size: [domain] size: unknown key"},
    {"--set material range",
     NULL,
     {"material.phi_cp=-1", NULL},
     EKM_EINPUT,
     "--set material.phi_cp: [material] phi_cp: expected a positive number, got -1"},
    {"--set position",
     NULL,
     {"domain.cells=10", "gravity.angle=x", NULL},
     EKM_EINPUT,
     "--set gravity.angle: [gravity] angle: expected a number, got 'x'"},
    /* the number literal: the whole value, decimal, finite */
    {"nan",
     "[numerics]\ncfl = nan",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] cfl: expected a number, got 'nan'"},
    {"exponent without digits",
     "[numerics]\ncfl = 1e",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] cfl: expected a number, got '1e'"},
    {"two numbers",
     "=rho_p:rho_p = 16 00",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":4: [material] rho_p: expected a number, got '16 00'"},
    {"hex",
     "=rho_p:rho_p = 0x640",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":4: [material] rho_p: expected a number, got '0x640'"},
    {"hex integer",
     "=cells:cells = 0x3c",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":18: [domain] cells: expected an integer, got '0x3c'"},
    {"trailing garbage",
     "=rho_p:rho_p = 2500kg",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":4: [material] rho_p: expected a number, got '2500kg'"},
    {"underflow",
     "[numerics]\ncfl = 1e-400",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [numerics] cfl: expected a number, got '1e-400'"},
    {"--set infinity",
     NULL,
     {"material.rho_p=infinity", NULL},
     EKM_EINPUT,
     "--set material.rho_p: [material] rho_p: expected a number, got 'infinity'"},
    {"--set trailing blank",
     NULL,
     {"domain.cells=60 ", NULL},
     EKM_EINPUT,
     "--set domain.cells: [domain] cells: expected an integer, got '60 '"},
    /* one line, one meaning */
    {"duplicate key",
     "+rho_p:rho_p = 2600",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":5: [material] rho_p: duplicate key (first at line 4)"},
    {"duplicate section",
     "[domain]",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":30: [domain]: duplicate section (first at line 16)"},
    {"text after a header",
     "[numerics] cfl = 0.3",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":30: text after the section header \"[numerics] cfl = 0.3\" (expected [name] alone, or a ';' "
               "comment)"},
    {"malformed header",
     "[numerics ; a comment]\ncfl = 0.3",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":30: malformed section header \"[numerics ; a comment]\" (expected [name])"},
    {"empty key",
     "[numerics]\n: 0.3",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: expected '[section]' or 'key = value'"},
    {"control character",
     "[numerics]\ncfl = 0.3\x1b[0m",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31:10: control character 0x1b: expected text (no control characters but tab)"},
    {"CR inside a line",
     "[numerics]\ncfl = 0.3\rx",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31:10: control character 0x0d: expected text (no control characters but tab)"},
    {"value longer than an entry",
     "+name:description = " NAME_65 NAME_65 "abcdefghijklmnopqrstuvwxyz0123",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":3: [scenario] description: value longer than 159 characters"},
    {"output_dt 0 in [run]",
     "+t_end:output_dt = 0",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":30: [run] output_dt: expected a time > 0 [s], got 0"},
    {"steady_window 0",
     "+t_end:steady_window = 0",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":30: [run] steady_window: expected a time > 0 [s], got 0"},
    {"too many frames",
     "+t_end:output_dt = 4.99e-5",
     {NULL},
     EKM_EINPUT,
     FILE_NAME
     ":30: [run] output_dt: expected a time >= t_end / 99999 = 5.00005e-05 s (at most 100000 output "
     "frames), got 4.99e-05"},
    {"piston without w",
     NULL,
     {"top.type=piston", "top.period=1", NULL},
     EKM_EINPUT,
     "--set top.type: [top] w: missing (required with type = piston)"},
    {"inflow without w",
     "=type:type = inflow\n+type:phi = 0.3",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":25: [bottom] w: missing (required with type = inflow)"},
    {"--set key too long",
     NULL,
     {"dem.abcdefghijklmnopqrstuvwxyzabcdefghijklmnopqrstuvwxyzabcdefghijklmnopq=1", NULL},
     EKM_EINPUT,
     "--set dem.abcdefghijklmnopqrstuvwxyzabcdefghijklmnopqrstuvwxyzabcdefghijklmnopq: expected "
     "section.key=value (a key of at most 63 characters)"},
    {"--set with a newline",
     NULL,
     {"scenario.name=a\nb", NULL},
     EKM_EINPUT,
     "--set number 1: control character 0x0a at character 16: expected section.key=value (one line of text)"},
    {"--set not UTF-8",
     NULL,
     {"scenario.name=caf\xe9", NULL},
     EKM_EINPUT,
     "--set scenario.name: [scenario] name: expected UTF-8 text"},
};

/* Reading errors of the other tools' sections. */
static const error_case TOOL_ERRORS[] = {
    {"[dem] unknown key",
     "[dem]\nref.foo = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] ref.foo: unknown key"},
    {"[dem] unknown prefix",
     "[dem]\nbig.lx = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] big.lx: unknown prefix (expected k, <engine>.k, <size>.k or <engine>.<size>.k; "
               "engine liggghts or lammps, size smoke or ref)"},
    {"[dem] size before engine",
     "[dem]\nref.lammps.lx = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] ref.lammps.lx: unknown prefix (expected k, <engine>.k, <size>.k or "
               "<engine>.<size>.k; engine liggghts or lammps, size smoke or ref)"},
    {"[dem] three prefixes",
     "[dem]\nlammps.ref.x.lx = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] lammps.ref.x.lx: unknown prefix (expected k, <engine>.k, <size>.k or "
               "<engine>.<size>.k; engine liggghts or lammps, size smoke or ref)"},
    {"[dem] number",
     "[dem]\nlammps.ref.lx = 2x",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] lammps.ref.lx: expected a number, got '2x'"},
    {"[dem] hex",
     "[dem]\ndt = 0x1p-10",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] dt: expected a number, got '0x1p-10'"},
    {"[dem] inf",
     "[dem]\ndt = inf",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] dt: expected a number, got 'inf'"},
    {"[dem] nan",
     "[dem]\ndt = nan",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] dt: expected a number, got 'nan'"},
    {"[dem] overflow",
     "[dem]\ndt = 1e999",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] dt: expected a number, got '1e999'"},
    {"[dem] empty", "[dem]\ndt =", {NULL}, EKM_EINPUT, FILE_NAME ":31: [dem] dt: expected a number, got ''"},
    {"[dem] integer",
     "[dem]\nseed = 1.5",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] seed: expected an integer, got '1.5'"},
    {"[dem] flag",
     "[dem]\nref.require_steady = yes",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] ref.require_steady: expected 0 or 1, got 'yes'"},
    {"[dem] list",
     "[dem]\nref.angles = 22,24",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] ref.angles: expected numbers separated by blanks, got '22,24'"},
    {"[dem] range",
     "[dem]\nlammps.ref.poisson = 0.5",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] lammps.ref.poisson: expected a Poisson ratio in (-1, 0.5), got '0.5'"},
    {"[dem] range dt",
     "[dem]\ndt = 0",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] dt: expected a time step > 0 [s], got '0'"},
    {"[dem] range restitution",
     "[dem]\nrestitution = 1.2",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] restitution: expected a restitution in (0, 1], got '1.2'"},
    {"[dem] range timeout",
     "[dem]\ntimeout = 0",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] timeout: expected a timeout >= 1 [s], got '0'"},
    {"[dem] range spread",
     "[dem]\nspread = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] spread: expected a size spread in [0, 1), got '1'"},
    {"[dem] range settle_max",
     "[dem]\nref.settle_max = 0",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [dem] ref.settle_max: expected a time > 0 [s], got '0'"},
    {"[dem] range friction --set",
     NULL,
     {"dem.friction=-0.1", NULL},
     EKM_EINPUT,
     "--set dem.friction: [dem] friction: expected a friction coefficient >= 0, got '-0.1'"},
    {"[dem] list --set",
     NULL,
     {"dem.phis=0.5 x", NULL},
     EKM_EINPUT,
     "--set dem.phis: [dem] phis: expected numbers separated by blanks, got '0.5 x'"},
    {"[compare] fields",
     "[compare]\nfields = phi,,T",
     {NULL},
     EKM_EINPUT,
     FILE_NAME
     ":31: [compare] fields: expected field names separated by commas (e.g. phi,vx,T), got 'phi,,T'"},
    {"[compare] fields with blanks",
     "[compare]\nfields = phi, T",
     {NULL},
     EKM_EINPUT,
     FILE_NAME
     ":31: [compare] fields: expected field names separated by commas (e.g. phi,vx,T), got 'phi, T'"},
    {"[compare] unknown field",
     "[compare]\nfields = phi,bogus",
     {NULL},
     EKM_EINPUT,
     FILE_NAME
     ":31: [compare] fields: expected field names of the schema (common/schema.c), not 'bogus', got "
     "'phi,bogus'"},
    {"[compare] unknown field --set",
     NULL,
     {"compare.fields=phi,bogus", NULL},
     EKM_EINPUT,
     "--set compare.fields: [compare] fields: expected field names of the schema (common/schema.c), not "
     "'bogus', "
     "got 'phi,bogus'"},
    {"[compare] cg_options: a bad value",
     "[compare]\nref.cg_options = --types 1 --width -1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [compare] ref.cg_options: --width: expected a positive width, got '-1'"},
    {"[compare] cg_options: an unknown option",
     NULL,
     {"compare.cg_options=--stress c_sa --bogus", NULL},
     EKM_EINPUT,
     "--set compare.cg_options: [compare] cg_options: --bogus: unknown option (expected options of "
     "`ekmcompare cg`)"},
    {"[compare] cg_options: an option the campaign adds",
     "[compare]\ncg_options = --steady -o cg.h5",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [compare] cg_options: -o: not here (the campaign adds the dumps, -o, --csv, --dt and "
               "--quiet)"},
    {"[compare] cg_options: a value missing",
     "[compare]\ncg_options = --steady --kernel",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [compare] cg_options: --kernel: expected a value"},
    {"[compare] enum",
     "[compare]\nlammps.ekm_time = first",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [compare] lammps.ekm_time: expected one of last interp, got 'first'"},
    {"[compare] shift",
     "[compare]\nshift = -",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [compare] shift: expected a number, got '-'"},
    {"[compare] unknown key",
     "[compare]\nsmoke.window = 1",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [compare] smoke.window: unknown key"},
    {"[campaign] has no keys",
     "[campaign]\nengines = lammps",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [campaign] engines: unknown key"},
    {"[figures] has no keys",
     "[figures]\nformat = pdf",
     {NULL},
     EKM_EINPUT,
     FILE_NAME ":31: [figures] format: unknown key"},
};

static void check_errors(const error_case *cases, size_t n)
{
    int failed = 0;
    for (size_t i = 0; i < n; i++) {
        const error_case *c = &cases[i];
        write_scenario(c->edit);
        size_t n_sets = 0;
        while (c->sets[n_sets])
            n_sets++;
        ekm_scenario sc;
        ekm_error err = {0};
        ekm_status st = ekm_scenario_load(&sc, FILE_NAME, c->sets, n_sets, &err);
        ekm_scenario_free(&sc);
        if (st != c->status || strcmp(err.message, c->message) != 0) {
            print_error("%s: status %d (want %d)\n  got  '%s'\n  want '%s'\n", c->what, (int)st,
                        (int)c->status, st == EKM_OK ? "" : err.message, c->message);
            failed = 1;
        }
    }
    assert_false(failed);
}

static void test_ekm_errors(void **state)
{
    (void)state;
    check_errors(EKM_ERRORS, sizeof EKM_ERRORS / sizeof EKM_ERRORS[0]);
}

static void test_tool_errors(void **state)
{
    (void)state;
    check_errors(TOOL_ERRORS, sizeof TOOL_ERRORS / sizeof TOOL_ERRORS[0]);
}

static void test_unreadable_and_long_line(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, "no_such_dir/none.ini", NULL, 0, &err), EKM_EIO);
    ekm_scenario_free(&sc);
    assert_string_equal(err.message,
                        "no_such_dir/none.ini: cannot open scenario file: No such file or directory");
    char line[400];
    memset(line, 'x', sizeof line - 1);
    line[sizeof line - 1] = '\0';
    memcpy(line, "+name:description = ", 20);
    write_scenario(line);
    assert_int_equal(ekm_scenario_load(&sc, FILE_NAME, NULL, 0, &err), EKM_EINPUT);
    ekm_scenario_free(&sc);
    assert_string_equal(err.message, FILE_NAME ":3: line longer than 198 characters");
}

/* The syntax that stays allowed: --set overrides a file key (the last of
 * two --set wins), indentation, CRLF, a byte-order mark, UTF-8 values,
 * exactly the largest number of frames; and what the text API reads. */
static void test_syntax_allowed(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_error err = {0};
    write_scenario("");
    const char *sets[] = {"material.rho_p=2600", "domain.cells=+40", "domain.cells=50"};
    assert_int_equal(ekm_scenario_load(&sc, FILE_NAME, sets, 3, &err), EKM_OK);
    assert_true(sc.material.rho_p == 2600.0);
    assert_int_equal(sc.cells, 50);
    const ekm_entry *e = ekm_scenario_entry_find(sc.entries, sc.n_entries, "material.rho_p");
    assert_non_null(e);
    assert_int_equal(e->origin, EKM_FROM_SET);
    assert_string_equal(e->value, "2600");
    ekm_scenario_free(&sc);

    /* indented keys and headers, CRLF line ends, a BOM, a UTF-8 value */
    char text[8192] = "\xEF\xBB\xBF";
    size_t used = 3;
    for (const char *p = BASE, *nl; (nl = strchr(p, '\n')) != NULL; p = nl + 1)
        used += (size_t)snprintf(text + used, sizeof text - used, "  %.*s\r\n", (int)(nl - p), p);
    strcat(text, "  [numerics] ; a comment\r\n\tcfl = 0.3 ; a comment\r\n[scenario2]");
    /* the last line: an unknown section, to see that the rest was read */
    ekm_scenario_text t = {.name = "mem.ini", .text = text, .size = strlen(text)};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, NULL, 0, &err), EKM_EINPUT);
    assert_string_equal(err.message,
                        "mem.ini:32: [scenario2]: unknown section (the sections are scenario material "
                        "model domain gravity initial bottom top left right run numerics hypo dem compare "
                        "campaign figures)");
    ekm_scenario_free(&sc);
    t.size = strlen(text) - strlen("[scenario2]");
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, NULL, NULL, 0, &err), EKM_OK);
    assert_true(sc.numerics.cfl == 0.3);
    assert_int_equal(sc.cells, 60);
    assert_string_equal(sc.source, "mem.ini");
    ekm_scenario_free(&sc);

    /* a key before the first section; a NUL in the text */
    ekm_scenario_text k = {.name = "k.ini", .text = "rho_p = 1\n[material]\n", .size = 21};
    assert_int_equal(ekm_scenario_load_texts(&sc, &k, NULL, NULL, 0, &err), EKM_EINPUT);
    assert_string_equal(err.message, "k.ini:1: 'rho_p = 1': a key before the first [section]");
    ekm_scenario_free(&sc);
    ekm_scenario_text z = {.name = "z.ini",
                           .text = "[material]\nrho_p = 16\0"
                                   "00\n",
                           .size = 23};
    assert_int_equal(ekm_scenario_load_texts(&sc, &z, NULL, NULL, 0, &err), EKM_EINPUT);
    assert_string_equal(err.message, "z.ini:2:11: a NUL byte: expected text (no control characters but tab)");
    ekm_scenario_free(&sc);

    /* a name in UTF-8; 99999 frames */
    write_scenario("=name:name = caf\xc3\xa9\n+t_end:output_dt = 5.0001e-5");
    assert_int_equal(ekm_scenario_load(&sc, FILE_NAME, NULL, 0, &err), EKM_OK);
    assert_string_equal(sc.name, "caf\xc3\xa9");
    assert_true(sc.t_end / sc.output_dt <= EKM_SCENARIO_MAX_FRAMES - 1);
    ekm_scenario_free(&sc);
    /* not given: output_dt = t_end / 100, steady_window = 10 output_dt */
    write_scenario("");
    assert_int_equal(ekm_scenario_load(&sc, FILE_NAME, NULL, 0, &err), EKM_OK);
    assert_true(sc.output_dt == 0.05 && sc.steady_window == 0.5);
    ekm_scenario_free(&sc);
}

/* --material's text: its own lines, its own duplicates. */
static void test_material_text(void **state)
{
    (void)state;
    char scen[4096];
    const char *m0 = strstr(BASE, "[material]"), *m1 = strstr(BASE, "[domain]");
    snprintf(scen, sizeof scen, "%.*s%s", (int)(m0 - BASE), BASE, m1);
    char mat[1024];
    snprintf(mat, sizeof mat, "; fitted\n%.*s", (int)(m1 - m0), m0);
    ekm_scenario_text t = {.name = "s.ini", .text = scen, .size = strlen(scen)};
    ekm_scenario_text m = {.name = "fit.ini", .text = mat, .size = strlen(mat)};
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, &m, NULL, 0, &err), EKM_OK);
    const ekm_entry *e = ekm_scenario_entry_find(sc.entries, sc.n_entries, "material.rho_p");
    assert_non_null(e);
    assert_int_equal(e->origin, EKM_FROM_MATERIAL);
    assert_int_equal(e->line, 3);
    assert_string_equal(sc.material_source, "fit.ini");
    ekm_scenario_free(&sc);
    strcat(mat, "nu = 2\n");
    m.size = strlen(mat);
    assert_int_equal(ekm_scenario_load_texts(&sc, &t, &m, NULL, 0, &err), EKM_EINPUT);
    assert_string_equal(err.message, "fit.ini:15: [material] nu: duplicate key (first at line 11)");
    ekm_scenario_free(&sc);
}

/* A scenario with a valid [dem] key loads for ekm run (the values are not ekm's). */
static void test_ekm_run_reads_tool_sections(void **state)
{
    (void)state;
    write_scenario("[dem]\nlammps.ref.lx = 20\n[compare]\ncg_options = --types 1\n[campaign]\n[figures]");
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, FILE_NAME, NULL, 0, &err), EKM_OK);
    assert_int_equal(sc.n_tool_entries, 2);
    assert_string_equal(sc.tool_entries[0].name, "dem.lammps.ref.lx");
    assert_int_equal(sc.tool_entries[0].line, 31);
    assert_string_equal(sc.tool_entries[1].name, "compare.cg_options");
    assert_string_equal(sc.tool_entries[1].value, "--types 1");
    /* ekm's entries (the output attributes) are only ekm's keys */
    for (size_t i = 0; i < sc.n_entries; i++)
        assert_null(strstr(sc.entries[i].name, "dem."));
    ekm_scenario_free(&sc);
}

/* --- resolving ------------------------------------------------------------------ */

typedef struct {
    ekm_scenario sc;
    ekm_resolved r;
    ekm_error err;
} resolved;

static ekm_status resolve_file(resolved *x, const char *path, const char *engine, const char *size,
                               const char *const *sets, size_t n_sets)
{
    memset(x, 0, sizeof *x);
    ekm_status st = ekm_scenario_load(&x->sc, path, sets, n_sets, &x->err);
    if (st == EKM_OK)
        st = ekm_resolve(&x->sc, engine, size, &x->r, &x->err);
    return st;
}

static void resolved_free(resolved *x)
{
    ekm_resolve_free(&x->r);
    ekm_scenario_free(&x->sc);
}

static void assert_key(const resolved *x, const char *name, const char *value, const char *from,
                       const char *as)
{
    const ekm_resolve_key *k = ekm_resolve_find(&x->r, name);
    if (!k)
        fail_msg("%s: absent", name);
    if (strcmp(k->value, value) != 0 || strcmp(k->from, from) != 0 || strcmp(k->as, as) != 0)
        fail_msg("%s: got value '%s' from '%s' as '%s', want '%s' from '%s' as '%s'", name, k->value, k->from,
                 k->as, value, from, as);
}

/* All four variants and the plain key: the most specific one wins. */
static const char LOOKUP[] = "[dem]\n"
                             "lx = 1\n"            /* 31 */
                             "lammps.lx = 2\n"     /* 32 */
                             "ref.lx = 3\n"        /* 33 */
                             "lammps.ref.lx = 4\n" /* 34 */
                             "ly = 5\n"            /* 35 */
                             "lammps.ly = 6\n"     /* 36 */
                             "ref.ly = 7\n"        /* 37 */
                             "dt = 8\n"            /* 38 */
                             "liggghts.dt = 9\n"   /* 39 */
                             "restitution = 0.8\n" /* 40 */
                             "[compare]\n"
                             "smoke.cg_options = --steady\n" /* 42 */
                             "lammps.smoke.shift = 0.5\n";   /* 43 */

static void test_lookup_rule(void **state)
{
    (void)state;
    write_scenario(LOOKUP);
    resolved x;
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "ref", NULL, 0), EKM_OK);
    assert_key(&x, "dem.lx", "4", FILE_NAME ":34", "lammps.ref.lx");
    assert_key(&x, "dem.ly", "7", FILE_NAME ":37", "ref.ly");
    assert_key(&x, "dem.dt", "8", FILE_NAME ":38", "");
    assert_key(&x, "dem.seed", "15485863", "default", "");
    assert_key(&x, "dem.restitution_input", "0.8", "default", "");
    assert_key(&x, "dem.t_end", "5", "default", "");
    assert_key(&x, "compare.ekm_time", "interp", "default", "");
    assert_key(&x, "compare.shift", "0", "default", "");
    assert_null(ekm_resolve_find(&x.r, "compare.cg_options"));
    assert_null(ekm_resolve_find(&x.r, "dem.diameter"));
    resolved_free(&x);

    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "smoke", NULL, 0), EKM_OK);
    assert_key(&x, "dem.lx", "2", FILE_NAME ":32", "lammps.lx");
    assert_key(&x, "dem.ly", "6", FILE_NAME ":36", "lammps.ly");
    assert_key(&x, "compare.cg_options", "--steady", FILE_NAME ":42", "smoke.cg_options");
    assert_key(&x, "compare.shift", "0.5", FILE_NAME ":43", "lammps.smoke.shift");
    resolved_free(&x);

    assert_int_equal(resolve_file(&x, FILE_NAME, "liggghts", "ref", NULL, 0), EKM_OK);
    assert_key(&x, "dem.lx", "3", FILE_NAME ":33", "ref.lx");
    assert_key(&x, "dem.dt", "9", FILE_NAME ":39", "liggghts.dt");
    resolved_free(&x);

    /* without engine and size: the plain keys only */
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, NULL, 0), EKM_OK);
    assert_key(&x, "dem.lx", "1", FILE_NAME ":31", "");
    assert_key(&x, "dem.dt", "8", FILE_NAME ":38", "");
    assert_null(ekm_resolve_find(&x.r, "compare.cg_options"));
    resolved_free(&x);

    /* a --set of the plain key beats every variant; of a variant, that variant */
    const char *plain[] = {"dem.lx=30", "dem.ref.ly=70", "dem.restitution_input=0.7"};
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "ref", plain, 3), EKM_OK);
    assert_key(&x, "dem.lx", "30", "--set", "");
    assert_key(&x, "dem.ly", "70", "--set", "ref.ly");
    assert_key(&x, "dem.restitution_input", "0.7", "--set", "");
    resolved_free(&x);
}

/* [dem] settle_max: by default t_end (no settling), else at least t_end, an
 * error naming where it was given. */
static void test_settle_max(void **state)
{
    (void)state;
    resolved x;
    write_scenario("[dem]\nt_end = 2\nref.settle_max = 3\nsmoke.settle_max = 1.5");
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "ref", NULL, 0), EKM_OK);
    assert_key(&x, "dem.settle_max", "3", FILE_NAME ":32", "ref.settle_max");
    resolved_free(&x);
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, NULL, 0), EKM_OK);
    assert_key(&x, "dem.settle_max", "2", "default", "");
    resolved_free(&x);
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "smoke", NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message,
                        FILE_NAME ":33: [dem] smoke.settle_max: expected a time >= [dem] t_end "
                                  "= 2 s (" FILE_NAME ":31), got '1.5'");
    resolved_free(&x);
    /* t_end raised by --set past the file's settle_max; the default t_end */
    const char *later[] = {"dem.t_end=4"};
    assert_int_equal(resolve_file(&x, FILE_NAME, "liggghts", "ref", later, 1), EKM_EINPUT);
    assert_string_equal(x.err.message, FILE_NAME ":32: [dem] ref.settle_max: expected a time >= [dem] t_end "
                                                 "= 4 s (--set), got '3'");
    resolved_free(&x);
    write_scenario("[dem]\nsettle_max = 4");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message,
                        FILE_NAME ":31: [dem] settle_max: expected a time >= [dem] t_end = 5 s "
                                  "(the default: [run] t_end), got '4'");
    resolved_free(&x);
    /* without a [dem] t_end nor settle_max: the default t_end, unchanged */
    write_scenario("[dem]\ndt = 1e-5");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, NULL, 0), EKM_OK);
    assert_key(&x, "dem.settle_max", "5", "default", "");
    resolved_free(&x);
}

/* ekm's keys: as written with their line, --set, or the default. */
static void test_ekm_keys(void **state)
{
    (void)state;
    write_scenario("[numerics]\ncfl = 0.3");
    resolved x;
    const char *sets[] = {"gravity.angle=30"};
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, sets, 1), EKM_OK);
    assert_key(&x, "material.eta0", "3.55e-4", FILE_NAME ":8", "");
    assert_key(&x, "numerics.cfl", "0.3", FILE_NAME ":31", "");
    assert_key(&x, "gravity.angle", "30", "--set", "");
    assert_key(&x, "numerics.dt_min", "1e-12", "default", "");
    assert_key(&x, "run.output_dt", "0.05", "default", "");
    assert_key(&x, "model.variant", "full", "default", "");
    assert_key(&x, "numerics.convection", "upwind", "default", "");
    assert_key(&x, "numerics.normal_coupling", "implicit", "default", "");
    assert_key(&x, "bottom.velocity", "0", "default", "");
    /* no number to show, or a key of another boundary type: absent */
    assert_null(ekm_resolve_find(&x.r, "numerics.dt_max"));
    assert_null(ekm_resolve_find(&x.r, "initial.layer_height"));
    assert_null(ekm_resolve_find(&x.r, "bottom.phi"));
    assert_null(ekm_resolve_find(&x.r, "top.velocity"));
    /* no [dem]: no dem keys, one point without variables */
    assert_null(ekm_resolve_find(&x.r, "dem.seed"));
    assert_int_equal(x.r.n_points, 1);
    assert_string_equal(x.r.points[0].tag, "");
    assert_int_equal(x.r.points[0].n_vars, 0);
    assert_int_equal(x.r.points[0].n_sets, 0);
    resolved_free(&x);
}

static const char *src_path(const char *rel, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", EKM_SOURCE_DIR, rel);
    return buf;
}

static void test_chute_points(void **state)
{
    (void)state;
    char path[1024];
    resolved x;
    assert_int_equal(
        resolve_file(&x, src_path("scenarios/chute.ini", path, sizeof path), "lammps", "ref", NULL, 0),
        EKM_OK);
    assert_int_equal(x.r.n_points, 3);
    const char *angle[] = {"22", "24", "26"};
    for (size_t i = 0; i < 3; i++) {
        const ekm_resolve_point *p = &x.r.points[i];
        char tag[32], set[32];
        snprintf(tag, sizeof tag, "theta%s", angle[i]);
        snprintf(set, sizeof set, "gravity.angle=%s", angle[i]);
        assert_string_equal(p->tag, tag);
        assert_int_equal(p->n_vars, 1);
        assert_string_equal(p->var_name[0], "theta");
        assert_string_equal(p->var_value[0], angle[i]);
        assert_int_equal(p->n_sets, 1);
        assert_string_equal(p->set[0], set);
    }
    const ekm_resolve_key *k = ekm_resolve_find(&x.r, "dem.restitution_input");
    assert_non_null(k);
    assert_string_equal(k->value, "0.724");
    assert_string_equal(k->as, "lammps.restitution_input");
    assert_non_null(strstr(k->from, "scenarios/chute.ini:"));
    resolved_free(&x);
}

static void test_chute_smoke_point(void **state)
{
    (void)state;
    char path[1024];
    resolved x;
    assert_int_equal(
        resolve_file(&x, src_path("scenarios/chute.ini", path, sizeof path), "liggghts", "smoke", NULL, 0),
        EKM_OK);
    assert_int_equal(x.r.n_points, 1);
    assert_string_equal(x.r.points[0].tag, "");
    assert_string_equal(x.r.points[0].var_value[0], "24");
    assert_string_equal(x.r.points[0].set[0], "gravity.angle=24");
    const ekm_resolve_key *k = ekm_resolve_find(&x.r, "dem.angles");
    assert_non_null(k);
    assert_string_equal(k->value, "24");
    assert_string_equal(k->from, "default");
    /* --point: the one point, or an error listing the points */
    assert_int_equal(ekm_resolve_keep_point(&x.r, "", &x.err), EKM_OK);
    assert_int_equal(ekm_resolve_keep_point(&x.r, "theta24", &x.err), EKM_EINPUT);
    assert_string_equal(x.err.message, "--point theta24: unknown point (the points are: \"\")");
    resolved_free(&x);
}

static void test_simple_shear_points(void **state)
{
    (void)state;
    char path[1024];
    resolved x;
    assert_int_equal(
        resolve_file(&x, src_path("scenarios/simple_shear.ini", path, sizeof path), "lammps", "ref", NULL, 0),
        EKM_OK);
    assert_int_equal(x.r.n_points, 21);
    const char *phi[] = {"0.45", "0.50", "0.53", "0.56", "0.58", "0.60", "0.62"}, *rate[] = {"5", "10", "20"},
               *wall[] = {"0.05", "0.1", "0.2"};
    for (size_t i = 0; i < 21; i++) {
        const ekm_resolve_point *p = &x.r.points[i];
        char want[96];
        snprintf(want, sizeof want, "phi%s-rate%s", phi[i / 3], rate[i % 3]);
        assert_string_equal(p->tag, want);
        assert_int_equal(p->n_vars, 2);
        assert_string_equal(p->var_name[0], "phi");
        assert_string_equal(p->var_value[0], phi[i / 3]);
        assert_string_equal(p->var_name[1], "rate");
        assert_string_equal(p->var_value[1], rate[i % 3]);
        assert_int_equal(p->n_sets, 3);
        snprintf(want, sizeof want, "initial.phi=%s", phi[i / 3]);
        assert_string_equal(p->set[0], want);
        snprintf(want, sizeof want, "top.velocity=%s", wall[i % 3]);
        assert_string_equal(p->set[1], want);
        snprintf(want, sizeof want, "bottom.velocity=-%s", wall[i % 3]);
        assert_string_equal(p->set[2], want);
    }
    assert_int_equal(ekm_resolve_keep_point(&x.r, "phi0.5-rate10", &x.err), EKM_EINPUT);
    assert_string_equal(
        x.err.message,
        "--point phi0.5-rate10: unknown point (the points are: phi0.45-rate5 phi0.45-rate10 "
        "phi0.45-rate20 phi0.50-rate5 phi0.50-rate10 phi0.50-rate20 phi0.53-rate5 phi0.53-rate10 "
        "phi0.53-rate20 phi0.56-rate5 phi0.56-rate10 phi0.56-rate20 phi0.58-rate5 phi0.58-rate10 "
        "phi0.58-rate20 phi0.60-rate5 phi0.60-rate10 phi0.60-rate20 phi0.62-rate5 phi0.62-rate10 "
        "phi0.62-rate20)");
    assert_int_equal(ekm_resolve_keep_point(&x.r, "phi0.53-rate20", &x.err), EKM_OK);
    assert_int_equal(x.r.n_points, 1);
    assert_string_equal(x.r.points[0].set[1], "top.velocity=0.2");
    resolved_free(&x);

    /* smoke: the single point of [initial] phi and the walls' rate 0.2 m/s / 0.02 m */
    assert_int_equal(resolve_file(&x, src_path("scenarios/simple_shear.ini", path, sizeof path), "lammps",
                                  "smoke", NULL, 0),
                     EKM_OK);
    assert_int_equal(x.r.n_points, 1);
    assert_string_equal(x.r.points[0].tag, "");
    assert_string_equal(x.r.points[0].var_value[0], "0.55");
    assert_string_equal(x.r.points[0].var_value[1], "10");
    assert_string_equal(x.r.points[0].set[1], "top.velocity=0.1");
    assert_string_equal(x.r.points[0].set[2], "bottom.velocity=-0.1");
    assert_key(&x, "dem.phis", "0.55", "default", "");
    assert_key(&x, "dem.rates", "10", "default", "");
    resolved_free(&x);
}

/* The pressure x rate sweep of simple_shear_p: tags p<P>-rate<R> from the
 * values as written, vars pressure rate dump_every, the EKM's top wall held
 * at the point's pressure and moving at the point's shear rate (bc.h), the
 * bottom wall at -R L/2. */
static void test_simple_shear_p_points(void **state)
{
    (void)state;
    char path[1024];
    resolved x;
    assert_int_equal(resolve_file(&x, src_path("scenarios/simple_shear_p.ini", path, sizeof path), "lammps",
                                  "ref", NULL, 0),
                     EKM_OK);
    assert_int_equal(x.r.n_points, 15);
    const char *pres[] = {"10", "100", "1000"}, *rate[] = {"0.3", "1", "3", "10", "30"},
               *wall[] = {"0.003", "0.01", "0.03", "0.1", "0.3"};
    /* dump_strain 0.1 / (rate 1e-5) + 0.5, truncated: 33333.8, 10000.5, 3333.8, 1000.5, 333.8 */
    const char *every[] = {"33333", "10000", "3333", "1000", "333"};
    for (size_t i = 0; i < 15; i++) {
        const ekm_resolve_point *p = &x.r.points[i];
        char want[96];
        snprintf(want, sizeof want, "p%s-rate%s", pres[i / 5], rate[i % 5]);
        assert_string_equal(p->tag, want);
        assert_int_equal(p->n_vars, 3);
        assert_string_equal(p->var_name[0], "pressure");
        assert_string_equal(p->var_value[0], pres[i / 5]);
        assert_string_equal(p->var_name[1], "rate");
        assert_string_equal(p->var_value[1], rate[i % 5]);
        assert_string_equal(p->var_name[2], "dump_every");
        assert_string_equal(p->var_value[2], every[i % 5]);
        assert_int_equal(p->n_sets, 3);
        snprintf(want, sizeof want, "top.pressure=%s", pres[i / 5]);
        assert_string_equal(p->set[0], want);
        snprintf(want, sizeof want, "top.shear_rate=%s", rate[i % 5]);
        assert_string_equal(p->set[1], want);
        snprintf(want, sizeof want, "bottom.velocity=-%s", wall[i % 5]);
        assert_string_equal(p->set[2], want);
    }
    const ekm_resolve_key *k = ekm_resolve_find(&x.r, "dem.pressures");
    assert_non_null(k);
    assert_string_equal(k->value, "10 100 1000");
    assert_string_equal(k->as, "ref.pressures");
    k = ekm_resolve_find(&x.r, "dem.p_gain");
    assert_non_null(k);
    assert_string_equal(k->value, "0.25");
    resolved_free(&x);

    /* smoke: three pressures at the plain rate 10 */
    assert_int_equal(resolve_file(&x, src_path("scenarios/simple_shear_p.ini", path, sizeof path), "lammps",
                                  "smoke", NULL, 0),
                     EKM_OK);
    assert_int_equal(x.r.n_points, 3);
    assert_string_equal(x.r.points[2].tag, "p1000-rate10");
    assert_string_equal(x.r.points[2].var_value[2], "1000");
    resolved_free(&x);

    /* a single point (its tag ""), the default rate from the walls, the
     * floor of 1 frame step and a list written with other spellings */
    write_scenario("[dem]\npressures = 1e2\ndump_strain = 1e-9\ndt = 1e-5");
    const char *sets[] = {"top.type=wall", "top.velocity=0.1", "bottom.velocity=-0.1", "domain.length=0.02"};
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, sets, 4), EKM_OK);
    assert_int_equal(x.r.n_points, 1);
    assert_string_equal(x.r.points[0].tag, "");
    assert_string_equal(x.r.points[0].var_value[0], "1e2");
    assert_string_equal(x.r.points[0].var_value[1], "10");
    assert_string_equal(x.r.points[0].var_value[2], "1");
    assert_key(&x, "dem.rates", "10", "default", "");
    resolved_free(&x);
    write_scenario("[dem]\npressures = 50 5e1\nrates = 2.5\ndump_strain = 0.2\ndt = 2e-5");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, sets, 4), EKM_OK);
    assert_int_equal(x.r.n_points, 2);
    assert_string_equal(x.r.points[0].tag, "p50-rate2.5");
    assert_string_equal(x.r.points[1].tag, "p5e1-rate2.5");
    assert_string_equal(x.r.points[1].var_value[2], "4000");       /* 0.2 / (2.5 2e-5) */
    assert_string_equal(x.r.points[1].set[0], "top.pressure=5e1"); /* as written */
    assert_string_equal(x.r.points[1].set[1], "top.shear_rate=2.5");
    assert_string_equal(x.r.points[1].set[2], "bottom.velocity=-0.025");
    resolved_free(&x);
    /* without dump_strain: no per-point dump_every */
    write_scenario("[dem]\npressures = 50\nrates = 2 4");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, sets, 4), EKM_OK);
    assert_int_equal(x.r.points[1].n_vars, 2);
    assert_string_equal(x.r.points[1].tag, "p50-rate4");
    resolved_free(&x);
}

/* A rate that is not a round number: %.10g of (v_top - v_bot) / L and of R L / 2. */
static void test_rate_formatting(void **state)
{
    (void)state;
    write_scenario("[dem]\nstrain = 2\nphis = 0.5 0.52\nrates = 3 7.5");
    resolved x;
    const char *sets[] = {"top.type=wall", "top.velocity=0.1", "bottom.velocity=-0.0333",
                          "domain.length=0.07"};
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, sets, 4), EKM_OK);
    assert_int_equal(x.r.n_points, 4);
    assert_string_equal(x.r.points[1].tag, "phi0.5-rate7.5");
    assert_string_equal(x.r.points[1].set[1], "top.velocity=0.2625");
    assert_string_equal(x.r.points[1].set[2], "bottom.velocity=-0.2625");
    resolved_free(&x);
    /* the default rate: (0.1 + 0.0333) / 0.07 = 1.904285714..., and its
     * walls from the rate as written (%.10g, as the DEM deck's walls) */
    write_scenario("[dem]\nstrain = 2");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, sets, 4), EKM_OK);
    assert_key(&x, "dem.rates", "1.904285714", "default", "");
    assert_string_equal(x.r.points[0].set[1], "top.velocity=0.06664999999");
    resolved_free(&x);
}

static void test_sweep_errors(void **state)
{
    (void)state;
    write_scenario("[dem]\nref.angles = 22 24 22");
    resolved x;
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "ref", NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message, FILE_NAME
                        ":31: [dem] ref.angles: value '22' given twice (each point needs its own tag)");
    resolved_free(&x);
    /* a rate <= 0 (once formatted as bottom.velocity=--...) and a phi outside (0, phi_cp) */
    const char *walls[] = {"top.type=wall", "top.velocity=0.1", "bottom.velocity=-0.0333",
                           "domain.length=0.07"};
    write_scenario("[dem]\nstrain = 2\nphis = 0.5\nrates = 3 -4");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, walls, 4), EKM_EINPUT);
    assert_string_equal(x.err.message,
                        FILE_NAME ":33: [dem] rates: expected shear rates > 0 [1/s], got '-4'");
    resolved_free(&x);
    write_scenario("[dem]\nstrain = 2\nphis = 0.5 0.7\nrates = 3");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, walls, 4), EKM_EINPUT);
    assert_string_equal(x.err.message, FILE_NAME
                        ":32: [dem] phis: expected volume fractions in (0, phi_cp = 0.64), got '0.7'");
    resolved_free(&x);
    write_scenario("[dem]\nt_flow = 1\nsmoke.rates = 3");
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "ref", NULL, 0), EKM_EINPUT);
    assert_string_equal(
        x.err.message,
        FILE_NAME ":32: [dem] smoke.rates: a key of the simple-shear sweep, but [dem] t_flow is one "
                  "of the inclined-flow sweep: expected the keys of one sweep only (inclined flow: t_settle "
                  "t_flow angles; simple shear: strain rates, and phis or pressures)");
    resolved_free(&x);
    /* the two shear sweeps' lists together, in any variants */
    write_scenario("[dem]\nstrain = 2\nsmoke.pressures = 10 100\nref.phis = 0.5");
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "smoke", NULL, 0), EKM_EINPUT);
    assert_string_equal(
        x.err.message,
        FILE_NAME ":33: [dem] ref.phis: a list of the phi x rate sweep, but [dem] smoke.pressures is "
                  "one of the pressure x rate sweep: expected phis (shear at fixed volume) or pressures "
                  "(shear at fixed pressure), not both");
    resolved_free(&x);
    write_scenario("[dem]\npressures = 10\nt_settle = 1");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, NULL, 0), EKM_EINPUT);
    assert_string_equal(
        x.err.message,
        FILE_NAME ":32: [dem] t_settle: a key of the inclined-flow sweep, but [dem] pressures is one "
                  "of the simple-shear sweep: expected the keys of one sweep only (inclined flow: t_settle "
                  "t_flow angles; simple shear: strain rates, and phis or pressures)");
    resolved_free(&x);
    /* a pressure sweep with no list at this size */
    write_scenario("[dem]\nref.pressures = 10 100\nrates = 1");
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "smoke", NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message,
                        FILE_NAME ": [dem] pressures: missing for this engine and size (only other "
                                  "variants are given; a pressure x rate sweep needs its list of "
                                  "normal stresses)");
    resolved_free(&x);
    /* dump_strain: needs dt, and rates > 0 */
    write_scenario("[dem]\npressures = 10\nrates = 1\ndump_strain = 0.1");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message, FILE_NAME
                        ":33: [dem] dump_strain: needs [dem] dt (dump_every = dump_strain / (rate dt))");
    resolved_free(&x);
    write_scenario("[dem]\npressures = 10 -5\nrates = 1");
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, NULL, NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message,
                        FILE_NAME ":31: [dem] pressures: expected normal stresses > 0 [Pa], got '-5'");
    resolved_free(&x);
    /* a rate of 0 is refused by the sweep's range check first */
    write_scenario("[dem]\npressures = 10\nref.rates = 1 0\ndump_strain = 0.1\ndt = 1e-5");
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "ref", NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message,
                        FILE_NAME ":32: [dem] ref.rates: expected shear rates > 0 [1/s], got '0'");
    resolved_free(&x);
    write_scenario("[dem]\npressures = 10\nref.rates = 1\ndump_strain = 0\ndt = 1e-5");
    assert_int_equal(resolve_file(&x, FILE_NAME, "lammps", "ref", NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message,
                        FILE_NAME ":33: [dem] dump_strain: expected dump_strain, dt and every rate > 0 "
                                  "(got dump_strain 0, dt 1e-5, rate 1 of [dem] ref.rates)");
    resolved_free(&x);
    write_scenario("");
    assert_int_equal(resolve_file(&x, FILE_NAME, "spring", NULL, NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message, "--engine spring: unknown engine (expected liggghts or lammps)");
    resolved_free(&x);
    assert_int_equal(resolve_file(&x, FILE_NAME, NULL, "huge", NULL, 0), EKM_EINPUT);
    assert_string_equal(x.err.message, "--size huge: unknown size (expected smoke or ref)");
    resolved_free(&x);
}

/* Every shipped scenario resolves for both engines and sizes. */
static void test_shipped_scenarios(void **state)
{
    (void)state;
    const char *names[] = {"chute",          "cooling",
                           "filling",        "hypoplastic_cycle",
                           "shear_cell",     "simple_shear",
                           "simple_shear_p", "thesis_column_incline",
                           "thesis_filling", "thesis_kinetic_flow",
                           "tilting_layer"};
    const char *engines[] = {"liggghts", "lammps"}, *sizes[] = {"smoke", "ref"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        for (size_t e = 0; e < 2; e++)
            for (size_t z = 0; z < 2; z++) {
                char rel[128], path[1024];
                snprintf(rel, sizeof rel, "scenarios/%s.ini", names[i]);
                resolved x;
                ekm_status st =
                    resolve_file(&x, src_path(rel, path, sizeof path), engines[e], sizes[z], NULL, 0);
                if (st != EKM_OK)
                    fail_msg("%s %s %s: %s", names[i], engines[e], sizes[z], x.err.message);
                assert_true(x.r.n_points >= 1);
                assert_non_null(ekm_resolve_find(&x.r, "run.t_end"));
                resolved_free(&x);
            }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ekm_errors),
        cmocka_unit_test(test_tool_errors),
        cmocka_unit_test(test_unreadable_and_long_line),
        cmocka_unit_test(test_syntax_allowed),
        cmocka_unit_test(test_material_text),
        cmocka_unit_test(test_ekm_run_reads_tool_sections),
        cmocka_unit_test(test_lookup_rule),
        cmocka_unit_test(test_settle_max),
        cmocka_unit_test(test_ekm_keys),
        cmocka_unit_test(test_chute_points),
        cmocka_unit_test(test_chute_smoke_point),
        cmocka_unit_test(test_simple_shear_points),
        cmocka_unit_test(test_simple_shear_p_points),
        cmocka_unit_test(test_rate_formatting),
        cmocka_unit_test(test_sweep_errors),
        cmocka_unit_test(test_shipped_scenarios),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
