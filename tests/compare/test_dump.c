/* test_dump.c: the dump reader on real-format fixtures, synthetic text /
 * gzip / binary dumps, and bad inputs (each with its message). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>
#include <stdint.h>

#include "dump.h"
#include "synth.h"
#include "test_util.h"

static const char *const cols[] = {"x",    "y",  "z",  "vx",      "vy",      "vz",  "radius",
                                   "mass", "xs", "zs", "c_sa[1]", "c_sa[6]", "type"};
#define NCOLS (sizeof cols / sizeof *cols)

/* Read all snapshots of a file; returns the status of the last call. */
static ekm_status read_all(const char *path, size_t *nsnap, cg_snapshot *last, ekm_error *err, int *truncated)
{
    cg_dump *d;
    ekm_status rc = cg_dump_open(&d, path, cols, NCOLS, err);
    if (rc)
        return rc;
    *nsnap = 0;
    while ((rc = cg_dump_next(d, last, err)) == EKM_OK)
        (*nsnap)++;
    *truncated = cg_dump_truncated(d);
    cg_dump_close(d);
    return rc;
}

static void test_parse_double(void **state)
{
    (void)state;
    struct {
        const char *s;
        double v;
        int rc;
    } cases[] = {{"1", 1.0, 0},
                 {"-2.5", -2.5, 0},
                 {"1e-3", 1e-3, 0},
                 {"+.5", 0.5, 0},
                 {"0.00123457", 0.00123457, 0},
                 {"1.5E+02", 150.0, 0},
                 {"6.02214076e23", 6.02214076e23, 0},
                 {"0.1234567890123456789", 0.1234567890123456789, 0},
                 {"1e-300", 1e-300, 0},
                 {"12345678901234567890", 12345678901234567890.0, 0},
                 {"nan", 0, 2},
                 {"-inf", 0, 2},
                 {"1e999", 0, 2},
                 {"abc", 0, 1},
                 {"1.2.3", 0, 1},
                 {"1e", 0, 1},
                 {"-", 0, 1},
                 {"3x", 0, 1},
                 {".", 0, 1}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        const char *p = cases[i].s;
        double v = -999;
        int rc = cg_parse_double(&p, &v);
        assert_int_equal(rc, cases[i].rc);
        if (rc == 0) {
            double ref = strtod(cases[i].s, NULL); /* within 1 ulp */
            assert_true(fabs(v - ref) <= 2.3e-16 * fabs(ref));
            assert_true(*p == '\0');
        }
    }
}

static void test_liggghts_deck(void **state)
{
    (void)state;
    cg_snapshot s = {0};
    ekm_error err;
    size_t n;
    int tr;
    assert_int_equal(read_all(CG_FIXTURES "/liggghts_deck.dump", &n, &s, &err, &tr), EKM_EOF);
    assert_int_equal(n, 3);
    assert_int_equal(tr, 0);
    assert_int_equal(s.step, 2000);
    assert_int_equal(s.has_time, 0);
    assert_int_equal(s.natoms, 8);
    assert_true(s.periodic[0] && s.periodic[1] && !s.periodic[2]);
    assert_true(s.present[0] && s.present[2] && s.present[7] && s.present[10] && s.present[11]);
    assert_false(s.present[8]);
    assert_close(s.hi[2], 0.02, 1e-15);
    /* first atom of the last snapshot: z = column 5 of its line */
    assert_true(s.data[2] > 0 && s.data[2] < 0.02);
    cg_snapshot_free(&s);
}

static void test_lammps_time_and_gzip(void **state)
{
    (void)state;
    cg_snapshot a = {0}, b = {0};
    ekm_error err;
    size_t na, nb;
    int tr;
    assert_int_equal(read_all(CG_FIXTURES "/lammps_time.dump", &na, &a, &err, &tr), EKM_EOF);
    assert_int_equal(read_all(CG_FIXTURES "/lammps_time.dump.gz", &nb, &b, &err, &tr), EKM_EOF);
    assert_int_equal(na, 3);
    assert_int_equal(nb, 3);
    assert_int_equal(a.has_time, 1);
    assert_close(a.time, 4000 * 2e-6, 1e-15);
    assert_memory_equal(a.data, b.data, a.natoms * a.nsel * sizeof(double));
    cg_snapshot_free(&a);
    cg_snapshot_free(&b);
}

static void test_triclinic(void **state)
{
    (void)state;
    cg_snapshot s = {0};
    ekm_error err;
    size_t n;
    int tr;
    assert_int_equal(read_all(CG_FIXTURES "/triclinic.dump", &n, &s, &err, &tr), EKM_EOF);
    assert_int_equal(n, 2);
    assert_int_equal(s.triclinic, 1);
    assert_close(s.tilt[1], 0.004, 1e-15);
    assert_close(s.lo[0], 0.0, 1e-15);
    assert_close(s.hi[0], 0.01, 1e-15); /* bounding box minus the tilt */
    assert_close(s.hi[1], 0.01, 1e-15);
    assert_true(s.present[8] && s.present[9]);
    cg_snapshot_free(&s);
}

static void test_truncated(void **state)
{
    (void)state;
    cg_snapshot s = {0};
    ekm_error err;
    size_t n;
    int tr;
    assert_int_equal(read_all(CG_FIXTURES "/truncated.dump", &n, &s, &err, &tr), EKM_EOF);
    assert_int_equal(n, 2);
    assert_int_equal(tr, 1);
    cg_snapshot_free(&s);
    /* a gzip stream cut short */
    char path[512];
    tmp_path(path, sizeof path, "cut.dump.gz");
    FILE *in = fopen(CG_FIXTURES "/lammps_time.dump.gz", "rb");
    assert_non_null(in);
    char buf[4096];
    size_t len = fread(buf, 1, sizeof buf, in);
    fclose(in);
    FILE *out = fopen(path, "wb");
    assert_non_null(out);
    fwrite(buf, 1, len * 3 / 4, out);
    fclose(out);
    ekm_status rc = read_all(path, &n, &s, &err, &tr);
    assert_int_equal(rc, EKM_EOF);
    assert_int_equal(tr, 1);
    assert_true(n >= 1 && n < 3);
    cg_snapshot_free(&s);
}

/* The same synthetic draw as text, gzip and binary gives the same numbers. */
static void test_formats_agree(void **state)
{
    (void)state;
    synth_opts o = synth_default();
    o.natoms = 500;
    o.nsnap = 3;
    o.gdot = 5;
    const char *names[3] = {"s.txt", "s.gz", "s.bin"};
    synth_format fm[3] = {SYNTH_TEXT, SYNTH_GZ, SYNTH_BIN};
    cg_snapshot s[3] = {{0}};
    for (int k = 0; k < 3; k++) {
        char path[512];
        o.format = fm[k];
        assert_int_equal(synth_write(tmp_path(path, sizeof path, names[k]), &o), 0);
        ekm_error err;
        size_t n;
        int tr;
        assert_int_equal(read_all(path, &n, &s[k], &err, &tr), EKM_EOF);
        assert_int_equal(n, 3);
        assert_int_equal(s[k].natoms, 500);
        assert_int_equal(s[k].has_time, 1);
    }
    assert_memory_equal(s[0].data, s[1].data, 500 * NCOLS * sizeof(double));
    for (size_t i = 0; i < 500 * NCOLS; i++)
        assert_true(fabs(s[0].data[i] - s[2].data[i]) <= 1e-8 * fabs(s[2].data[i]) + 1e-300);
    for (int k = 0; k < 3; k++)
        cg_snapshot_free(&s[k]);
}

/* Bad inputs: each gives one error naming file and line. */
static void expect_error(const char *name, const char *text, const char *needle)
{
    char path[512];
    tmp_path(path, sizeof path, name);
    assert_int_equal(write_text(path, text), 0);
    cg_snapshot s = {0};
    ekm_error err;
    size_t n;
    int tr;
    ekm_status rc = read_all(path, &n, &s, &err, &tr);
    cg_snapshot_free(&s);
    if (rc != EKM_EINPUT || !strstr(err.message, needle) || !strstr(err.message, path))
        fail_msg("%s: rc %d, message '%s', expected '%s'", name, rc, err.message, needle);
}

#define HDR "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 1\n"

/* Values that make no sense for what their column is (cg_dump_expect:
 * radius and mass positive, a particle no larger than the box, an integer
 * type, a velocity below the speed of light) and boxes without a finite
 * length: errors at the dump's line and column. */
static void expect_value_error(const char *name, const char *text, const char *needle)
{
    char path[512];
    tmp_path(path, sizeof path, name);
    assert_int_equal(write_text(path, text), 0);
    cg_dump *d;
    ekm_error err;
    assert_int_equal(cg_dump_open(&d, path, cols, NCOLS, &err), EKM_OK);
    cg_dump_expect(d, 6, CG_DUMP_RADIUS);
    cg_dump_expect(d, 7, CG_DUMP_POSITIVE);
    cg_dump_expect(d, 12, CG_DUMP_INTEGER);
    for (size_t j = 3; j < 6; j++)
        cg_dump_expect(d, j, CG_DUMP_VELOCITY);
    cg_snapshot s = {0};
    ekm_status rc;
    while ((rc = cg_dump_next(d, &s, &err)) == EKM_OK)
        ;
    cg_dump_close(d);
    cg_snapshot_free(&s);
    if (rc != EKM_EINPUT || !strstr(err.message, needle) || !strstr(err.message, path))
        fail_msg("%s: rc %d, message '%s', expected '%s'", name, rc, err.message, needle);
}

static void test_value_checks(void **state)
{
    (void)state;
    expect_value_error("neg_radius.dump",
                       HDR "ITEM: ATOMS x y z vx vy vz radius mass\n"
                           "0.1 0.2 0.3 0 0 0 0.01 1\n0.1 0.2 0.3 0 0 0 -0.001 1\n",
                       ":11:19: radius: expected a positive finite number, got -0.001");
    expect_value_error(
        "big_radius.dump",
        HDR "ITEM: ATOMS x y z vx vy vz radius mass\n"
            "0.1 0.2 0.3 0 0 0 1e30 1\n0.1 0.2 0.3 0 0 0 0.01 1\n",
        ":10:19: radius: expected a particle no larger than the box (longest edge 1 m), got 1e30");
    expect_value_error("zero_mass.dump",
                       HDR "ITEM: ATOMS x y z vx vy vz radius mass\n"
                           "0.1 0.2 0.3 0 0 0 0.01 0\n0.1 0.2 0.3 0 0 0 0.01 1\n",
                       ":10:24: mass: expected a positive finite number, got 0");
    expect_value_error("half_type.dump",
                       HDR "ITEM: ATOMS x y z vx vy vz radius mass type\n"
                           "0.1 0.2 0.3 0 0 0 0.01 1 1\n0.1 0.2 0.3 0 0 0 0.01 1 1.5\n",
                       ":11:26: type: expected an integer, got 1.5");
    expect_value_error("huge_type.dump",
                       HDR "ITEM: ATOMS x y z vx vy vz radius mass type\n"
                           "0.1 0.2 0.3 0 0 0 0.01 1 1e17\n0.1 0.2 0.3 0 0 0 0.01 1 1\n",
                       ":10:26: type: expected an integer of magnitude at most 2^53");
    expect_value_error("light_speed.dump",
                       HDR "ITEM: ATOMS x y z vx vy vz radius mass\n"
                           "0.1 0.2 0.3 0 -299792457 0 0.01 1\n0.1 0.2 0.3 0 -299792458 0 0.01 1\n",
                       ":11:15: vy: expected a velocity component below the speed of light (|v| < 299792458 "
                       "m/s), got -299792458");
    expect_value_error("huge_velocity.dump",
                       HDR "ITEM: ATOMS x y z vx vy vz radius mass\n"
                           "0.1 0.2 0.3 1e300 0 0 0.01 1\n0.1 0.2 0.3 0 0 0 0.01 1\n",
                       ":10:13: vx: expected a velocity component below the speed of light");
    expect_value_error("huge_box.dump",
                       "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp ff\n0 1\n"
                       "-1e308 1e308\n0 1\nITEM: ATOMS x y z vx vy vz radius mass\n0 0 0 0 0 0 0.1 1\n",
                       ":7: ITEM: BOX BOUNDS: y: expected finite bounds lo < hi with a finite length, got "
                       "-1e+308 .. 1e+308");
    expect_value_error("inf_box.dump",
                       "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp ff\n0 1\n"
                       "0 1\n0 1e999\nITEM: ATOMS x y z vx vy vz radius mass\n0 0 0 0 0 0 0.1 1\n",
                       ":8:3: ITEM: BOX BOUNDS: expected 2 finite numbers");
}

/* A last line without its newline is cut short, also when what is left of
 * it parses (the last value 1.25 cut to 1.2, or only the newline gone): the
 * snapshot is skipped as truncated, the earlier one kept. */
static void test_cut_last_line(void **state)
{
    (void)state;
#define SNAP HDR "ITEM: ATOMS x y z vx vy vz mass\n0.1 0.2 0.3 0 0 0 1\n0.1 0.2 0.3 0 0 0 1.25\n"
    static const char full[] = SNAP SNAP;
#undef SNAP
    const size_t len = sizeof full - 1;
    const struct {
        size_t cut; /* bytes cut off the end */
        size_t n;   /* complete snapshots */
        int trunc;  /* 1: the last one skipped */
    } cases[] = {{0, 2, 0}, {1, 1, 1}, {2, 1, 1}, {3, 1, 1}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        char path[512], text[sizeof full];
        memcpy(text, full, len - cases[c].cut);
        text[len - cases[c].cut] = '\0';
        tmp_path(path, sizeof path, "cut_line.dump");
        assert_int_equal(write_text(path, text), 0);
        cg_snapshot s = {0};
        ekm_error err;
        size_t n;
        int tr;
        assert_int_equal(read_all(path, &n, &s, &err, &tr), EKM_EOF);
        assert_int_equal(n, cases[c].n);
        assert_int_equal(tr, cases[c].trunc);
        cg_snapshot_free(&s);
    }
}

/* Snapshot times increase strictly (cg_snapshot_time): ITEM: TIME going
 * back or repeating is an error at its line, naming both times; without
 * ITEM: TIME step x dt, and no dt is a usage error. */
static void expect_times(const char *name, const char *text, double dt, size_t nok, ekm_status want,
                         const char *needle)
{
    char path[512];
    tmp_path(path, sizeof path, name);
    assert_int_equal(write_text(path, text), 0);
    cg_dump *d;
    ekm_error err;
    assert_int_equal(cg_dump_open(&d, path, cols, NCOLS, &err), EKM_OK);
    cg_snapshot s = {0};
    cg_time_order ord = {0, 0.0};
    ekm_status rc;
    size_t n = 0;
    double t = -1.0;
    while ((rc = cg_dump_next(d, &s, &err)) == EKM_OK) {
        if ((rc = cg_snapshot_time(&s, dt, &ord, &t, &err)))
            break;
        n++;
    }
    cg_dump_close(d);
    cg_snapshot_free(&s);
    if (n != nok || rc != want || (needle && (!strstr(err.message, needle) || !strstr(err.message, path))))
        fail_msg("%s: %zu times, rc %d, message '%s', expected %zu, '%s'", name, n, rc,
                 rc > 0 ? err.message : "", nok, needle ? needle : "");
}

static void test_times(void **state)
{
    (void)state;
#define ONE "ITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 1\nITEM: ATOMS x\n0.5\n"
    expect_times("times_ok.dump",
                 "ITEM: TIME\n0\nITEM: TIMESTEP\n0\n" ONE "ITEM: TIME\n0.004\nITEM: TIMESTEP\n1\n" ONE, 0.0,
                 2, EKM_EOF, NULL);
    expect_times("times_back.dump",
                 "ITEM: TIME\n0\nITEM: TIMESTEP\n0\n" ONE "ITEM: TIME\n0.01\nITEM: TIMESTEP\n1\n" ONE
                 "ITEM: TIME\n0.008\nITEM: TIMESTEP\n2\n" ONE,
                 1e-5, 2, EKM_EINPUT,
                 ":26: ITEM: TIME: expected a time after the previous snapshot's 0.01 s, got 0.008 s");
    /* TIMESTEP after TIME (either order): the error still names the TIME */
    expect_times("times_repeat.dump",
                 "ITEM: TIMESTEP\n0\nITEM: TIME\n0\n" ONE "ITEM: TIMESTEP\n1\nITEM: TIME\n0.004\n" ONE
                 "ITEM: TIMESTEP\n2\nITEM: TIME\n0.004\n" ONE,
                 0.0, 2, EKM_EINPUT,
                 ":28: ITEM: TIME: expected a time after the previous snapshot's 0.004 s, got 0.004 s");
    /* two times that differ in the 17th digit are printed so */
    expect_times("times_close.dump",
                 "ITEM: TIME\n0.10000000000000002\nITEM: TIMESTEP\n0\n" ONE
                 "ITEM: TIME\n0.1\nITEM: TIMESTEP\n1\n" ONE,
                 0.0, 1, EKM_EINPUT, "previous snapshot's 0.10000000000000002 s, got 0.1 s");
    /* step x dt: steps beyond 2^53 that round to the same time */
    expect_times("times_steps.dump",
                 "ITEM: TIMESTEP\n9007199254740992\n" ONE "ITEM: TIMESTEP\n9007199254740993\n" ONE, 1.0, 1,
                 EKM_EINPUT, ":12: ITEM: TIMESTEP 9007199254740993 x --dt 1 s: expected a time after");
    expect_times("times_nodt.dump", "ITEM: TIMESTEP\n0\n" ONE, 0.0, 0, EKM_EUSAGE,
                 ":9: the dump has no ITEM: TIME: give --dt");
#undef ONE
}

static void test_bad_inputs(void **state)
{
    (void)state;
    expect_error("malformed.dump",
                 HDR "ITEM: ATOMS x y z vx vy vz mass\n"
                     "0.1 0.2 0.3 0 0 0 1\n0.1 0.2 0.3x 0 0 0 1\n",
                 ":11:9: column 'z': expected a number, got '0.3x'");
    expect_error("nan.dump",
                 HDR "ITEM: ATOMS x y z vx vy vz mass\n"
                     "0.1 0.2 0.3 0 0 0 1\n0.1 0.2 0.3 nan 0 0 1\n",
                 ":11:13: column 'vx': expected a finite number, got 'nan'");
    expect_error("inf.dump",
                 HDR "ITEM: ATOMS x y z vx vy vz mass\n"
                     "0.1 0.2 0.3 0 0 -inf 1\n0.1 0.2 0.3 0 0 0 1\n",
                 ":10:17: column 'vz': expected a finite number");
    expect_error("fewcols.dump",
                 HDR "ITEM: ATOMS x y z vx vy vz mass\n"
                     "0.1 0.2 0.3 0 0 0 1\n0.1 0.2 0.3 0 0\n",
                 ":11: expected 7 columns, got 5");
    expect_error("manycols.dump",
                 HDR "ITEM: ATOMS x y z vx vy vz mass\n"
                     "0.1 0.2 0.3 0 0 0 1 7\n0.1 0.2 0.3 0 0 0 1\n",
                 ":10: expected 7 columns, got more");
    expect_error("fewatoms.dump",
                 HDR "ITEM: ATOMS x y z vx vy vz mass\n"
                     "0.1 0.2 0.3 0 0 0 1\n" HDR "ITEM: ATOMS x y z vx vy vz mass\n",
                 ":11: expected 2 atoms (ITEM: NUMBER OF ATOMS), got 1");
    expect_error("moreatoms.dump",
                 HDR "ITEM: ATOMS x y z vx vy vz mass\n"
                     "0.1 0.2 0.3 0 0 0 1\n0.1 0.2 0.3 0 0 0 1\n0.1 0.2 0.3 0 0 0 1\n",
                 ":12: expected an ITEM: line");
    expect_error("badstep.dump", "ITEM: TIMESTEP\n5a\n", ":2: ITEM: TIMESTEP: expected an integer");
    expect_error("badbox.dump",
                 "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp ff\n0 1\n1 0\n0 1\n",
                 ":7: ITEM: BOX BOUNDS: expected lo < hi");
    expect_error("noatoms.dump",
                 "ITEM: TIMESTEP\n5\nITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 1\nITEM: ATOMS x\n",
                 ":7: expected ITEM: NUMBER OF ATOMS before ITEM: ATOMS");
    expect_error("unknown.dump", "ITEM: TIMESTEP\n5\nITEM: BONDS\n", ":3: expected ITEM: TIMESTEP");
    expect_error("garbage.dump", "hello world, this is not a dump\n", ":1: expected an ITEM: line");
}

/* Binary inconsistencies: chunks that do not add up to the atom count. */
static void test_bad_binary(void **state)
{
    (void)state;
    synth_opts o = synth_default();
    o.natoms = 10;
    o.nsnap = 1;
    o.format = SYNTH_BIN;
    char path[512];
    assert_int_equal(synth_write(tmp_path(path, sizeof path, "b.bin"), &o), 0);
    FILE *fp = fopen(path, "rb");
    char buf[8192];
    size_t len = fread(buf, 1, sizeof buf, fp);
    fclose(fp);
    /* natoms is the int64 after magic(8+10), endian, revision, step */
    int64_t na = 11;
    memcpy(buf + 8 + 10 + 4 + 4 + 8, &na, 8);
    char bad[512];
    fp = fopen(tmp_path(bad, sizeof bad, "bad.bin"), "wb");
    fwrite(buf, 1, len, fp);
    fclose(fp);
    cg_snapshot s = {0};
    ekm_error err;
    size_t n;
    int tr;
    assert_int_equal(read_all(bad, &n, &s, &err, &tr), EKM_EINPUT);
    assert_non_null(strstr(err.message, "expected 11 atoms (header), chunks hold 10"));
    /* truncated binary: a warning, not an error */
    fp = fopen(bad, "wb");
    fwrite(buf, 1, len - 100, fp);
    fclose(fp);
    assert_int_equal(read_all(bad, &n, &s, &err, &tr), EKM_EOF);
    assert_int_equal(tr, 1);
    assert_int_equal(n, 0);
    cg_snapshot_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_double),
        cmocka_unit_test(test_liggghts_deck),
        cmocka_unit_test(test_lammps_time_and_gzip),
        cmocka_unit_test(test_triclinic),
        cmocka_unit_test(test_truncated),
        cmocka_unit_test(test_cut_last_line),
        cmocka_unit_test(test_times),
        cmocka_unit_test(test_formats_agree),
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_value_checks),
        cmocka_unit_test(test_bad_binary),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
