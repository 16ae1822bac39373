/* main.c: the ekmcompare command line (cg, score, score2d, fit, steady and base subcommands). */
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ekm_version.h"
#include "cg_run.h"
#include "status.h"
#include "atomic.h"
#include "pile_base.h"
#include "fit_cli.h"
#include "h5.h"
#include "score.h"
#include "score2d.h"
#include "steadiness.h"

static const char usage_text[] =
    "usage: ekmcompare cg [options] DUMP... (-o OUT.h5 | --csv OUT.csv)\n"
    "       ekmcompare score --dem CG.h5 --ekm RUN.h5 [--fields phi,vx,T] [--support F] [--scalars L] [-o "
    "SCORE.json]\n"
    "       ekmcompare score2d --dem MAPS.h5 [--group G] --model RUN.h5 [--time T] [--fields L] [-o "
    "SCORE.json]\n"
    "       ekmcompare fit --rheology CG.h5 [CG.h5 ...] --params T0,phi_co,eta0,eps0,nu [--start FILE.ini]\n"
    "                      [--material M.ini] [--closure NAME] [--fields P,sxz,T] -o FIT.json [--ini "
    "FIT.ini]   "
    "(docs/compare.md)\n"
    "       ekmcompare fit --scenario CASES.json --params eta0,eps0 [--fields phi,vx,T,P,sxz]\n"
    "                      -o FIT.json [--ini FIT.ini]   (docs/compare.md)\n"
    "       ekmcompare steady MONITOR.txt [--column N] [--tol X]\n"
    "       ekmcompare base DUMP... (-o BASE.h5 | --csv BASE.csv) [--floor-type N] [--dx DX]\n"
    "       ekmcompare --help | --version\n"
    "\n"
    "cg: coarse-grain LAMMPS/LIGGGHTS dumps (text, gzip, binary) into slab profiles\n"
    "with standard errors (block averages). Options:\n"
    "  -o FILE              HDF5 output (written atomically)\n"
    "  --csv FILE           the same as CSV\n"
    "  --axis x|y|z         profile axis (default z)\n"
    "  --axes x,z           a 2D grid in x and z averaged over y: fields [nt][nz][nx] (--axes z: the\n"
    "                       1D profile, the default); --bins NX,NZ or --dz (both axes); --range: z\n"
    "  --ensemble           (with --axes x,z) every DUMP is an independent run: SE across the runs\n"
    "  --kernel K           gauss (default), lucy or bins (exact sphere-slab volumes)\n"
    "  --exact-kernel       evaluate gauss/lucy per particle instead of on a dz/16 sub-grid\n"
    "  --width W            kernel standard deviation [m] (default: mean diameter)\n"
    "  --bins N | --dz DZ   output grid (default dz = width/2)\n"
    "  --range LO:HI        grid extent [m] (default: the box; no wall reflection)\n"
    "  --rho-p RHO          material density [kg/m^3] (dumps without mass)\n"
    "  --dt DT              engine time step [s] (dumps without ITEM: TIME)\n"
    "  --from T --to T      select snapshots by time [s]\n"
    "  --steps A:B          select snapshots by step (inclusive)\n"
    "  --steady             find the start of the steady state (MSER-5) and use from there\n"
    "  --every K            one profile per K snapshots (time series)\n"
    "  --window DT          one profile per DT seconds (time series)\n"
    "  --temperature M      particle (default: fluctuations about V at the particle)\n"
    "                       or consistent (about the bin's V; adds the shear within the kernel)\n"
    "  --stress C           per-atom stress x volume columns (compute stress/atom, contact part):\n"
    "                       a prefix (c_s means c_s[1]..c_s[6]) or six names xx,yy,zz,xy,xz,yz\n"
    "  --pairs FILE         pair dump (dump local; repeat for several files): contact stress\n"
    "                       by line integrals along the branch vectors, matched by step\n"
    "  --pair-columns L     its columns: x1,y1,z1,x2,y2,z2,fx,fy,fz (positions) or\n"
    "                       id1,id2,fx,fy,fz (atom ids; positions from the atom dump);\n"
    "                       f is the force on atom 1 by atom 2\n"
    "  --types L            only atoms of these types count (e.g. 1, or 1,3; column `type`):\n"
    "                       frozen wall grains are left out of every field\n"
    "  --expect-snapshots N the dumps hold exactly N complete snapshots (e.g. the frame count\n"
    "                       the DEM run recorded): fewer, more or one cut short is an error\n"
    "                       (exit 2) instead of a warning\n"
    "  --quiet              no notes on stderr\n"
    "\n"
    "score: interpolate ekm's output onto the DEM grid and times; per field the relative L2\n"
    "error and the noise-normalised error (docs/model-notes.md section 9); prints a markdown table.\n"
    "  --dem FILE --ekm FILE  inputs (ekmcompare cg output; ekm output)\n"
    "  --fields LIST        default: phi,vx,vz,T,P,sxz,szz (those in both files)\n"
    "  -o FILE              JSON output\n"
    "  --ekm-time last      compare with the EKM's last output (steady state)\n"
    "  --shift DZ           add DZ [m] to the DEM coordinate\n"
    "  --support F          common support: a point counts only where phi > F x the DEM's\n"
    "                       largest phi on both sides (default 0.1; 0: every point)\n"
    "  --scalars LIST       scalar observables with SEs: set names (chute, shear_cell,\n"
    "                       filling, simple_shear) or scalar names (docs/compare.md)\n"
    "  --dem-sha256 H --ekm-sha256 H  record the inputs' SHA-256 digests (sha256sum's 64 hex\n"
    "                       digits) in the JSON's \"inputs\" (the campaign's score_step.sh)\n"
    "\n"
    "score2d: a 2D ekm run's output frame (the last, or --time T [s]) against a sand pile's DEM map\n"
    "(a group of scripts/dem/pile_map.py's maps, e.g. results/sandpile/maps-ref.h5) or against the\n"
    "last window of an `ekmcompare cg --axes x,z` output; per field the relative L2 and\n"
    "noise-normalised errors over the common support and the map's interior (docs/compare.md\n"
    "\"Scoring a 2D pile\"). Stresses compression positive (ekm's and cg's negated).\n"
    "  --dem FILE [--group G]  the DEM: a map file and its group (/ENGINE/LAW/SOURCE), or a cg output\n"
    "  --model FILE         an ekm 2D run output, a second cg output, or (--model-group G2) a map\n"
    "  --fields LIST        of phi,P,sxx,szz,sxz (default: those both files have)\n"
    "  --support F          as score's (default 0.1)\n"
    "  --noise se|none      se (default): the inputs' SEs; none: no noise estimate (one DEM pile at\n"
    "                       rest, whose time SE is not its pile-to-pile scatter): noise-normalised null\n"
    "  -o FILE              JSON output (--dem-sha256 H --ekm-sha256 H: recorded as score's)\n"
    "  --quiet              no table on stdout\n"
    "\n"
    "base: the base pressure p(x) = -sum(fz of the floor grains in a bin)/(dx L_y) of a pile,\n"
    "time-averaged per run (each DUMP one run: an independent pile), with the SE across runs and\n"
    "from folding about the centre (docs/compare.md). Options: -o, --csv, --floor-type N (default\n"
    "2), --dx DX | --bins N (default 2 floor-grain diameters), --range LO:HI, --centre XC (default\n"
    "the middle), --from T --to T, --steps A:B, --dt DT, --last N (the last N selected snapshots\n"
    "of each run), --quiet.\n"
    "\n"
    "steady: is a run steady? The drift criterion on a monitor series (column N, default 2,\n"
    "of the lines not starting with #): the relative change of the mean from the quarter\n"
    "before the last to the last quarter, to 4 digits, against --tol (default 0.05).\n"
    "Prints one JSON line {\"steady\": true|false|null, \"drift\": x, \"tol\": x, \"samples\": n}\n"
    "(null below 8 samples).\n"
    "\n"
    "Exit status (docs/exit-codes.md): 0 success; 1 bad command line; 2 bad input file or\n"
    "data (score: also no point in common, a file of the wrong kind); 3 a file could not be\n"
    "opened, read or written (or an output would overwrite an input); 4 score: a number that\n"
    "cannot be computed; 5 internal error or out of memory; 128+N stopped by signal N\n"
    "(temporary files removed). Errors are one line: ekmcompare: file:line: message.\n";

static ekm_status usage_error(ekm_error *err, const char *fmt, const char *arg)
{
    return EKM_FAIL(err, EKM_EUSAGE, fmt, arg);
}

static ekm_status get_double(const char *opt, const char *s, double *out, ekm_error *err)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v))
        return EKM_FAIL(err, EKM_EUSAGE, "%s: expected a number, got '%s'", opt, s);
    *out = v;
    return EKM_OK;
}

static ekm_status get_size(const char *opt, const char *s, size_t *out, ekm_error *err)
{
    char *end;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || v < 1)
        return EKM_FAIL(err, EKM_EUSAGE, "%s: expected a positive integer, got '%s'", opt, s);
    *out = (size_t)v;
    return EKM_OK;
}

/* ARG(): v = the value of option a (argv[i + 1]) in an option loop over
 * argv[0..argc-1]; a missing value is a usage error that leaves the loop
 * (the break is the loop's: v is never used NULL). */
#define ARG()                                             \
    if (i + 1 >= argc) {                                  \
        rc = usage_error(err, "%s: expected a value", a); \
        break;                                            \
    }                                                     \
    v = argv[++i]

static ekm_status cmd_cg(int argc, char **argv, ekm_error *err)
{
    cg_run_opts o = cg_opts_default();
    o.log = stderr;
    cg_opts_names names;
    const char **inputs = calloc((size_t)argc, sizeof *inputs);
    const char **pairs = calloc((size_t)argc, sizeof *pairs);
    if (!inputs || !pairs) {
        free(inputs);
        free(pairs);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    size_t nin = 0, npairs = 0;
    ekm_status rc = EKM_OK;
    for (int i = 0; i < argc && !rc; i++) {
        const char *a = argv[i], *v = NULL;
        if (a[0] != '-' || !strcmp(a, "-")) {
            inputs[nin++] = a;
            continue;
        }
        /* the options' table and their values' checks: scenario/cg_keys.h */
        const ekm_cg_key *k = ekm_cg_keys_find(a);
        if (!k) {
            rc = usage_error(err, "cg: unknown option '%s' (see ekmcompare --help)", a);
            break;
        }
        if (k->takes_value) {
            ARG();
        }
        ekm_cg_value val;
        rc = ekm_cg_keys_parse(k, v, &val, err);
        if (!rc && k->id == EKM_CG_PAIRS)
            pairs[npairs++] = v;
        else if (!rc)
            cg_opts_apply(&o, &names, &val);
    }
    if (!rc && o.every && o.window > 0)
        rc = EKM_FAIL(err, EKM_EUSAGE, "cg: expected --every or --window, not both");
    if (!rc && o.axis2 < 0 && o.ensemble)
        rc = EKM_FAIL(err, EKM_EUSAGE,
                      "--ensemble: expected --axes x,z (the 1D profile has no ensemble mode)");
    if (!rc && o.axis2 < 0 && o.bins_x)
        rc = EKM_FAIL(err, EKM_EUSAGE, "--bins NX,NZ: expected --axes x,z (a 1D profile takes --bins N)");
    if (!rc) {
        o.inputs = inputs;
        o.ninputs = nin;
        o.pairs = pairs;
        o.npairs = npairs;
        if (npairs && !o.npaircols)
            rc = EKM_FAIL(err, EKM_EUSAGE, "--pairs: expected --pair-columns too");
        else if (!npairs && o.npaircols)
            rc = EKM_FAIL(err, EKM_EUSAGE, "--pair-columns: expected --pairs too");
        else
            rc = cg_run(&o, err);
    }
    free(inputs);
    free(pairs);
    return rc;
}

static ekm_status cmd_base(int argc, char **argv, ekm_error *err)
{
    cg_base_opts o = cg_base_opts_default();
    o.log = stderr;
    const char **inputs = calloc((size_t)argc + 1, sizeof *inputs);
    if (!inputs)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    size_t nin = 0;
    ekm_status rc = EKM_OK;
    for (int i = 0; i < argc && !rc; i++) {
        const char *a = argv[i], *v = NULL;
        if (a[0] != '-' || !strcmp(a, "-")) {
            inputs[nin++] = a;
            continue;
        }
        const ekm_cg_key *k = ekm_cg_keys_find(a);
        if (k && (k->id == EKM_CG_OUT || k->id == EKM_CG_CSV || k->id == EKM_CG_RANGE || k->id == EKM_CG_DT ||
                  k->id == EKM_CG_FROM || k->id == EKM_CG_TO || k->id == EKM_CG_STEPS)) {
            /* as `cg` reads them (scenario/cg_keys.h) */
            ARG();
            ekm_cg_value val;
            rc = ekm_cg_keys_parse(k, v, &val, err);
            if (!rc)
                cg_base_opts_apply(&o, &val);
        } else if (!strcmp(a, "--floor-type")) {
            ARG();
            char *end;
            long t = strtol(v, &end, 10);
            if (end == v || *end || t < 0 || t > 1000000)
                rc = usage_error(err, "--floor-type: expected an atom type (integer >= 0), got '%s'", v);
            o.floor_type = (int)t;
        } else if (!strcmp(a, "--dx")) {
            ARG();
            rc = get_double(a, v, &o.dx, err);
            if (!rc && !(o.dx > 0))
                rc = usage_error(err, "--dx: expected a positive bin width, got '%s'", v);
        } else if (!strcmp(a, "--bins")) {
            ARG();
            rc = get_size(a, v, &o.bins, err);
        } else if (!strcmp(a, "--centre")) {
            ARG();
            rc = get_double(a, v, &o.centre, err);
            o.have_centre = 1;
        } else if (!strcmp(a, "--last")) {
            ARG();
            rc = get_size(a, v, &o.last, err);
        } else if (!strcmp(a, "--quiet"))
            o.log = NULL;
        else
            rc = usage_error(err, "base: unknown option '%s' (see ekmcompare --help)", a);
    }
    if (!rc && o.dx > 0 && o.bins)
        rc = EKM_FAIL(err, EKM_EUSAGE, "base: expected --dx or --bins, not both");
    if (!rc) {
        o.inputs = inputs;
        o.ninputs = nin;
        rc = cg_base_run(&o, err);
    }
    free(inputs);
    return rc;
}

static ekm_status cmd_score(int argc, char **argv, ekm_error *err)
{
    cg_score_opts o = cg_score_opts_default();
    o.table = stdout;
    o.log = stderr;
    ekm_status rc = EKM_OK;
    for (int i = 0; i < argc && !rc; i++) {
        const char *a = argv[i], *v = NULL;
        if (!strcmp(a, "--dem")) {
            ARG();
            o.dem = v;
        } else if (!strcmp(a, "--ekm")) {
            ARG();
            o.ekm = v;
        } else if (!strcmp(a, "--fields")) {
            ARG();
            o.fields = v;
        } else if (!strcmp(a, "-o")) {
            ARG();
            o.json = v;
        } else if (!strcmp(a, "--shift")) {
            ARG();
            rc = get_double(a, v, &o.shift, err);
        } else if (!strcmp(a, "--ekm-time")) {
            ARG();
            if (!strcmp(v, "last"))
                o.ekm_last = 1;
            else if (!strcmp(v, "interp"))
                o.ekm_last = 0;
            else
                rc = usage_error(err, "--ekm-time: expected last or interp, got '%s'", v);
        } else if (!strcmp(a, "--support")) {
            ARG();
            rc = get_double(a, v, &o.support, err);
        } else if (!strcmp(a, "--scalars")) {
            ARG();
            o.scalars = v;
        } else if (!strcmp(a, "--dem-sha256")) {
            ARG();
            o.dem_sha256 = v;
        } else if (!strcmp(a, "--ekm-sha256")) {
            ARG();
            o.ekm_sha256 = v;
        } else if (!strcmp(a, "--quiet"))
            o.log = NULL;
        else
            rc = usage_error(err, "score: unknown argument '%s' (see ekmcompare --help)", a);
    }
    size_t nres;
    if (!rc)
        rc = cg_score(&o, NULL, &nres, err);
    return rc;
}

static ekm_status cmd_score2d(int argc, char **argv, ekm_error *err)
{
    cg_score2d_opts o = cg_score2d_opts_default();
    o.table = stdout;
    ekm_status rc = EKM_OK;
    for (int i = 0; i < argc && !rc; i++) {
        const char *a = argv[i], *v = NULL;
        if (!strcmp(a, "--dem")) {
            ARG();
            o.dem = v;
        } else if (!strcmp(a, "--group")) {
            ARG();
            o.group = v;
        } else if (!strcmp(a, "--model")) {
            ARG();
            o.model = v;
        } else if (!strcmp(a, "--model-group")) {
            ARG();
            o.model_group = v;
        } else if (!strcmp(a, "--time")) {
            ARG();
            rc = get_double(a, v, &o.time, err);
        } else if (!strcmp(a, "--fields")) {
            ARG();
            o.fields = v;
        } else if (!strcmp(a, "--support")) {
            ARG();
            rc = get_double(a, v, &o.support, err);
        } else if (!strcmp(a, "--quiet")) {
            o.table = NULL;
        } else if (!strcmp(a, "--noise")) {
            ARG();
            if (!strcmp(v, "se"))
                o.no_noise = 0;
            else if (!strcmp(v, "none"))
                o.no_noise = 1;
            else
                rc = usage_error(err, "score2d: --noise: expected se or none, got '%s'", v);
        } else if (!strcmp(a, "-o")) {
            ARG();
            o.json = v;
        } else if (!strcmp(a, "--dem-sha256")) {
            ARG();
            o.dem_sha256 = v;
        } else if (!strcmp(a, "--ekm-sha256")) {
            ARG();
            o.ekm_sha256 = v;
        } else
            rc = usage_error(err, "score2d: unknown argument '%s' (see ekmcompare --help)", a);
    }
    size_t nrows;
    if (!rc)
        rc = cg_score2d(&o, NULL, &nrows, err);
    return rc;
}

/* A number for JSON that reads back to the same double. */
static void print_exact(double v)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%.15g", v);
    if (strtod(buf, NULL) != v)
        snprintf(buf, sizeof buf, "%.17g", v);
    fputs(buf, stdout);
}

static ekm_status cmd_steady(int argc, char **argv, ekm_error *err)
{
    const char *path = NULL;
    int column = 2;
    double tol = 0.05;
    ekm_status rc = EKM_OK;
    for (int i = 0; i < argc && !rc; i++) {
        const char *a = argv[i], *v = NULL;
        if (!strcmp(a, "--column")) {
            ARG();
            size_t c;
            rc = get_size(a, v, &c, err);
            if (!rc && c > 64)
                rc = usage_error(err, "--column: expected at most 64, got '%s'", v);
            column = (int)c;
        } else if (!strcmp(a, "--tol")) {
            ARG();
            rc = get_double(a, v, &tol, err);
            if (!rc && !(tol >= 0))
                rc = usage_error(err, "--tol: expected a tolerance >= 0, got '%s'", v);
        } else if (a[0] == '-' && a[1])
            rc = usage_error(err, "steady: unknown option '%s' (see ekmcompare --help)", a);
        else if (path)
            rc = usage_error(err, "steady: expected one monitor file, got a second one '%s'", a);
        else
            path = a;
    }
    if (!rc && !path)
        rc = EKM_FAIL(err, EKM_EUSAGE, "steady: expected a monitor file (see ekmcompare --help)");
    double *v = NULL;
    size_t n = 0;
    if (!rc)
        rc = cg_steadiness_monitor_read(path, column, &v, &n, err);
    if (rc)
        return rc;
    cg_steadiness_verdict r = cg_steadiness_drift(v, n, tol);
    free(v);
    fputs("{\"steady\": ", stdout);
    fputs(!r.known ? "null" : r.steady ? "true" : "false", stdout);
    fputs(", \"drift\": ", stdout);
    if (r.known)
        printf("%.4g", r.drift);
    else
        fputs("null", stdout);
    fputs(", \"tol\": ", stdout);
    print_exact(tol);
    printf(", \"samples\": %zu}\n", r.samples);
    if (fflush(stdout) != 0 || ferror(stdout))
        return EKM_FAIL(err, EKM_EIO, "steady: cannot write the result");
    return EKM_OK;
}

int main(int argc, char **argv)
{
    gsl_set_error_handler_off();
    ekm_h5_quiet();
    ekm_error err;
    ekm_error_clear(&err);
    ekm_status rc = ekm_atomic_install_signal_cleanup(&err);
    if (rc) {
        ekm_error_print("ekmcompare", &err);
        return ekm_status_exit_code(rc);
    }
    if (argc < 2) {
        fputs(usage_text, stderr);
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        fputs(usage_text, stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("ekmcompare %s\n", EKMBENCH_VERSION);
        return 0;
    }
    if (!strcmp(argv[1], "fit"))
        return cg_fit_main(argc - 2, argv + 2); /* exit codes of docs/exit-codes.md */
    if (!strcmp(argv[1], "cg"))
        rc = cmd_cg(argc - 2, argv + 2, &err);
    else if (!strcmp(argv[1], "score"))
        rc = cmd_score(argc - 2, argv + 2, &err);
    else if (!strcmp(argv[1], "score2d"))
        rc = cmd_score2d(argc - 2, argv + 2, &err);
    else if (!strcmp(argv[1], "steady"))
        rc = cmd_steady(argc - 2, argv + 2, &err);
    else if (!strcmp(argv[1], "base"))
        rc = cmd_base(argc - 2, argv + 2, &err);
    else
        rc = EKM_FAIL(&err, EKM_EUSAGE,
                      "unknown command '%s': expected cg, score, score2d, fit, steady or base (see --help)",
                      argv[1]);
    if (rc) {
        ekm_error_print("ekmcompare", &err);
        return ekm_status_exit_code(rc);
    }
    return 0;
}
