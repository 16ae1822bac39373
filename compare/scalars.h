/* scalars.h: scalar observables of a slab profile with their standard
 * errors (docs/model-notes.md section 9: "what papers quote"), as pure functions of
 * one profile (no files: score.c reads, interpolates and writes).
 *
 * A profile is n points z[k] (increasing, m) with bin averages and their
 * standard errors (an SE array may be NULL, an SE NaN: unknown). Every bin
 * has the width w_k = (z[k+1] - z[k-1]) / 2 (ends: the spacing to the
 * neighbour), so a sum f_k w_k is the integral of a bin-averaged field.
 *
 * Definitions (H = half the profile's largest phi; "material" = phi >= H):
 *   layer_height      the highest z where phi crosses H downwards, linear
 *                     between the two points (m). SE from the two phi SEs,
 *                     independent: se = w/D sqrt(((1-a) s_k)^2 + (a s_k+1)^2)
 *                     (D = phi_k - phi_k+1, a the fraction). NaN when phi
 *                     does not fall below H above the material (a layer
 *                     reaching the grid's top).
 *   base              the lowest point in material.
 *   surface_velocity  vx at the highest point in material below the layer
 *                     height (m/s), its SE.
 *   flow_rate         q = sum phi_k vx_k w_k over the points with finite vx
 *                     and phi > CG_SCALAR_TRACE x the largest phi (a trace
 *                     below it is a grain that crossed the bin once or
 *                     twice: its vx has no SE, and it carries less than
 *                     1e-3 of a full bin's flux): the volume flux per unit
 *                     width (m^2/s);
 *                     SE = sum w_k sqrt((vx_k se_phi_k)^2 + (phi_k se_vx_k)^2):
 *                     the fully correlated bound (every bin averages the
 *                     same snapshots).
 *   depth_averaged_velocity  q / sum phi_k w_k (same points; m/s): the
 *                     phi-weighted mean vx; SE the phi-weighted mean of
 *                     se_vx (fully correlated, phi weights taken as exact).
 *   bulk_phi          mean phi over the points in the middle half of the
 *                     layer, base + (h - base)/4 .. base + 3(h - base)/4;
 *                     SE the mean of their SEs (fully correlated bound).
 *   base_friction     |sxz| / |szz| at the base; SE with the two relative
 *                     SEs independent.
 *   mean_phi, mean_P, mean_T, wall_shear_stress (= mean |sxz|)
 *                     plain means over the points in material (finite
 *                     values), SE the mean of their SEs (fully correlated).
 *   wall_friction     mean |sxz| / mean |szz|, mu = mean |sxz| / mean P,
 *                     over the points in material; SE with the two relative
 *                     SEs independent.
 *   edges             the lower and upper edge of the material: where phi
 *                     crosses H below the base (upwards) and above the
 *                     highest point in material (downwards), linear, SE as
 *                     layer_height's; an end point of the grid in material
 *                     has its edge at the grid's end, z[0] - w_0/2 or
 *                     z[n-1] + w_n-1/2 (a wall the continuum fills), SE 0.
 *   gap               upper edge - lower edge (m), the material's thickness
 *                     between two walls; SE the two edges' in quadrature.
 *   wall_slip         top_velocity - vx at the upper edge (m/s): vx linear
 *                     between the two points of the crossing, or extrapolated
 *                     linearly from the two highest points to a grid end;
 *                     SE^2 = (sum |c_i| se_vx_i)^2 + (dvx/dz se_edge)^2
 *                     (c_i the interpolation weights; fully correlated).
 *   base_stress_over_weight  |szz| at the base over the weight per unit area
 *                     of the material above the base point,
 *                     W = g_normal sum c_k rho_k w_k (c = 1/2 for the base
 *                     bin, 1 above; bins with phi > CG_SCALAR_TRACE x the
 *                     largest phi; rho = rho_p phi where no rho is given);
 *                     SE with the relative SEs of |szz| and of W
 *                     (g_normal sum c_k se_rho_k w_k, fully correlated)
 *                     independent.
 * Every value is NaN (and its SE NaN) when a field it needs is missing or
 * there is no point to take it from; an SE is NaN when an SE it needs is.
 */
#ifndef CG_SCALARS_H
#define CG_SCALARS_H

#include <stddef.h>

/* Bins with phi at or below this fraction of the profile's largest phi are
 * traces (see flow_rate). */
#define CG_SCALAR_TRACE 1e-3

typedef struct {
    size_t n;
    const double *z;                            /* [m], increasing */
    const double *phi, *vx, *sxz, *szz, *P, *T; /* [-], [m/s], [Pa], [m^2/s^2]; NULL: absent */
    const double *phi_se, *vx_se, *sxz_se, *szz_se, *P_se, *T_se; /* NULL: unknown */
    const double *rho, *rho_se; /* [kg/m^3] bulk density; NULL: rho_p phi (SE rho_p se_phi) */
    double rho_p;               /* [kg/m^3] grain density where rho is NULL; NaN: unknown */
    double g_normal;            /* [m/s^2] |z component of gravity|; NaN: unknown */
    double top_velocity;        /* [m/s] x velocity of the top wall; NaN: unknown */
} cg_scalar_profile;

typedef struct {
    double value; /* in the scalar's units, NaN if undefined */
    double se;    /* standard error, NaN if unknown */
} cg_scalar_value;

typedef enum {
    CG_SCALAR_LAYER_HEIGHT,
    CG_SCALAR_BULK_PHI,
    CG_SCALAR_SURFACE_VELOCITY,
    CG_SCALAR_DEPTH_AVERAGED_VELOCITY,
    CG_SCALAR_FLOW_RATE,
    CG_SCALAR_BASE_FRICTION,
    CG_SCALAR_MEAN_PHI,
    CG_SCALAR_WALL_SHEAR_STRESS,
    CG_SCALAR_WALL_FRICTION,
    CG_SCALAR_MEAN_P,
    CG_SCALAR_MU,
    CG_SCALAR_MEAN_T,
    CG_SCALAR_BED_HEIGHT, /* the layer height at every compared time */
    CG_SCALAR_GAP,
    CG_SCALAR_WALL_SLIP,
    CG_SCALAR_BASE_STRESS_OVER_WEIGHT, /* at every compared time */
    CG_SCALAR_COUNT
} cg_scalar_kind;

/* The name ("layer_height", ...), or NULL for a kind out of range. */
const char *cg_scalar_name(cg_scalar_kind k);
/* The units ("m", "m/s", "m^2/s", "Pa", "m^2/s^2", "1"). */
const char *cg_scalar_units(cg_scalar_kind k);
/* The kind named name, or -1. */
int cg_scalar_lookup(const char *name);
/* 1 if the scalar is a time series (evaluated at every compared time),
 * 0 if it is taken at the last compared time. */
int cg_scalar_per_time(cg_scalar_kind k);
/* The scalars of a scenario set ("chute", "shear_cell", "filling",
 * "simple_shear") as a comma-separated list, or NULL. */
const char *cg_scalar_set(const char *name);

/* The scalar k of profile p. */
cg_scalar_value cg_scalar_compute(cg_scalar_kind k, const cg_scalar_profile *p);

#endif
