/* synth.h: synthetic particle dumps with known fields, for tests and the
 * benchmark. Box [0,lx) x [0,ly) x [0,lz], periodic in x and y, walls in z.
 * Positions: x, y uniform; z from the density p(z) ~ 1 + a (z/lz - 1/2).
 * Velocities: vx = u0 + gdot (z - lz/2) + sqrt(T(z)) N(0,1), vy and vz
 * = v0 + sqrt(T(z)) N(0,1), T(z) = T0 (1 + b (z/lz - 1/2)).
 * Every snapshot is an independent draw (fixed seed).
 */
#ifndef SYNTH_H
#define SYNTH_H

#include <stddef.h>
#include <stdint.h>

typedef enum { SYNTH_TEXT, SYNTH_GZ, SYNTH_BIN } synth_format;

typedef struct {
    size_t natoms, nsnap;
    unsigned long seed;
    double lx, ly, lz;    /* box [m] */
    double radius, rho_p; /* particle radius [m], density [kg/m^3] */
    double a;             /* density slope (|a| < 2) */
    double u0, v0;        /* uniform velocity in x and in y, z [m/s] */
    double gdot;          /* shear rate du/dz [1/s] */
    double T0, b;         /* temperature [m^2/s^2] and its slope */
    synth_format format;
    int liggghts;         /* LIGGGHTS look: no TIME, trailing blanks, 6 digits, duplicate 'type' */
    int shuffle;          /* another column order, with extra columns */
    int with_mass;        /* write a mass column */
    int with_stress;      /* write c_s[1..6] = -P0 V (xx yy zz), S0 V (xz) */
    double P0, S0;        /* contact pressure and shear stress [Pa] */
    double dt;            /* time step [s]; TIME = step dt */
    int64_t step0, dstep; /* first step and step between snapshots */
    double ax;            /* density slope along x: p(x) ~ 1 + ax (x/lx - 1/2) (|ax| < 2; 0: uniform) */
    int xwalls;           /* 1: walls in x (BOX BOUNDS ff pp ff) instead of periodic */
} synth_opts;

synth_opts synth_default(void);

/* Write the dump; 0 on success. */
int synth_write(const char *path, const synth_opts *o);

/* Exact density [kg/m^3] at z of the draw (all snapshots). */
double synth_rho(const synth_opts *o, double z);

/* A synthetic pile at rest for `ekmcompare base`: floor grains (type 2)
 * on a lattice of nfx x nfy sites ((i + 1/2) lx/nfx, (j + 1/2) ly/nfy)
 * at z = radius, each with fz = -p(x_i) (lx/nfx) (ly/nfy): the weight of
 * the hydrostatic column above its site, p(x) = rho_bulk g h(x) (1 + eps)
 * (1 + tilt (x - xc)/halfwidth), h(x) = height max(0, 1 - |x - xc|/halfwidth),
 * xc = lx/2 (a wedge pile); fx, fy small random; npile pile grains
 * (type 1) inside the wedge with random forces (which must not count). */
typedef struct {
    size_t nfx, nfy;    /* floor lattice sites along x and y */
    double lx, ly, lz;  /* box [0,lx) x [0,ly) x [0,lz] [m] */
    double radius;      /* grain radius [m] */
    double height;      /* wedge height at its centre [m] */
    double halfwidth;   /* wedge half-width at the floor [m] */
    double rho_bulk, g; /* bulk density [kg/m^3], gravity [m/s^2] */
    double eps, tilt;   /* relative perturbation of the load, and its slope */
    double eps_step;    /* snapshot s carries the load x (1 + eps_step s) on top */
    size_t npile;       /* pile grains (type 1) */
    size_t nsnap;       /* snapshots (all the same pile) */
    int with_fz;        /* 0: no fx fy fz columns (a dump `base` must refuse) */
    unsigned long seed;
} synth_pile_opts;

synth_pile_opts synth_pile_default(void);

/* The base pressure [Pa] the pile's floor load represents at x. */
double synth_pile_p(const synth_pile_opts *o, double x);

/* Write the dump (text, full precision); 0 on success. */
int synth_pile_write(const char *path, const synth_pile_opts *o);

#endif
