/* synth.c: synthetic particle dumps (see synth.h). */
#include "synth.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#define PI 3.14159265358979323846

synth_opts synth_default(void)
{
    synth_opts o;
    memset(&o, 0, sizeof o);
    o.natoms = 2000;
    o.nsnap = 10;
    o.seed = 42;
    o.lx = o.ly = 0.02;
    o.lz = 0.04;
    o.radius = 0.001;
    o.rho_p = 2500;
    o.T0 = 1e-3;
    o.with_mass = 1;
    o.dt = 1e-5;
    o.step0 = 0;
    o.dstep = 1000;
    return o;
}

double synth_rho(const synth_opts *o, double z)
{
    double m = o->rho_p * 4.0 / 3.0 * PI * pow(o->radius, 3);
    double p = (1.0 + o->a * (z / o->lz - 0.5)) / o->lz;
    return (double)o->natoms * m * p / (o->lx * o->ly);
}

/* z from p(z) ~ 1 + a (z/lz - 1/2) by inverting the CDF. */
static double draw_z(const synth_opts *o, double u)
{
    double a = o->a;
    if (fabs(a) < 1e-12)
        return u * o->lz;
    /* CDF(x) = x (1 - a/2) + a x^2/2, x = z/lz */
    double A = 0.5 * a, B = 1.0 - 0.5 * a;
    double x = (-B + sqrt(B * B + 4.0 * A * u)) / (2.0 * A);
    return x * o->lz;
}

/* x from p(x) ~ 1 + ax (x/lx - 1/2), as draw_z. */
static double draw_x(const synth_opts *o, double u)
{
    double A = 0.5 * o->ax, B = 1.0 - 0.5 * o->ax;
    return (-B + sqrt(B * B + 4.0 * A * u)) / (2.0 * A) * o->lx;
}

typedef struct {
    FILE *fp;
    gzFile gz;
    char *buf;
    size_t len, cap;
} out_t;

static void put(out_t *w, const void *p, size_t n)
{
    if (w->len + n > w->cap) {
        while (w->len + n > w->cap)
            w->cap = w->cap ? 2 * w->cap : 1 << 20;
        w->buf = realloc(w->buf, w->cap);
    }
    memcpy(w->buf + w->len, p, n);
    w->len += n;
}

static void putf(out_t *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
#include <stdarg.h>
static void putf(out_t *w, const char *fmt, ...)
{
    char tmp[1024];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    put(w, tmp, (size_t)n);
}

static int flush(out_t *w)
{
    int ok = 1;
    if (w->gz)
        ok = gzwrite(w->gz, w->buf, (unsigned)w->len) == (int)w->len;
    else
        ok = fwrite(w->buf, 1, w->len, w->fp) == w->len;
    w->len = 0;
    return ok ? 0 : 1;
}

int synth_write(const char *path, const synth_opts *o)
{
    out_t w;
    memset(&w, 0, sizeof w);
    if (o->format == SYNTH_GZ)
        w.gz = gzopen(path, "wb6");
    else
        w.fp = fopen(path, "wb");
    if (!w.fp && !w.gz)
        return 1;
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, o->seed);
    double vol = 4.0 / 3.0 * PI * pow(o->radius, 3), m = o->rho_p * vol;
    const char *fmt = o->liggghts ? "%.6g" : "%.9g";
    size_t n = o->natoms;
    double *rows = malloc((n ? n : 1) * 20 * sizeof *rows);
    int rc = 0;
    for (size_t s = 0; s < o->nsnap && !rc; s++) {
        int64_t step = o->step0 + (int64_t)s * o->dstep;
        /* values per atom, in the canonical order:
         * 0 id 1 type 2 x 3 y 4 z 5 vx 6 vy 7 vz 8 radius 9 mass 10 fx 11..16 c_s[1..6] */
        for (size_t i = 0; i < n; i++) {
            double *q = rows + 20 * i;
            double z = draw_z(o, gsl_rng_uniform(r));
            double T = o->T0 * (1.0 + o->b * (z / o->lz - 0.5)), sd = sqrt(T);
            q[0] = (double)(i + 1);
            q[1] = 1;
            q[2] = o->ax == 0.0 ? gsl_rng_uniform(r) * o->lx : draw_x(o, gsl_rng_uniform(r));
            q[3] = gsl_rng_uniform(r) * o->ly;
            q[4] = z;
            q[5] = o->u0 + o->gdot * (z - 0.5 * o->lz) + gsl_ran_gaussian(r, sd);
            q[6] = o->v0 + gsl_ran_gaussian(r, sd);
            q[7] = o->v0 + gsl_ran_gaussian(r, sd);
            q[8] = o->radius;
            q[9] = m;
            q[10] = gsl_ran_gaussian(r, 1e-3);
            q[11] = -o->P0 * vol;
            q[12] = -o->P0 * vol;
            q[13] = -o->P0 * vol;
            q[14] = 0.0;
            q[15] = o->S0 * vol;
            q[16] = 0.0;
        }
        /* column order */
        static const int plain[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14, 15, 16};
        static const char *const pname[] = {"id",     "type",   "x",      "y",      "z",     "vx",
                                            "vy",     "vz",     "radius", "mass",   "fx",    "c_s[1]",
                                            "c_s[2]", "c_s[3]", "c_s[4]", "c_s[5]", "c_s[6]"};
        static const int shuf[] = {7, 0, 8, 10, 4, 1, 6, 2, 9, 5, 3, 16, 15, 14, 13, 12, 11};
        int cols[20], nc = 0;
        if (o->shuffle) {
            for (size_t k = 0; k < sizeof shuf / sizeof *shuf; k++) {
                int c = shuf[k];
                if (c == 9 && !o->with_mass)
                    continue;
                if (c >= 11 && !o->with_stress)
                    continue;
                cols[nc++] = c;
            }
        } else {
            for (size_t k = 0; k < sizeof plain / sizeof *plain; k++) {
                int c = plain[k];
                if (c == 9 && !o->with_mass)
                    continue;
                if (c >= 11 && !o->with_stress)
                    continue;
                cols[nc++] = c;
            }
        }
        if (o->format == SYNTH_BIN) {
            int64_t mlen = -10;
            int32_t endian = 1, rev = 2, tri = 0, bnd[6] = {0, 0, 0, 0, 1, 1}, size_one = nc;
            if (o->xwalls)
                bnd[0] = bnd[1] = 1;
            double box[6] = {0, o->lx, 0, o->ly, 0, o->lz};
            int64_t na = (int64_t)n;
            put(&w, &mlen, 8);
            put(&w, "DUMPCUSTOM", 10);
            put(&w, &endian, 4);
            put(&w, &rev, 4);
            put(&w, &step, 8);
            put(&w, &na, 8);
            put(&w, &tri, 4);
            put(&w, bnd, sizeof bnd);
            put(&w, box, sizeof box);
            put(&w, &size_one, 4);
            int32_t ulen = 2;
            put(&w, &ulen, 4);
            put(&w, "si", 2);
            char tf = 1;
            double t = (double)step * o->dt;
            put(&w, &tf, 1);
            put(&w, &t, 8);
            char names[512] = "";
            for (int k = 0; k < nc; k++) {
                strcat(names, pname[cols[k]]);
                if (k + 1 < nc)
                    strcat(names, " ");
            }
            int32_t clen = (int32_t)strlen(names);
            put(&w, &clen, 4);
            put(&w, names, (size_t)clen);
            int32_t nchunk = 2;
            put(&w, &nchunk, 4);
            size_t half = n / 2;
            for (int ch = 0; ch < 2; ch++) {
                size_t i0 = ch ? half : 0, i1 = ch ? n : half;
                int32_t len = (int32_t)((i1 - i0) * (size_t)nc);
                put(&w, &len, 4);
                for (size_t i = i0; i < i1; i++)
                    for (int k = 0; k < nc; k++)
                        put(&w, &rows[20 * i + cols[k]], 8);
            }
        } else {
            if (!o->liggghts)
                putf(&w, "ITEM: TIME\n%.16g\n", (double)step * o->dt);
            putf(&w, "ITEM: TIMESTEP\n%lld\nITEM: NUMBER OF ATOMS\n%zu\n", (long long)step, n);
            putf(&w, o->xwalls ? "ITEM: BOX BOUNDS ff pp ff\n" : "ITEM: BOX BOUNDS pp pp ff\n");
            putf(&w, "%.16e %.16e\n%.16e %.16e\n%.16e %.16e\n", 0.0, o->lx, 0.0, o->ly, 0.0, o->lz);
            putf(&w, "ITEM: ATOMS");
            for (int k = 0; k < nc; k++) {
                putf(&w, " %s", pname[cols[k]]);
                if (o->liggghts && cols[k] == 1)
                    putf(&w, " type");
            }
            put(&w, o->liggghts ? " \n" : "\n", o->liggghts ? 2 : 1);
            for (size_t i = 0; i < n; i++) {
                for (int k = 0; k < nc; k++) {
                    double v = rows[20 * i + cols[k]];
                    if (k)
                        put(&w, " ", 1);
                    if (cols[k] <= 1)
                        putf(&w, "%lld", (long long)v);
                    else
                        putf(&w, fmt, v);
                    if (o->liggghts && cols[k] == 1)
                        putf(&w, " %lld", (long long)v);
                }
                put(&w, o->liggghts ? " \n" : "\n", o->liggghts ? 2 : 1);
                if (w.len > (1u << 20))
                    rc |= flush(&w);
            }
        }
        rc |= flush(&w);
    }
    free(rows);
    free(w.buf);
    gsl_rng_free(r);
    if (w.gz)
        rc |= gzclose(w.gz) != Z_OK;
    if (w.fp)
        rc |= fclose(w.fp) != 0;
    return rc;
}

synth_pile_opts synth_pile_default(void)
{
    synth_pile_opts o;
    memset(&o, 0, sizeof o);
    o.nfx = 80;
    o.nfy = 2;
    o.lx = 0.16;
    o.ly = 0.004;
    o.lz = 0.1;
    o.radius = 0.001;
    o.height = 0.03;
    o.halfwidth = 0.06;
    o.rho_bulk = 1500.0;
    o.g = 9.81;
    o.npile = 300;
    o.nsnap = 3;
    o.with_fz = 1;
    o.seed = 7;
    return o;
}

double synth_pile_p(const synth_pile_opts *o, double x)
{
    double xc = 0.5 * o->lx, h = o->height * (1.0 - fabs(x - xc) / o->halfwidth);
    if (h < 0.0)
        h = 0.0;
    return o->rho_bulk * o->g * h * (1.0 + o->eps) * (1.0 + o->tilt * (x - xc) / o->halfwidth);
}

int synth_pile_write(const char *path, const synth_pile_opts *o)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        return 1;
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, o->seed);
    double a = o->lx / (double)o->nfx, b = o->ly / (double)o->nfy,
           m = o->rho_bulk / 0.6 * 4.0 / 3.0 * PI * o->radius * o->radius * o->radius;
    size_t nfloor = o->nfx * o->nfy, n = nfloor + o->npile;
    for (size_t s = 0; s < o->nsnap; s++) {
        fprintf(fp, "ITEM: TIMESTEP\n%zu\nITEM: NUMBER OF ATOMS\n%zu\n", 1000 * s, n);
        fprintf(fp, "ITEM: BOX BOUNDS ff pp ff\n%.17g %.17g\n%.17g %.17g\n%.17g %.17g\n", 0.0, o->lx, 0.0,
                o->ly, 0.0, o->lz);
        fprintf(fp, "ITEM: ATOMS id type x y z vx vy vz radius mass%s\n", o->with_fz ? " fx fy fz" : "");
        for (size_t i = 0; i < n; i++) {
            double x, y, z, fz;
            int type;
            if (i < nfloor) {
                type = 2;
                x = ((double)(i % o->nfx) + 0.5) * a;
                y = ((double)(i / o->nfx) + 0.5) * b;
                z = o->radius;
                fz = -synth_pile_p(o, x) * a * b * (1.0 + o->eps_step * (double)s);
            } else {
                type = 1;
                x = 0.5 * o->lx + (2.0 * gsl_rng_uniform(r) - 1.0) * o->halfwidth;
                y = gsl_rng_uniform(r) * o->ly;
                double h = o->height * (1.0 - fabs(x - 0.5 * o->lx) / o->halfwidth);
                z = 2.0 * o->radius + gsl_rng_uniform(r) * h;
                fz = gsl_ran_gaussian(r, 1e-3);
            }
            fprintf(fp, "%zu %d %.17g %.17g %.17g 0 0 0 %.17g %.17g", i + 1, type, x, y, z, o->radius, m);
            if (o->with_fz)
                fprintf(fp, " %.17g %.17g %.17g", gsl_ran_gaussian(r, 1e-4), gsl_ran_gaussian(r, 1e-4), fz);
            fputc('\n', fp);
        }
    }
    gsl_rng_free(r);
    return fclose(fp) != 0;
}
