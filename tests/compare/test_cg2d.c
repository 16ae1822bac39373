/* test_cg2d.c: `ekmcompare cg --axes x,z` and `ekmcompare base` against
 * exact identities on synthetic dumps (fixed seeds): mass and volume
 * conservation of the 2D grid to round-off, the 1D profile recovered from
 * the 2D grid averaged over x, the ensemble's mean and SE across runs,
 * and the base pressure of a synthetic hydrostatic pile recovered exactly
 * with its two standard errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>

#include "pile_base.h"
#include "cg_run.h"
#include "dump.h"
#include "h5.h"
#include "synth.h"
#include "test_util.h"

#define PI 3.14159265358979323846

/* A dataset of an output, any rank; *count values. */
static double *read_data(const char *path, const char *name, size_t dims[EKM_H5_MAX_RANK], int *rank)
{
    ekm_h5_file *r;
    ekm_error err;
    double *data = NULL;
    assert_int_equal(ekm_h5_open(&r, path, &err), EKM_OK);
    if (ekm_h5_read_double(r, name, rank, dims, &data, &err))
        fail_msg("%s", err.message);
    ekm_h5_close(r);
    return data;
}

static double read_attr(const char *path, const char *name)
{
    ekm_h5_file *r;
    ekm_error err;
    double v = NAN;
    assert_int_equal(ekm_h5_open(&r, path, &err), EKM_OK);
    if (ekm_h5_attr_get_double(r, NULL, name, &v, &err))
        fail_msg("%s", err.message);
    ekm_h5_close(r);
    return v;
}

/* A 2D field [nt][nz][nx]. */
typedef struct {
    size_t nt, nz, nx;
    double *f;
} grid2d;

static grid2d read2d(const char *path, const char *name)
{
    size_t dims[EKM_H5_MAX_RANK];
    int rank;
    grid2d g;
    g.f = read_data(path, name, dims, &rank);
    assert_int_equal(rank, 3);
    g.nt = dims[0];
    g.nz = dims[1];
    g.nx = dims[2];
    return g;
}

/* A 1D profile [nt][nz]. */
static double *read1d(const char *path, const char *name, size_t *nt, size_t *nz)
{
    size_t dims[EKM_H5_MAX_RANK];
    int rank;
    double *f = read_data(path, name, dims, &rank);
    assert_int_equal(rank, 2);
    *nt = dims[0];
    *nz = dims[1];
    return f;
}

static void run(cg_run_opts *o, const char *const *in, size_t nin, const char *out)
{
    o->inputs = in;
    o->ninputs = nin;
    o->out = out;
    ekm_error err;
    if (cg_run(o, &err))
        fail_msg("cg_run: %s", err.message);
}

static synth_opts dump2d(void)
{
    synth_opts o = synth_default();
    o.natoms = 1500;
    o.nsnap = 4;
    o.lx = 0.03;
    o.ly = 0.006;
    o.lz = 0.02;
    o.a = 0.6;
    o.ax = -0.8;
    o.gdot = 5.0;
    o.T0 = 2e-3;
    o.b = 0.5;
    o.u0 = 0.1;
    o.v0 = 0.02;
    o.with_stress = 1;
    o.P0 = 40.0;
    o.S0 = 7.0;
    return o;
}

/* The integral of rho over the grid times L_y is the total mass, of phi
 * the total volume, to round-off: periodic x, walls (reflection) in x and
 * z, both kernels, every window. */
static void test_mass_volume(void **state)
{
    (void)state;
    char dump[512], out[512];
    for (int walls = 0; walls < 2; walls++)
        for (int ik = 0; ik < 2; ik++) {
            synth_opts so = dump2d();
            so.xwalls = walls;
            assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "cg2d_mass.dump"), &so), 0);
            cg_run_opts o = cg_opts_default();
            o.axis2 = 0;
            o.kernel = ik ? "lucy" : "gauss";
            o.width = 0.0025;
            o.every = 2;
            const char *in[1] = {dump};
            run(&o, in, 1, tmp_path(out, sizeof out, "cg2d_mass.h5"));
            /* the dump's values: radius and mass as written (%.9g) */
            char buf[64];
            snprintf(buf, sizeof buf, "%.9g", so.radius);
            double r = strtod(buf, NULL), vol = 4.0 / 3.0 * PI * r * r * r;
            snprintf(buf, sizeof buf, "%.9g", so.rho_p * 4.0 / 3.0 * PI * pow(so.radius, 3));
            double mass = strtod(buf, NULL) * (double)so.natoms;
            double dx = read_attr(out, "dx"), dz = read_attr(out, "dz"),
                   ly = read_attr(out, "averaged_length");
            assert_close(ly, so.ly, 1e-15);
            grid2d rho = read2d(out, "rho"), phi = read2d(out, "phi");
            assert_int_equal(rho.nt, 2);
            for (size_t it = 0; it < rho.nt; it++) {
                double m = 0.0, v = 0.0;
                size_t nc = rho.nz * rho.nx;
                for (size_t c = 0; c < nc; c++) {
                    m += rho.f[it * nc + c] * dx * dz * ly;
                    v += phi.f[it * nc + c] * dx * dz * ly;
                }
                assert_close(m, mass, 1e-12 * mass);
                assert_close(v, vol * (double)so.natoms, 1e-12 * vol * (double)so.natoms);
            }
            free(rho.f);
            free(phi.f);
        }
}

/* Mean over x of field f of a 2D output at (it, iz). */
static double xmean(const grid2d *g, size_t it, size_t iz, const double *f)
{
    double s = 0.0;
    for (size_t ix = 0; ix < g->nx; ix++)
        s += f[(it * g->nz + iz) * g->nx + ix];
    return s / (double)g->nx;
}

/* The 1D profile (exact kernel) is the 2D grid averaged over x: rho and
 * phi directly; momentum rho V, the second moments and the stresses
 * through the kernel sums they are made of (consistent temperature:
 * K = sum m v v W - rho V V in both), to round-off. One snapshot: a
 * window's K is the mean of its snapshots' K, each with its own V. */
static void test_1d_from_2d(void **state)
{
    (void)state;
    char dump[512], out1[512], out2[512];
    synth_opts so = dump2d();
    so.nsnap = 1;
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "cg2d_1d.dump"), &so), 0);
    const char *in[1] = {dump};
    const char *stress[6] = {"c_s[1]", "c_s[2]", "c_s[3]", "c_s[4]", "c_s[5]", "c_s[6]"};
    for (int ik = 0; ik < 2; ik++) {
        const char *kernel = ik ? "lucy" : "gauss";
        cg_run_opts o1 = cg_opts_default();
        o1.exact = 1;
        o1.kernel = kernel;
        o1.tmode = CG_T_CONSISTENT;
        o1.nstress = 6;
        for (int c = 0; c < 6; c++)
            o1.stress[c] = stress[c];
        cg_run_opts o2 = o1;
        o2.axis2 = 0;
        run(&o1, in, 1, tmp_path(out1, sizeof out1, "cg2d_1d_a.h5"));
        run(&o2, in, 1, tmp_path(out2, sizeof out2, "cg2d_1d_b.h5"));
        size_t nt, nz;
        double *rho1 = read1d(out1, "rho", &nt, &nz), *phi1 = read1d(out1, "phi", &nt, &nz);
        double *vx1 = read1d(out1, "vx", &nt, &nz), *vz1 = read1d(out1, "vz", &nt, &nz);
        double *vy1 = read1d(out1, "vy", &nt, &nz), *T1 = read1d(out1, "T", &nt, &nz);
        double *szz1 = read1d(out1, "szz", &nt, &nz), *sxz1 = read1d(out1, "sxz", &nt, &nz);
        double *P1 = read1d(out1, "P", &nt, &nz);
        grid2d rho = read2d(out2, "rho"), phi = read2d(out2, "phi"), vx = read2d(out2, "vx"),
               vy = read2d(out2, "vy"), vz = read2d(out2, "vz"), T = read2d(out2, "T"),
               szz = read2d(out2, "szz"), sxz = read2d(out2, "sxz"), P = read2d(out2, "P");
        assert_int_equal(rho.nz, nz);
        assert_int_equal(rho.nt, nt);
        size_t nc = rho.nz * rho.nx;
        double *w = malloc(8 * nc * sizeof *w); /* per cell: rho vx, rho vz, 2nd moments, stresses */
        double rmax = 0.0, smax = 0.0, emax = 0.0;
        for (size_t k = 0; k < nz; k++) {
            rmax = fmax(rmax, rho1[k]);
            smax = fmax(smax, fabs(szz1[k]));
            emax = fmax(emax, 3.0 * rho1[k] * T1[k]);
        }
        for (size_t c = 0; c < nc; c++) {
            double r = rho.f[c], ok = r > 0;
            double ux = ok ? vx.f[c] : 0, uy = ok ? vy.f[c] : 0, uz = ok ? vz.f[c] : 0,
                   u2 = ux * ux + uy * uy + uz * uz;
            w[0 * nc + c] = r * ux;
            w[1 * nc + c] = r * uz;
            w[2 * nc + c] = ok ? 3.0 * r * T.f[c] + r * u2 : 0.0; /* tr of sum m v v W / L */
            w[3 * nc + c] = szz.f[c] - r * uz * uz;               /* -M_zz + S_zz */
            w[4 * nc + c] = sxz.f[c] - r * ux * uz;               /* -M_xz + S_xz */
            w[5 * nc + c] = P.f[c] + r * u2 / 3.0;                /* (tr M - tr S)/3 */
        }
        for (size_t k = 0; k < nz; k++) {
            double u2 = vx1[k] * vx1[k] + vy1[k] * vy1[k] + vz1[k] * vz1[k];
            assert_close(xmean(&rho, 0, k, rho.f), rho1[k], 1e-12 * rmax);
            assert_close(xmean(&phi, 0, k, phi.f), phi1[k], 1e-12 * rmax / so.rho_p);
            assert_close(xmean(&rho, 0, k, w), rho1[k] * vx1[k], 1e-12 * rmax * 1.0);
            assert_close(xmean(&rho, 0, k, w + nc), rho1[k] * vz1[k], 1e-12 * rmax * 1.0);
            assert_close(xmean(&rho, 0, k, w + 2 * nc), 3.0 * rho1[k] * T1[k] + rho1[k] * u2, 1e-10 * emax);
            assert_close(xmean(&rho, 0, k, w + 3 * nc), szz1[k] - rho1[k] * vz1[k] * vz1[k], 1e-10 * smax);
            assert_close(xmean(&rho, 0, k, w + 4 * nc), sxz1[k] - rho1[k] * vx1[k] * vz1[k], 1e-10 * smax);
            assert_close(xmean(&rho, 0, k, w + 5 * nc), P1[k] + rho1[k] * u2 / 3.0, 1e-10 * smax);
        }
        free(w);
        double *a1[] = {rho1, phi1, vx1, vy1, vz1, T1, szz1, sxz1, P1};
        for (size_t i = 0; i < sizeof a1 / sizeof a1[0]; i++)
            free(a1[i]);
        grid2d *a2[] = {&rho, &phi, &vx, &vy, &vz, &T, &szz, &sxz, &P};
        for (size_t i = 0; i < sizeof a2 / sizeof a2[0]; i++)
            free(a2[i]->f);
    }
}

/* The particle temperature (fluctuations about V interpolated at the
 * particle, the default) of the 2D grid, mass-averaged over x, is the 1D
 * one within 3% in the bulk (the 2D V follows the flow more closely and
 * subtracts a little more noise: T low by ~T/N_eff per cell). */
static void test_particle_temperature(void **state)
{
    (void)state;
    char dump[512], out1[512], out2[512];
    synth_opts so = dump2d();
    so.natoms = 6000;
    assert_int_equal(synth_write(tmp_path(dump, sizeof dump, "cg2d_T.dump"), &so), 0);
    const char *in[1] = {dump};
    cg_run_opts o1 = cg_opts_default();
    o1.exact = 1;
    o1.width = 0.003;
    cg_run_opts o2 = o1;
    o2.axis2 = 0;
    run(&o1, in, 1, tmp_path(out1, sizeof out1, "cg2d_T_a.h5"));
    run(&o2, in, 1, tmp_path(out2, sizeof out2, "cg2d_T_b.h5"));
    size_t nt, nz;
    double *T1 = read1d(out1, "T", &nt, &nz);
    grid2d rho = read2d(out2, "rho"), T = read2d(out2, "T");
    double *z = read_data(out1, "z", (size_t[EKM_H5_MAX_RANK]){0}, &(int){0});
    for (size_t k = 0; k < nz; k++) {
        if (z[k] < 0.005 || z[k] > so.lz - 0.005)
            continue;
        double num = 0, den = 0;
        for (size_t ix = 0; ix < T.nx; ix++) {
            size_t c = k * T.nx + ix;
            num += rho.f[c] * T.f[c];
            den += rho.f[c];
        }
        assert_close(num / den, T1[k], 0.03 * T1[k]);
    }
    free(T1);
    free(z);
    free(rho.f);
    free(T.f);
}

/* --ensemble of two runs: rho is the mean of the runs' rho, vx the
 * ensemble's momentum over its density, and every SE that of two values,
 * |a - b|/2, exactly. */
static void test_ensemble(void **state)
{
    (void)state;
    char d1[512], d2[512], o1[512], o2[512], oe[512];
    synth_opts so = dump2d();
    assert_int_equal(synth_write(tmp_path(d1, sizeof d1, "cg2d_ens1.dump"), &so), 0);
    so.seed = 4242;
    so.u0 = 0.3;
    assert_int_equal(synth_write(tmp_path(d2, sizeof d2, "cg2d_ens2.dump"), &so), 0);
    cg_run_opts o = cg_opts_default();
    o.axis2 = 0;
    o.width = 0.0025;
    const char *in1[1] = {d1}, *in2[1] = {d2}, *both[2] = {d1, d2};
    run(&o, in1, 1, tmp_path(o1, sizeof o1, "cg2d_ens1.h5"));
    run(&o, in2, 1, tmp_path(o2, sizeof o2, "cg2d_ens2.h5"));
    o.ensemble = 1;
    run(&o, both, 2, tmp_path(oe, sizeof oe, "cg2d_ens.h5"));
    assert_close(read_attr(oe, "runs"), 2, 0);
    assert_close(read_attr(oe, "snapshots_used"), 2.0 * (double)so.nsnap, 0);
    grid2d r1 = read2d(o1, "rho"), r2 = read2d(o2, "rho"), re = read2d(oe, "rho"), rse = read2d(oe, "rho_se");
    grid2d v1 = read2d(o1, "vx"), v2 = read2d(o2, "vx"), ve = read2d(oe, "vx"), vse = read2d(oe, "vx_se");
    assert_int_equal(re.nt, 1);
    size_t nc = re.nz * re.nx, nfinite = 0;
    double rmax = 0;
    for (size_t c = 0; c < nc; c++)
        rmax = fmax(rmax, re.f[c]);
    for (size_t c = 0; c < nc; c++) {
        assert_close(re.f[c], 0.5 * (r1.f[c] + r2.f[c]), 1e-13 * rmax);
        assert_close(rse.f[c], 0.5 * fabs(r1.f[c] - r2.f[c]), 1e-13 * rmax);
        if (r1.f[c] > 0 && r2.f[c] > 0) {
            double p = (r1.f[c] * v1.f[c] + r2.f[c] * v2.f[c]) / (r1.f[c] + r2.f[c]);
            assert_close(ve.f[c], p, 1e-12);
            assert_close(vse.f[c], 0.5 * fabs(v1.f[c] - v2.f[c]), 1e-12);
            nfinite++;
        }
    }
    assert_true(nfinite > nc / 2);
    grid2d *all[] = {&r1, &r2, &re, &rse, &v1, &v2, &ve, &vse};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        free(all[i]->f);
}

/* One run of 4 snapshots: 4 blocks of one snapshot, below the 8 blocks of
 * a blocking level, so rho_se is the plain SE of the 4 snapshots' rho and
 * vx_se that of their vx (each from its own snapshot), exactly. */
static void test_window_se(void **state)
{
    (void)state;
    char d[512], o[512], os[4][512];
    synth_opts so = dump2d();
    assert_int_equal(synth_write(tmp_path(d, sizeof d, "cg2d_se.dump"), &so), 0);
    const char *in[1] = {d};
    cg_run_opts opt = cg_opts_default();
    opt.axis2 = 0;
    opt.width = 0.0025;
    run(&opt, in, 1, tmp_path(o, sizeof o, "cg2d_se.h5"));
    grid2d rho = read2d(o, "rho"), rse = read2d(o, "rho_se"), vse = read2d(o, "vx_se"), r[4], v[4];
    opt.select.have_steps = 1;
    for (int j = 0; j < 4; j++) {
        char name[64];
        snprintf(name, sizeof name, "cg2d_se%d.h5", j);
        opt.select.step_a = opt.select.step_b = so.step0 + j * so.dstep;
        run(&opt, in, 1, tmp_path(os[j], sizeof os[j], name));
        r[j] = read2d(os[j], "rho");
        v[j] = read2d(os[j], "vx");
    }
    size_t nc = rho.nz * rho.nx, checked = 0;
    double rmax = 0;
    for (size_t c = 0; c < nc; c++)
        rmax = fmax(rmax, rho.f[c]);
    for (size_t c = 0; c < nc; c++) {
        double m = 0, s = 0, mv = 0, sv = 0;
        int allv = 1;
        for (int j = 0; j < 4; j++) {
            m += r[j].f[c] / 4;
            allv &= isfinite(v[j].f[c]);
            mv += v[j].f[c] / 4;
        }
        for (int j = 0; j < 4; j++) {
            s += (r[j].f[c] - m) * (r[j].f[c] - m);
            sv += (v[j].f[c] - mv) * (v[j].f[c] - mv);
        }
        assert_close(rho.f[c], m, 1e-13 * rmax);
        assert_close(rse.f[c], sqrt(s / 3 / 4), 1e-12 * rmax);
        if (allv) {
            assert_close(vse.f[c], sqrt(sv / 3 / 4), 1e-12);
            checked++;
        }
    }
    assert_true(checked > nc / 2);
    free(rho.f);
    free(rse.f);
    free(vse.f);
    for (int j = 0; j < 4; j++) {
        free(r[j].f);
        free(v[j].f);
    }
}

/* Contact stress from a pair dump (the LIGGGHTS chute fixture, positions
 * mode): the integral of cxx, czz, cxz over the grid times L_y is, for
 * each snapshot, the sum over contacts of -f_x b_x, -f_z b_z,
 * -(f_x b_z + f_z b_x)/2 with b the minimum-image branch vector: the
 * branch line integral conserves the contact stress to round-off. */
static void test_pair_contacts(void **state)
{
    (void)state;
    static const char *cols[9] = {"c_pc[1]", "c_pc[2]",  "c_pc[3]",  "c_pc[4]", "c_pc[5]",
                                  "c_pc[6]", "c_pc[10]", "c_pc[11]", "c_pc[12]"};
    const char *atoms = CG_FIXTURES "/chute_liggghts_atoms.dump.gz",
               *pairs = CG_FIXTURES "/chute_liggghts_pairs.dump.gz";
    char out[512];
    cg_run_opts o = cg_opts_default();
    o.axis2 = 0;
    o.select.dt = 1e-5;
    o.every = 1;
    o.pairs = (const char *const[1]){pairs};
    o.npairs = 1;
    o.npaircols = 9;
    for (int j = 0; j < 9; j++)
        o.paircols[j] = cols[j];
    run(&o, (const char *const[1]){atoms}, 1, tmp_path(out, sizeof out, "cg2d_pairs.h5"));
    grid2d cxx = read2d(out, "cxx"), czz = read2d(out, "czz"), cxz = read2d(out, "cxz");
    double dx = read_attr(out, "dx"), dz = read_attr(out, "dz"), ly = read_attr(out, "averaged_length");
    assert_int_equal(czz.nt, 2);
    cg_dump *d;
    cg_snapshot sn;
    memset(&sn, 0, sizeof sn);
    ekm_error err;
    assert_int_equal(cg_dump_open(&d, pairs, cols, 9, &err), EKM_OK);
    for (size_t it = 0; it < 2; it++) {
        assert_int_equal(cg_dump_next(d, &sn, &err), EKM_OK);
        double want[3] = {0, 0, 0}, got[3] = {0, 0, 0};
        for (size_t k = 0; k < (size_t)sn.natoms; k++) {
            const double *row = sn.data + k * sn.nsel;
            double b[3];
            for (int c = 0; c < 3; c++) {
                double L = sn.hi[c] - sn.lo[c];
                b[c] = row[c] - row[3 + c];
                if (sn.periodic[c])
                    b[c] -= L * nearbyint(b[c] / L);
            }
            want[0] += -row[6] * b[0];
            want[1] += -row[8] * b[2];
            want[2] += -0.5 * (row[6] * b[2] + row[8] * b[0]);
        }
        size_t nc = czz.nz * czz.nx;
        for (size_t c = 0; c < nc; c++) {
            got[0] += cxx.f[it * nc + c] * dx * dz * ly;
            got[1] += czz.f[it * nc + c] * dx * dz * ly;
            got[2] += cxz.f[it * nc + c] * dx * dz * ly;
        }
        for (int q = 0; q < 3; q++)
            assert_close(got[q], want[q], 1e-11 * fabs(want[1]));
        assert_true(want[1] < 0); /* compression */
    }
    cg_dump_close(d);
    cg_snapshot_free(&sn);
    free(cxx.f);
    free(czz.f);
    free(cxz.f);
}

static void run_base(cg_base_opts *o, const char *const *in, size_t nin, const char *out)
{
    o->inputs = in;
    o->ninputs = nin;
    o->out = out;
    o->log = NULL;
    ekm_error err;
    if (cg_base_run(o, &err))
        fail_msg("cg_base_run: %s", err.message);
}

/* Expected p of bin [lo, lo + dx): the mean of p over the lattice sites
 * inside (what the floor load of those sites represents). */
static double bin_p(const synth_pile_opts *so, double lo, double dx)
{
    double a = so->lx / (double)so->nfx, s = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < so->nfx; i++) {
        double x = ((double)i + 0.5) * a;
        if (x >= lo && x < lo + dx) {
            s += synth_pile_p(so, x);
            n++;
        }
    }
    return n ? s / (double)n : NAN;
}

/* A hydrostatic wedge: the floor load of every site is the weight of the
 * column above it; p(x) is recovered exactly (round-off), the pile grains'
 * forces do not count, a symmetric pile has fold SE 0, one run has no
 * ensemble SE; with two runs of loads (1 +- eps) the mean is the
 * unperturbed p and the SE eps p; a tilted pile's fold SE is
 * |p(x_c + s) - p(x_c - s)|/2. */
static void test_base_hydrostatic(void **state)
{
    (void)state;
    char d1[512], d2[512], d3[512], out[512];
    synth_pile_opts so = synth_pile_default();
    assert_int_equal(synth_pile_write(tmp_path(d1, sizeof d1, "pile1.dump"), &so), 0);
    cg_base_opts o = cg_base_opts_default();
    o.dx = 0.008; /* 4 lattice sites per bin */
    const char *one[1] = {d1};
    run_base(&o, one, 1, tmp_path(out, sizeof out, "pile1.h5"));
    size_t dims[EKM_H5_MAX_RANK];
    int rank;
    double *x = read_data(out, "x", dims, &rank), *p = read_data(out, "p_base", dims, &rank);
    double *se = read_data(out, "p_base_se", dims, &rank),
           *fold = read_data(out, "p_base_se_fold", dims, &rank);
    size_t n = dims[0];
    assert_int_equal(n, 20);
    double pmax = so.rho_bulk * so.g * so.height;
    for (size_t k = 0; k < n; k++) {
        assert_close(p[k], bin_p(&so, x[k] - 0.004, 0.008), 1e-12 * pmax);
        assert_close(fold[k], 0.0, 1e-12 * pmax);
        assert_true(isnan(se[k]));
    }
    /* the whole floor load is the pile's weight: sum of p dx L_y */
    double load = 0.0;
    for (size_t i = 0; i < so.nfx; i++)
        load +=
            synth_pile_p(&so, ((double)i + 0.5) * so.lx / (double)so.nfx) * so.lx / (double)so.nfx * so.ly;
    assert_close(read_attr(out, "floor_load"), load, 1e-12 * load);
    free(p);
    free(se);
    free(fold);

    /* two runs, loads x (1 + eps) and x (1 - eps), and a tilted one alone */
    so.eps = 0.1;
    assert_int_equal(synth_pile_write(tmp_path(d2, sizeof d2, "pile2.dump"), &so), 0);
    so.eps = -0.1;
    so.seed = 99;
    assert_int_equal(synth_pile_write(tmp_path(d3, sizeof d3, "pile3.dump"), &so), 0);
    const char *two[2] = {d2, d3};
    run_base(&o, two, 2, out);
    p = read_data(out, "p_base", dims, &rank);
    se = read_data(out, "p_base_se", dims, &rank);
    double *runs = read_data(out, "p_base_runs", dims, &rank);
    assert_int_equal(rank, 2);
    assert_int_equal(dims[0], 2);
    so.eps = 0.0;
    for (size_t k = 0; k < n; k++) {
        double want = bin_p(&so, x[k] - 0.004, 0.008);
        assert_close(p[k], want, 1e-12 * pmax);
        assert_close(se[k], 0.1 * want, 1e-12 * pmax);
        assert_close(runs[k], 1.1 * want, 1e-12 * pmax);
    }
    free(p);
    free(se);
    free(runs);
    so.tilt = 0.2;
    assert_int_equal(synth_pile_write(d2, &so), 0);
    run_base(&o, (const char *const[1]){d2}, 1, out);
    fold = read_data(out, "p_base_se_fold", dims, &rank);
    for (size_t k = 0; k < n; k++) {
        double a = bin_p(&so, x[k] - 0.004, 0.008), b = bin_p(&so, x[n - 1 - k] - 0.004, 0.008);
        assert_close(fold[k], 0.5 * fabs(a - b), 1e-12 * pmax);
    }
    free(fold);
    free(x);
}

/* --last N averages the last N selected snapshots, --steps selects;
 * --centre with a symmetric --range sets the grid (and the fold). */
static void test_base_selection(void **state)
{
    (void)state;
    char d[512], out[512];
    synth_pile_opts so = synth_pile_default();
    so.eps_step = 0.05; /* snapshots 0, 1, 2: loads x 1, 1.05, 1.10 */
    so.tilt = 0.3;
    assert_int_equal(synth_pile_write(tmp_path(d, sizeof d, "pile_sel.dump"), &so), 0);
    const char *one[1] = {d};
    const double factor[4] = {1.05, 1.10, 1.075, 1.05}; /* all, --last 1, --last 2, --steps 1000:1000 */
    so.eps_step = 0.0;
    for (int mode = 0; mode < 4; mode++) {
        cg_base_opts o = cg_base_opts_default();
        o.dx = 0.008;
        o.last = mode == 1 ? 1 : mode == 2 ? 2 : 0;
        if (mode == 3) {
            o.select.have_steps = 1;
            o.select.step_a = o.select.step_b = 1000;
            o.have_centre = 1;
            o.centre = 0.08;
            o.have_range = 1;
            o.range_lo = 0.02;
            o.range_hi = 0.14;
        }
        run_base(&o, one, 1, tmp_path(out, sizeof out, "pile_sel.h5"));
        size_t dims[EKM_H5_MAX_RANK];
        int rank;
        double *x = read_data(out, "x", dims, &rank), *p = read_data(out, "p_base", dims, &rank);
        double *fold = read_data(out, "p_base_se_fold", dims, &rank);
        size_t n = dims[0];
        assert_int_equal(n, mode == 3 ? 15 : 20);
        assert_close(read_attr(out, "snapshots_used"), mode == 0 ? 3 : mode == 3 ? 1 : (double)o.last, 0);
        double pmax = so.rho_bulk * so.g * so.height;
        for (size_t k = 0; k < n; k++) {
            double a = bin_p(&so, x[k] - 0.004, 0.008), b = bin_p(&so, x[n - 1 - k] - 0.004, 0.008);
            assert_close(p[k], factor[mode] * a, 1e-12 * pmax);
            assert_close(fold[k], 0.5 * factor[mode] * fabs(a - b), 1e-12 * pmax);
        }
        free(x);
        free(p);
        free(fold);
    }
}

/* --floor-type picks the floor; a type with no atom is an error, as is a
 * dump without fz (the decks must dump fx fy fz). */
static void test_base_bad_input(void **state)
{
    (void)state;
    char d[512], out[512];
    synth_pile_opts so = synth_pile_default();
    so.with_fz = 0;
    assert_int_equal(synth_pile_write(tmp_path(d, sizeof d, "pile_nofz.dump"), &so), 0);
    cg_base_opts o = cg_base_opts_default();
    o.inputs = (const char *const[1]){d};
    o.ninputs = 1;
    o.out = tmp_path(out, sizeof out, "pile_nofz.h5");
    ekm_error err;
    assert_int_equal(cg_base_run(&o, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "no column 'fz'"));
    assert_non_null(strstr(err.message, "pile_nofz.dump:9"));
    so.with_fz = 1;
    assert_int_equal(synth_pile_write(d, &so), 0);
    o.floor_type = 3;
    assert_int_equal(cg_base_run(&o, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "type 3"));
    FILE *fp = fopen(out, "r");
    assert_null(fp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mass_volume),
        cmocka_unit_test(test_1d_from_2d),
        cmocka_unit_test(test_particle_temperature),
        cmocka_unit_test(test_ensemble),
        cmocka_unit_test(test_window_se),
        cmocka_unit_test(test_pair_contacts),
        cmocka_unit_test(test_base_hydrostatic),
        cmocka_unit_test(test_base_selection),
        cmocka_unit_test(test_base_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
