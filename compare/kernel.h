/* kernel.h: 1D coarse-graining kernels and the output grid (docs/model-notes.md section 8).
 *
 * A kernel W(x) of a particle at distance x, normalised to 1 over the line,
 * enters the fields through its bin integrals: the weight of a particle at
 * s in bin k = [e_k, e_k+1) is (F(e_k+1 - s) - F(e_k - s)) / dz, with F the
 * kernel's cumulative integral. Fields are thus exact bin averages of the
 * continuous coarse-grained fields, and the weights of a particle sum to
 * exactly 1/dz x dz = 1 (mass is conserved to round-off) whenever the kernel
 * lies inside the grid. Kernels, all of standard deviation `width` w:
 *   gauss  Gaussian cut at 3w and renormalised (F and F' tabulated at 601
 *          points, cubic Hermite interpolation, error < 1e-10);
 *   lucy   Lucy's polynomial (5/4c)(1+3r)(1-r)^3, r = |x|/c, with cutoff
 *          c = sqrt(21/2) w (same standard deviation as the Gaussian);
 *   bins   exact sphere-slab volume bins: a sphere of radius R is split
 *          among the bins by the volume of the slices (width unused).
 * Boundaries: a periodic axis wraps the kernel; at a wall (non-periodic
 * box face) the part of the kernel that leaks past it is reflected back
 * (image particle), which keeps mass exact and a uniform field uniform.
 */
#ifndef CG_KERNEL_H
#define CG_KERNEL_H

#include <stddef.h>

#include "status.h"

typedef enum { CG_KERNEL_GAUSS, CG_KERNEL_LUCY, CG_KERNEL_BINS } cg_kernel_type;

typedef struct {
    cg_kernel_type type;
    double width;  /* standard deviation w [m] (gauss, lucy) */
    double cutoff; /* support half-width [m] (gauss 3w, lucy c; bins: 0) */
    size_t ntab;   /* tabulated points of F (gauss) */
    double *tab;   /* (F, h F') at u = -3 + h i, h = 6/(ntab-1), u = x/w (gauss) */
    double tscale; /* table index per metre [1/m] (gauss) */
    double toff;   /* table index of x = 0 (gauss) */
} cg_kernel;

typedef struct {
    size_t n;      /* number of bins */
    double lo, hi; /* grid ends along the axis [m] */
    double dz;     /* bin width (hi - lo)/n [m] */
    int periodic;  /* 1: wrap the kernel across lo/hi */
    int reflect;   /* 1: reflect the kernel at lo and hi (walls) */
    int axis;      /* profile axis: 0 x, 1 y, 2 z */
} cg_grid;

/* Kernel by name ("gauss", "lucy", "bins"); width w > 0 [m]. */
ekm_status cg_kernel_alloc(cg_kernel **k, const char *name, double width, ekm_error *err);
void cg_kernel_free(cg_kernel *k);

/* Name of a kernel type. */
const char *cg_kernel_name(const cg_kernel *k);

/* Cumulative integral F(x) of the kernel of a particle of radius R [m]. */
double cg_kernel_cdf(const cg_kernel *k, double x, double R);

/* Support half-width for a particle of radius R [m]. */
double cg_kernel_support(const cg_kernel *k, double R);

/* Bin weights [1/m] of a particle at s (radius R): appends (bin[i], w[i]),
 * returns how many; at most cg_kernel_maxweights(g) entries. */
size_t cg_kernel_weights(const cg_kernel *k, const cg_grid *g, double s, double R, size_t *bin, double *w);
size_t cg_kernel_maxweights(const cg_grid *g);

#endif
