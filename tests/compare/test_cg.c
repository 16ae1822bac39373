/* test_cg.c: coarse-graining against known truth (synthetic particle sets
 * with a fixed seed), exact identities, and the DEM-deck fixture. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>

#include <gsl/gsl_rng.h>
#include <zlib.h>

#include "cg_run.h"
#include "h5.h"
#include "synth.h"
#include "test_util.h"

#define PI 3.14159265358979323846

typedef struct {
    size_t n, nt;
    double *z, *t, *f, *se;
} profile;

static void profile_free(profile *p)
{
    free(p->z);
    free(p->t);
    free(p->f);
    free(p->se);
    memset(p, 0, sizeof *p);
}

/* A dataset of a cg output: [n] (*nt = 0) or [nt][n]. */
static void read_array(ekm_h5_file *r, const char *name, double **data, size_t *nt, size_t *n)
{
    ekm_error err;
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    if (ekm_h5_read_double(r, name, &rank, dims, data, &err))
        fail_msg("%s", err.message);
    assert_true(rank == 1 || rank == 2);
    *nt = rank == 2 ? dims[0] : 0;
    *n = rank == 2 ? dims[1] : dims[0];
}

/* Read field `name` (and its _se) of a cg output. */
static void read_field(const char *path, const char *name, profile *p)
{
    ekm_h5_file *r;
    ekm_error err;
    size_t nt, n;
    char se[64];
    memset(p, 0, sizeof *p);
    assert_int_equal(ekm_h5_open(&r, path, &err), EKM_OK);
    read_array(r, "z", &p->z, &nt, &p->n);
    read_array(r, "t", &p->t, &nt, &p->nt);
    read_array(r, name, &p->f, &nt, &n);
    assert_int_equal(nt, p->nt);
    assert_int_equal(n, p->n);
    snprintf(se, sizeof se, "%s_se", name);
    read_array(r, se, &p->se, &nt, &n);
    ekm_h5_close(r);
}

static void run_cg_x(const char *dump, const char *out, const char *kernel, double width, size_t bins,
                     cg_tmode tmode, size_t every, int exact)
{
    cg_run_opts o = cg_opts_default();
    o.exact = exact;
    const char *in[1] = {dump};
    o.inputs = in;
    o.ninputs = 1;
    o.out = out;
    o.kernel = kernel;
    o.width = width;
    o.bins = bins;
    o.tmode = tmode;
    o.every = every;
    ekm_error err;
    ekm_status rc = cg_run(&o, &err);
    if (rc)
        fail_msg("cg_run: %s", err.message);
}

static void run_cg(const char *dump, const char *out, const char *kernel, double width, size_t bins,
                   cg_tmode tmode, size_t every)
{
    run_cg_x(dump, out, kernel, width, bins, tmode, every, 0);
}

/* |f - truth| <= 3 SE in every bulk bin (>= `edge` from the walls), and
 * the normalised residuals have an rms in [0.4, 1.6] (SEs are honest). */
static void check_truth(const char *what, const profile *p, double edge, double lz,
                        double (*truth)(double z, const void *ctx), const void *ctx)
{
    double chi2 = 0;
    size_t nb = 0;
    for (size_t k = 0; k < p->n; k++) {
        double z = p->z[k];
        if (z < edge || z > lz - edge)
            continue;
        double tr = truth(z, ctx), d = p->f[k] - tr, se = p->se[k];
        assert_true(se > 0);
        if (fabs(d) > 3 * se)
            fail_msg("%s at z = %g: %g, truth %g, SE %g (%.2f SE)", what, z, p->f[k], tr, se, d / se);
        chi2 += d * d / (se * se);
        nb++;
    }
    assert_true(nb >= 5);
    double rms = sqrt(chi2 / (double)nb);
    if (rms < 0.4 || rms > 1.6)
        fail_msg("%s: rms of residual/SE = %g", what, rms);
}

static double t_phi(double z, const void *ctx)
{
    const synth_opts *o = ctx;
    return synth_rho(o, z) / o->rho_p;
}
static double t_u(double z, const void *ctx)
{
    const synth_opts *o = ctx;
    return o->u0 + o->gdot * (z - 0.5 * o->lz);
}
static double t_v(double z, const void *ctx)
{
    (void)z;
    return ((const synth_opts *)ctx)->v0;
}
static double t_T(double z, const void *ctx)
{
    const synth_opts *o = ctx;
    return o->T0 * (1.0 + o->b * (z / o->lz - 0.5));
}

static synth_opts base(void)
{
    synth_opts o = synth_default();
    o.natoms = 4000;
    o.nsnap = 24;
    o.radius = 0.0004;
    o.a = 0.8;
    o.b = 0.5;
    o.u0 = 0.1;
    o.v0 = -0.05;
    o.T0 = 1e-4;
    return o;
}

/* phi(z), u(z), T(z) recovered within 3 SE in the bulk (no shear). */
static void test_recovery(void **state)
{
    (void)state;
    synth_opts o = base();
    char dump[512], out[512];
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "rec.dump"), &o), 0);
    const char *kernels[] = {"gauss", "lucy", "bins"};
    for (int ik = 0; ik < 3; ik++) {
        tmp_path(out, sizeof out, "rec.h5");
        run_cg(dump, out, kernels[ik], 0.002, 20, CG_T_PARTICLE, 0);
        profile p;
        double edge = 0.007;
        read_field(out, "phi", &p);
        assert_int_equal(p.nt, 1);
        check_truth("phi", &p, edge, o.lz, t_phi, &o);
        profile_free(&p);
        read_field(out, "vx", &p);
        check_truth("vx", &p, edge, o.lz, t_u, &o);
        profile_free(&p);
        read_field(out, "vz", &p);
        check_truth("vz", &p, edge, o.lz, t_v, &o);
        profile_free(&p);
        read_field(out, "T", &p);
        check_truth("T", &p, edge, o.lz, t_T, &o);
        profile_free(&p);
    }
}

/* Shear: the particle T recovers T; the consistent T adds the velocity
 * variance inside the kernel, gdot^2 (w_eff^2)/3, w_eff^2 = var(kernel) +
 * dz^2/12 (bin average); truncated Gaussian: var = 0.97333 w^2. */
static double shear_extra;
static double t_T_consistent(double z, const void *ctx)
{
    return t_T(z, ctx) + shear_extra;
}

static void test_shear_temperatures(void **state)
{
    (void)state;
    synth_opts o = base();
    o.a = 0.0;
    o.b = 0.0;
    o.gdot = 5.0;
    char dump[512], out[512];
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "shear.dump"), &o), 0);
    double w = 0.002, dz = o.lz / 20;
    tmp_path(out, sizeof out, "shear.h5");
    profile p;
    run_cg(dump, out, "gauss", w, 20, CG_T_PARTICLE, 0);
    read_field(out, "T", &p);
    check_truth("T (particle)", &p, 0.007, o.lz, t_T, &o);
    profile_free(&p);
    run_cg(dump, out, "gauss", w, 20, CG_T_CONSISTENT, 0);
    shear_extra = o.gdot * o.gdot * (0.973336 * w * w + dz * dz / 12.0) / 3.0;
    assert_true(shear_extra > 0.3 * o.T0);
    read_field(out, "T", &p);
    check_truth("T (consistent)", &p, 0.007, o.lz, t_T_consistent, &o);
    profile_free(&p);
}

/* --steady over several files: a cooling transient (T0 = 8, 4, 2 x the
 * final value in the first three files) then a steady state; the chosen
 * start is after the transient and T is recovered. */
static void test_steady_multifile(void **state)
{
    (void)state;
    synth_opts o = base(); /* 4000 particles: N_eff ~ 700 per kernel, so the
                              -T/N_eff bias of the fluctuation estimate stays
                              well below one SE */
    o.nsnap = 10;
    o.a = 0;
    o.b = 0;
    const double f[6] = {8, 4, 2, 1, 1, 1};
    char names[6][512];
    const char *in[6];
    for (int i = 0; i < 6; i++) {
        char nm[32];
        snprintf(nm, sizeof nm, "steady%d.dump", i);
        o.T0 = 1e-4 * f[i];
        o.seed = 100 + (unsigned long)i;
        o.step0 = (int64_t)i * 10 * o.dstep;
        assert_int_equal(synth_write(tmp_path(names[i], sizeof names[i], nm), &o), 0);
        in[i] = names[i];
    }
    cg_run_opts ro = cg_opts_default();
    char out[512];
    ro.inputs = in;
    ro.ninputs = 6;
    ro.out = tmp_path(out, sizeof out, "steady.h5");
    ro.width = 0.002;
    ro.bins = 20;
    ro.steady = 1;
    ekm_error err;
    if (cg_run(&ro, &err))
        fail_msg("%s", err.message);
    ekm_h5_file *r;
    assert_int_equal(ekm_h5_open(&r, out, &err), EKM_OK);
    double ts, t3 = 30 * o.dstep * o.dt;
    assert_int_equal(ekm_h5_attr_get_double(r, NULL, "steady_start", &ts, &err), EKM_OK);
    ekm_h5_close(r);
    if (ts < t3 - 1e-12 || ts > t3 + 10 * o.dstep * o.dt)
        fail_msg("steady start %g s, expected in [%g, %g]", ts, t3, t3 + 10 * o.dstep * o.dt);
    /* the transient is excluded: one snapshot at 2x T among the 30 would put
     * the bulk-mean T 3% high. Bulk mean vs truth within 3 SE, with the SE of
     * a bin (bins are correlated over the kernel; the per-bin 3-SE check is
     * test_recovery's) */
    profile p;
    read_field(out, "T", &p);
    double m = 0, se = 0;
    int nb = 0;
    for (size_t k = 0; k < p.n; k++)
        if (p.z[k] > 0.007 && p.z[k] < o.lz - 0.007) {
            m += p.f[k];
            se += p.se[k];
            nb++;
        }
    m /= nb;
    se /= nb;
    assert_true(se < 0.01 * 1e-4);
    assert_close(m, 1e-4, 3 * se);
    profile_free(&p);
}

/* Integral of rho over z = total mass / area, each snapshot, every kernel. */
static void test_mass_identity(void **state)
{
    (void)state;
    synth_opts o = base();
    o.nsnap = 3;
    o.natoms = 1000;
    char dump[512], out[512];
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "mass.dump"), &o), 0);
    double m = o.rho_p * 4.0 / 3.0 * PI * pow(o.radius, 3);
    double expect = (double)o.natoms * m / (o.lx * o.ly);
    const char *kernels[] = {"gauss", "lucy", "bins", "gauss", "lucy"};
    for (int ik = 0; ik < 5; ik++) {
        run_cg_x(dump, tmp_path(out, sizeof out, "mass.h5"), kernels[ik], 0.003, 37, CG_T_PARTICLE, 1,
                 ik >= 3);
        profile p;
        read_field(out, "rho", &p);
        assert_int_equal(p.nt, 3);
        double dz = p.z[1] - p.z[0];
        for (size_t it = 0; it < p.nt; it++) {
            double sum = 0;
            for (size_t k = 0; k < p.n; k++)
                sum += p.f[it * p.n + k] * dz;
            assert_close(sum, expect, 1e-9 * expect);
        }
        profile_free(&p);
    }
}

/* The sub-grid (default) and the per-particle kernel agree: the sub-grid
 * only widens the kernel variance by <= (dz/32)^2. */
static void test_subgrid_vs_exact(void **state)
{
    (void)state;
    synth_opts o = base();
    o.nsnap = 4;
    o.gdot = 3.0;
    char dump[512], h1[512], h2[512];
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "sub.dump"), &o), 0);
    const char *kernels[] = {"gauss", "lucy"};
    for (int ik = 0; ik < 2; ik++) {
        run_cg_x(dump, tmp_path(h1, sizeof h1, "sub1.h5"), kernels[ik], 0.002, 20, CG_T_PARTICLE, 0, 0);
        run_cg_x(dump, tmp_path(h2, sizeof h2, "sub2.h5"), kernels[ik], 0.002, 20, CG_T_PARTICLE, 0, 1);
        const char *f[] = {"phi", "vx", "T"};
        for (int i = 0; i < 3; i++) {
            profile a, b;
            read_field(h1, f[i], &a);
            read_field(h2, f[i], &b);
            for (size_t k = 0; k < a.n; k++)
                assert_close(a.f[k], b.f[k], 2e-4 * fabs(b.f[k]) + 1e-3 * b.se[k]);
            profile_free(&a);
            profile_free(&b);
        }
    }
}

/* A uniform velocity added to every particle leaves T unchanged. */
static void test_galilean(void **state)
{
    (void)state;
    synth_opts o = base();
    o.nsnap = 4;
    o.gdot = 3.0;
    o.format = SYNTH_BIN;
    char d1[512], d2[512], h1[512], h2[512];
    assert_int_equal(synth_write(tmp_path(d1, sizeof d1, "gal1.bin"), &o), 0);
    o.u0 += 3.7;
    o.v0 -= 1.2;
    assert_int_equal(synth_write(tmp_path(d2, sizeof d2, "gal2.bin"), &o), 0);
    for (int mode = 0; mode < 2; mode++) {
        cg_tmode tm = mode ? CG_T_CONSISTENT : CG_T_PARTICLE;
        run_cg(d1, tmp_path(h1, sizeof h1, "gal1.h5"), "gauss", 0.002, 20, tm, 0);
        run_cg(d2, tmp_path(h2, sizeof h2, "gal2.h5"), "gauss", 0.002, 20, tm, 0);
        profile a, b;
        read_field(h1, "T", &a);
        read_field(h2, "T", &b);
        for (size_t k = 0; k < a.n; k++)
            assert_close(b.f[k], a.f[k], 1e-8 * a.f[k]);
        profile_free(&a);
        profile_free(&b);
    }
}

/* Shuffled columns (and extra ones) give identical output. */
static void test_shuffled_columns(void **state)
{
    (void)state;
    synth_opts o = base();
    o.nsnap = 3;
    o.with_stress = 1;
    o.P0 = 100;
    char d1[512], d2[512], h1[512], h2[512];
    assert_int_equal(synth_write(tmp_path(d1, sizeof d1, "ord1.dump"), &o), 0);
    o.shuffle = 1;
    assert_int_equal(synth_write(tmp_path(d2, sizeof d2, "ord2.dump"), &o), 0);
    run_cg(d1, tmp_path(h1, sizeof h1, "ord1.h5"), "gauss", 0.002, 20, CG_T_PARTICLE, 0);
    run_cg(d2, tmp_path(h2, sizeof h2, "ord2.h5"), "gauss", 0.002, 20, CG_T_PARTICLE, 0);
    const char *f[] = {"phi", "rho", "vx", "vy", "vz", "T", "P", "sxz", "szz"};
    for (size_t i = 0; i < sizeof f / sizeof *f; i++) {
        profile a, b;
        read_field(h1, f[i], &a);
        read_field(h2, f[i], &b);
        assert_memory_equal(a.f, b.f, a.n * sizeof(double));
        assert_memory_equal(a.se, b.se, a.n * sizeof(double));
        profile_free(&a);
        profile_free(&b);
    }
}

/* Contact stress from per-atom stress x volume: uniform P0 and S0 give
 * P = P0 phi + kinetic, sxz = S0 phi (bulk), mu and I are written. */
static void test_contact_stress(void **state)
{
    (void)state;
    synth_opts o = base();
    o.a = 0;
    o.b = 0;
    o.nsnap = 4;
    o.with_stress = 1;
    o.P0 = 1000;
    o.S0 = 300;
    char dump[512], out[512];
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "stress.dump"), &o), 0);
    cg_run_opts ro = cg_opts_default();
    const char *in[1] = {dump};
    ro.inputs = in;
    ro.ninputs = 1;
    ro.out = tmp_path(out, sizeof out, "stress.h5");
    ro.width = 0.002;
    ro.bins = 20;
    ro.nstress = 6;
    const char *names[6] = {"c_s[1]", "c_s[2]", "c_s[3]", "c_s[4]", "c_s[5]", "c_s[6]"};
    for (int c = 0; c < 6; c++)
        ro.stress[c] = names[c];
    ekm_error err;
    if (cg_run(&ro, &err))
        fail_msg("%s", err.message);
    profile phi, P, sxz, mu;
    read_field(out, "phi", &phi);
    read_field(out, "P", &P);
    read_field(out, "sxz", &sxz);
    read_field(out, "mu", &mu);
    for (size_t k = 3; k + 3 < phi.n; k++) {
        double rho = phi.f[k] * o.rho_p;
        assert_close(P.f[k], o.P0 * phi.f[k] + rho * o.T0, 0.05 * o.P0 * phi.f[k]);
        assert_close(sxz.f[k], o.S0 * phi.f[k], 0.05 * o.S0 * phi.f[k]);
        assert_close(mu.f[k], fabs(sxz.f[k]) / P.f[k], 1e-12);
    }
    profile_free(&phi);
    profile_free(&P);
    profile_free(&sxz);
    profile_free(&mu);
}

/* Contacts: the same random packing written as an atom dump with per-atom
 * stress (each contact's -f b split half to each atom) and as pair dumps
 * (positions, and atom ids). Pair positions and ids give the same fields;
 * every form gives the same integral of szz over z (contact part exact:
 * the kernel weights of a contact sum to one); the sub-grid and the exact
 * kernel agree. */
static void write_packing(const char *atoms, const char *pos, const char *ids)
{
    enum { N = 400 };
    const double L = 0.01, H = 0.02, r = 0.0005, dc = 0.0022;
    static double x[N][3], S[N][6];
    gsl_rng *g = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(g, 11);
    for (int i = 0; i < N; i++) {
        x[i][0] = gsl_rng_uniform(g) * L;
        x[i][1] = gsl_rng_uniform(g) * L;
        x[i][2] = r + gsl_rng_uniform(g) * (H - 2 * r);
        for (int c = 0; c < 6; c++)
            S[i][c] = 0;
    }
    FILE *fp = fopen(pos, "w"), *fi = fopen(ids, "w");
    const char *hdr = "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ENTRIES\n%d\nITEM: BOX BOUNDS pp pp ff\n"
                      "0 0.01\n0 0.01\n0 0.02\n";
    /* count contacts first */
    int nc = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            fprintf(fp, hdr, nc);
            fprintf(fp, "ITEM: ENTRIES c_pc[1] c_pc[2] c_pc[3] c_pc[4] c_pc[5] c_pc[6] c_pc[7] c_pc[8] "
                        "c_pc[9] c_pc[10] c_pc[11] c_pc[12] \n");
            fprintf(fi, hdr, nc);
            fprintf(fi, "ITEM: ENTRIES c_pid[1] c_pid[2] c_pl[1] c_pl[2] c_pl[3] c_pl[4]\n");
        }
        for (int i = 0; i < N; i++)
            for (int j = i + 1; j < N; j++) {
                double b[3], d2 = 0, jimg[3];
                for (int c = 0; c < 3; c++) {
                    b[c] = x[i][c] - x[j][c];
                    if (c < 2)
                        b[c] -= L * nearbyint(b[c] / L);
                    jimg[c] = x[i][c] - b[c];
                    d2 += b[c] * b[c];
                }
                if (d2 > dc * dc)
                    continue;
                if (pass == 0) {
                    nc++;
                    continue;
                }
                double d = sqrt(d2), f[3];
                for (int c = 0; c < 3; c++)
                    f[c] = 1e-3 * b[c] / d + (c == 0 ? 2e-4 : 0.0);
                double t[6] = {-f[0] * b[0],
                               -f[1] * b[1],
                               -f[2] * b[2],
                               -0.5 * (f[0] * b[1] + f[1] * b[0]),
                               -0.5 * (f[0] * b[2] + f[2] * b[0]),
                               -0.5 * (f[1] * b[2] + f[2] * b[1])};
                for (int c = 0; c < 6; c++) {
                    S[i][c] += 0.5 * t[c];
                    S[j][c] += 0.5 * t[c];
                }
                /* LIGGGHTS writes the partner's own (wrapped) position, not its image:
                 * half the contacts as LIGGGHTS, half with the image */
                const double *xj = (i + j) % 2 ? x[j] : jimg;
                fprintf(fp, "%.17g %.17g %.17g %.17g %.17g %.17g %d %d 0 %.17g %.17g %.17g \n", x[i][0],
                        x[i][1], x[i][2], xj[0], xj[1], xj[2], i + 1, j + 1, f[0], f[1], f[2]);
                fprintf(fi, "%d %d %.17g %.17g %.17g %.17g\n", i + 1, j + 1, d, f[0], f[1], f[2]);
            }
    }
    fclose(fp);
    fclose(fi);
    fp = fopen(atoms, "w");
    fprintf(fp,
            "ITEM: TIME\n0.001\nITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n%d\nITEM: BOX BOUNDS pp pp ff\n"
            "0 0.01\n0 0.01\n0 0.02\nITEM: ATOMS id x y z vx vy vz radius mass c_s[1] c_s[2] c_s[3] c_s[4] "
            "c_s[5] c_s[6]\n",
            N);
    for (int i = 0; i < N; i++) {
        fprintf(fp, "%d %.17g %.17g %.17g 0 0 0 %g %g", i + 1, x[i][0], x[i][1], x[i][2], r,
                2500 * 4.18879 * r * r * r);
        for (int c = 0; c < 6; c++)
            fprintf(fp, " %.17g", S[i][c]);
        fputc('\n', fp);
    }
    fclose(fp);
    gsl_rng_free(g);
}

static void run_contacts(const char *atoms, const char *pairs, int idmode, int exact, const char *out)
{
    cg_run_opts o = cg_opts_default();
    const char *in[1] = {atoms}, *pin[1] = {pairs};
    static const char *posc[9] = {"c_pc[1]", "c_pc[2]",  "c_pc[3]",  "c_pc[4]", "c_pc[5]",
                                  "c_pc[6]", "c_pc[10]", "c_pc[11]", "c_pc[12]"};
    static const char *idc[5] = {"c_pid[1]", "c_pid[2]", "c_pl[2]", "c_pl[3]", "c_pl[4]"};
    static const char *sc[6] = {"c_s[1]", "c_s[2]", "c_s[3]", "c_s[4]", "c_s[5]", "c_s[6]"};
    o.inputs = in;
    o.ninputs = 1;
    o.out = out;
    o.width = 0.001;
    o.bins = 40;
    o.exact = exact;
    if (pairs) {
        o.pairs = pin;
        o.npairs = 1;
        o.npaircols = idmode ? 5 : 9;
        for (size_t j = 0; j < o.npaircols; j++)
            o.paircols[j] = idmode ? idc[j] : posc[j];
    } else {
        o.nstress = 6;
        for (int c = 0; c < 6; c++)
            o.stress[c] = sc[c];
    }
    ekm_error err;
    if (cg_run(&o, &err))
        fail_msg("%s", err.message);
}

static double integral(const profile *p)
{
    double s = 0, dz = p->z[1] - p->z[0];
    for (size_t k = 0; k < p->n; k++)
        s += p->f[k] * dz;
    return s;
}

static void test_pair_contacts(void **state)
{
    (void)state;
    char atoms[512], pos[512], ids[512], h[4][512];
    write_packing(tmp_path(atoms, sizeof atoms, "pk_atoms.dump"), tmp_path(pos, sizeof pos, "pk_pos.dump"),
                  tmp_path(ids, sizeof ids, "pk_ids.dump"));
    run_contacts(atoms, pos, 0, 0, tmp_path(h[0], sizeof h[0], "pk0.h5"));
    run_contacts(atoms, ids, 1, 0, tmp_path(h[1], sizeof h[1], "pk1.h5"));
    run_contacts(atoms, NULL, 0, 0, tmp_path(h[2], sizeof h[2], "pk2.h5"));
    run_contacts(atoms, pos, 0, 1, tmp_path(h[3], sizeof h[3], "pk3.h5"));
    const char *f[] = {"szz", "sxz", "P"};
    for (int i = 0; i < 3; i++) {
        profile a[4];
        for (int r = 0; r < 4; r++)
            read_field(h[r], f[i], &a[r]);
        double ref = integral(&a[2]);
        assert_true(fabs(ref) > 0);
        for (int r = 0; r < 4; r++)
            assert_close(integral(&a[r]), ref, 1e-9 * fabs(ref));
        for (size_t k = 0; k < a[0].n; k++) {
            assert_close(a[1].f[k], a[0].f[k], 1e-9 * fabs(ref) / 0.02);
            assert_close(a[3].f[k], a[0].f[k], 2e-3 * fabs(ref) / 0.02);
        }
        for (int r = 0; r < 4; r++)
            profile_free(&a[r]);
    }
}

/* Real dumps from the DEM decks (chute, LIGGGHTS and LAMMPS smoke runs,
 * last two snapshots, with their pair dumps): read, coarse-grained with
 * the contact stress from the pair dumps and from stress/atom, total mass
 * checked against the sum of the mass column. */
static double dump_mass(const char *path, int snap)
{
    gzFile gz = gzopen(path, "rb");
    assert_non_null(gz);
    char line[4096];
    int col = -1, in_atoms = 0, s = 0;
    double sum = 0;
    while (gzgets(gz, line, sizeof line)) {
        if (!strncmp(line, "ITEM: ATOMS", 11)) {
            s++;
            in_atoms = (s == snap);
            char *tok = strtok(line + 11, " \n");
            for (int c = 0; tok; c++, tok = strtok(NULL, " \n"))
                if (!strcmp(tok, "mass"))
                    col = c;
            continue;
        }
        if (!strncmp(line, "ITEM:", 5)) {
            in_atoms = 0;
            continue;
        }
        if (in_atoms) {
            char *p = line;
            for (int c = 0; c < col; c++)
                strtod(p, &p);
            sum += strtod(p, NULL);
        }
    }
    gzclose(gz);
    assert_true(col >= 0);
    return sum;
}

static void test_real_chute(void **state)
{
    (void)state;
    const char *eng[2] = {"liggghts", "lammps"};
    static const char *lig[9] = {"c_pc[1]", "c_pc[2]",  "c_pc[3]",  "c_pc[4]", "c_pc[5]",
                                 "c_pc[6]", "c_pc[10]", "c_pc[11]", "c_pc[12]"};
    static const char *lmp[5] = {"c_pid[1]", "c_pid[2]", "c_pl[2]", "c_pl[3]", "c_pl[4]"};
    static const char *sa[6] = {"c_sa[1]", "c_sa[2]", "c_sa[3]", "c_sa[4]", "c_sa[5]", "c_sa[6]"};
    for (int e = 0; e < 2; e++) {
        char atoms[512], pairs[512], out[512];
        snprintf(atoms, sizeof atoms, CG_FIXTURES "/chute_%s_atoms.dump.gz", eng[e]);
        snprintf(pairs, sizeof pairs, CG_FIXTURES "/chute_%s_pairs.dump.gz", eng[e]);
        for (int mode = 0; mode < 2; mode++) {
            cg_run_opts o = cg_opts_default();
            const char *in[1] = {atoms}, *pin[1] = {pairs};
            o.inputs = in;
            o.ninputs = 1;
            o.out = tmp_path(out, sizeof out, "chute.h5");
            o.select.dt = 1e-5; /* LIGGGHTS writes no ITEM: TIME */
            o.every = 1;
            if (mode == 0) {
                o.pairs = pin;
                o.npairs = 1;
                o.npaircols = e == 0 ? 9 : 5;
                for (size_t j = 0; j < o.npaircols; j++)
                    o.paircols[j] = e == 0 ? lig[j] : lmp[j];
            } else {
                o.nstress = 6;
                for (int c = 0; c < 6; c++)
                    o.stress[c] = sa[c];
            }
            ekm_error err;
            if (cg_run(&o, &err))
                fail_msg("%s: %s", eng[e], err.message);
            profile rho, phi, P;
            read_field(out, "rho", &rho);
            read_field(out, "phi", &phi);
            read_field(out, "P", &P);
            assert_int_equal(rho.nt, 2);
            double dz = rho.z[1] - rho.z[0], area = 0.016 * 0.012;
            for (size_t it = 0; it < 2; it++) {
                double m = 0;
                for (size_t k = 0; k < rho.n; k++)
                    m += rho.f[it * rho.n + k] * dz * area;
                double ref = dump_mass(atoms, (int)it + 1);
                assert_close(m, ref, 1e-9 * ref);
            }
            /* a dense flowing bed: phi near 0.59 and P > 0 at mid-depth (z = 2 cm) */
            for (size_t k = 0; k < phi.n; k++)
                if (fabs(phi.z[k] - 0.02) < 0.001) {
                    assert_true(phi.f[k] > 0.5 && phi.f[k] < 0.65);
                    assert_true(P.f[k] > 0);
                }
            profile_free(&rho);
            profile_free(&phi);
            profile_free(&P);
        }
    }
}

/* The LIGGGHTS deck's dump format (deck columns, c_sa stress, no TIME):
 * read, coarse-grained, total mass checked. */
static void test_deck_dump(void **state)
{
    (void)state;
    cg_run_opts o = cg_opts_default();
    const char *in[1] = {CG_FIXTURES "/liggghts_deck.dump"};
    char out[512];
    o.inputs = in;
    o.ninputs = 1;
    o.out = tmp_path(out, sizeof out, "deck.h5");
    o.select.dt = 1e-5;
    o.every = 1;
    o.nstress = 6;
    const char *names[6] = {"c_sa[1]", "c_sa[2]", "c_sa[3]", "c_sa[4]", "c_sa[5]", "c_sa[6]"};
    for (int c = 0; c < 6; c++)
        o.stress[c] = names[c];
    ekm_error err;
    if (cg_run(&o, &err))
        fail_msg("%s", err.message);
    /* total mass of the fixture: sum of its mass column */
    FILE *fp = fopen(CG_FIXTURES "/liggghts_deck.dump", "r");
    char line[1024];
    double mtot = 0;
    int in_atoms = 0, snap = 0;
    while (fgets(line, sizeof line, fp)) {
        if (!strncmp(line, "ITEM: ATOMS", 11)) {
            in_atoms = 1;
            snap++;
            continue;
        }
        if (!strncmp(line, "ITEM:", 5)) {
            in_atoms = 0;
            continue;
        }
        if (in_atoms && snap == 1) {
            double v[10];
            sscanf(line, "%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                   &v[6], &v[7], &v[8], &v[9]);
            mtot += v[9];
        }
    }
    fclose(fp);
    profile p;
    read_field(out, "rho", &p);
    assert_int_equal(p.nt, 3);
    assert_close(p.t[2], 2000 * 1e-5, 1e-15);
    double dz = p.z[1] - p.z[0];
    for (size_t it = 0; it < p.nt; it++) {
        double sum = 0;
        for (size_t k = 0; k < p.n; k++)
            sum += p.f[it * p.n + k] * dz * 0.01 * 0.01;
        assert_close(sum, mtot, 1e-5 * mtot); /* masses printed with 6 digits */
    }
    profile_free(&p);
    read_field(out, "mu", &p);
    profile_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_recovery),         cmocka_unit_test(test_shear_temperatures),
        cmocka_unit_test(test_steady_multifile), cmocka_unit_test(test_mass_identity),
        cmocka_unit_test(test_subgrid_vs_exact), cmocka_unit_test(test_galilean),
        cmocka_unit_test(test_shuffled_columns), cmocka_unit_test(test_contact_stress),
        cmocka_unit_test(test_deck_dump),        cmocka_unit_test(test_pair_contacts),
        cmocka_unit_test(test_real_chute),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
