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
} synth_opts;

synth_opts synth_default(void);

/* Write the dump; 0 on success. */
int synth_write(const char *path, const synth_opts *o);

/* Exact density [kg/m^3] at z of the draw (all snapshots). */
double synth_rho(const synth_opts *o, double z);

#endif
