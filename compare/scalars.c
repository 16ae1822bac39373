/* scalars.c: scalar observables of a profile and their SEs (see scalars.h). */
#include "scalars.h"

#include <math.h>
#include <string.h>

static const struct {
    const char *name, *units;
    int per_time;
} SCALARS[CG_SCALAR_COUNT] = {
    [CG_SCALAR_LAYER_HEIGHT] = {"layer_height", "m", 0},
    [CG_SCALAR_BULK_PHI] = {"bulk_phi", "1", 0},
    [CG_SCALAR_SURFACE_VELOCITY] = {"surface_velocity", "m/s", 0},
    [CG_SCALAR_DEPTH_AVERAGED_VELOCITY] = {"depth_averaged_velocity", "m/s", 0},
    [CG_SCALAR_FLOW_RATE] = {"flow_rate", "m^2/s", 0},
    [CG_SCALAR_BASE_FRICTION] = {"base_friction", "1", 0},
    [CG_SCALAR_MEAN_PHI] = {"mean_phi", "1", 0},
    [CG_SCALAR_WALL_SHEAR_STRESS] = {"wall_shear_stress", "Pa", 0},
    [CG_SCALAR_WALL_FRICTION] = {"wall_friction", "1", 0},
    [CG_SCALAR_MEAN_P] = {"mean_P", "Pa", 0},
    [CG_SCALAR_MU] = {"mu", "1", 0},
    [CG_SCALAR_MEAN_T] = {"mean_T", "m^2/s^2", 0},
    [CG_SCALAR_BED_HEIGHT] = {"bed_height", "m", 1},
    [CG_SCALAR_GAP] = {"gap", "m", 0},
    [CG_SCALAR_WALL_SLIP] = {"wall_slip", "m/s", 0},
    [CG_SCALAR_BASE_STRESS_OVER_WEIGHT] = {"base_stress_over_weight", "1", 1},
};

static const struct {
    const char *set, *list;
} SETS[] = {
    {"chute", "layer_height,bulk_phi,surface_velocity,depth_averaged_velocity,flow_rate,base_friction"},
    {"shear_cell", "mean_phi,wall_shear_stress,wall_friction,gap,wall_slip"},
    {"filling", "bed_height,mean_phi,base_stress_over_weight"},
    {"simple_shear", "mean_P,mu,mean_T,mean_phi"},
};

const char *cg_scalar_name(cg_scalar_kind k)
{
    return (unsigned)k < CG_SCALAR_COUNT ? SCALARS[k].name : NULL;
}

const char *cg_scalar_units(cg_scalar_kind k)
{
    return (unsigned)k < CG_SCALAR_COUNT ? SCALARS[k].units : NULL;
}

int cg_scalar_per_time(cg_scalar_kind k)
{
    return (unsigned)k < CG_SCALAR_COUNT ? SCALARS[k].per_time : 0;
}

int cg_scalar_lookup(const char *name)
{
    for (int k = 0; k < CG_SCALAR_COUNT; k++)
        if (!strcmp(name, SCALARS[k].name))
            return k;
    return -1;
}

const char *cg_scalar_set(const char *name)
{
    for (size_t i = 0; i < sizeof SETS / sizeof *SETS; i++)
        if (!strcmp(name, SETS[i].set))
            return SETS[i].list;
    return NULL;
}

static const cg_scalar_value UNDEFINED = {NAN, NAN};

static double se_at(const double *se, size_t k)
{
    return se ? se[k] : NAN;
}

/* bin width of point k */
static double width(const cg_scalar_profile *p, size_t k)
{
    if (p->n < 2)
        return NAN;
    if (k == 0)
        return p->z[1] - p->z[0];
    if (k == p->n - 1)
        return p->z[k] - p->z[k - 1];
    return 0.5 * (p->z[k + 1] - p->z[k - 1]);
}

/* H = half the largest finite phi (NaN without one) */
static double half_max_phi(const cg_scalar_profile *p)
{
    double m = NAN;
    for (size_t k = 0; k < p->n; k++)
        if (isfinite(p->phi[k]) && !(p->phi[k] <= m))
            m = p->phi[k];
    return 0.5 * m;
}

static int in_material(const cg_scalar_profile *p, size_t k, double h)
{
    return isfinite(p->phi[k]) && p->phi[k] >= h;
}

/* index of the highest point in material (n if none) */
static size_t top_index(const cg_scalar_profile *p, double h)
{
    for (size_t k = p->n; k-- > 0;)
        if (in_material(p, k, h))
            return k;
    return p->n;
}

static size_t base_index(const cg_scalar_profile *p, double h)
{
    for (size_t k = 0; k < p->n; k++)
        if (in_material(p, k, h))
            return k;
    return p->n;
}

static cg_scalar_value layer_height(const cg_scalar_profile *p)
{
    double h = half_max_phi(p);
    size_t k = top_index(p, h);
    if (k >= p->n || k + 1 >= p->n || !isfinite(p->phi[k + 1]))
        return UNDEFINED;
    double d = p->phi[k] - p->phi[k + 1], dz = p->z[k + 1] - p->z[k];
    double a = (p->phi[k] - h) / d;
    cg_scalar_value r;
    r.value = p->z[k] + a * dz;
    double s0 = (1.0 - a) * se_at(p->phi_se, k), s1 = a * se_at(p->phi_se, k + 1);
    r.se = dz / d * sqrt(s0 * s0 + s1 * s1);
    return r;
}

/* mean of f (abs: of |f|) and of its SE over the points in material with
 * z in [lo, hi] and f finite */
static cg_scalar_value mean_over(const cg_scalar_profile *p, const double *f, const double *se, int abs_value,
                                 double lo, double hi)
{
    if (!f)
        return UNDEFINED;
    double h = half_max_phi(p), sum = 0, sum_se = 0;
    size_t n = 0;
    for (size_t k = 0; k < p->n; k++) {
        if (!in_material(p, k, h) || !isfinite(f[k]) || p->z[k] < lo || p->z[k] > hi)
            continue;
        sum += abs_value ? fabs(f[k]) : f[k];
        sum_se += se_at(se, k);
        n++;
    }
    if (n == 0)
        return UNDEFINED;
    cg_scalar_value r = {sum / (double)n, sum_se / (double)n};
    return r;
}

static cg_scalar_value ratio(cg_scalar_value a, cg_scalar_value b)
{
    cg_scalar_value r;
    r.value = a.value / b.value;
    double ra = a.se / a.value, rb = b.se / b.value;
    r.se = fabs(r.value) * sqrt(ra * ra + rb * rb);
    if (!isfinite(r.value))
        return UNDEFINED;
    return r;
}

static cg_scalar_value flow(const cg_scalar_profile *p, int average)
{
    if (!p->vx || p->n < 2)
        return UNDEFINED;
    double q = 0, q_se = 0, hold = 0, u_se = 0, trace = CG_SCALAR_TRACE * 2.0 * half_max_phi(p);
    size_t n = 0;
    for (size_t k = 0; k < p->n; k++) {
        double f = p->phi[k], v = p->vx[k], w = width(p, k);
        if (!(f > trace) || !isfinite(v))
            continue;
        double a = v * se_at(p->phi_se, k), b = f * se_at(p->vx_se, k);
        q += f * v * w;
        q_se += w * sqrt(a * a + b * b);
        hold += f * w;
        u_se += f * w * se_at(p->vx_se, k);
        n++;
    }
    if (n == 0)
        return UNDEFINED;
    cg_scalar_value r;
    if (average) {
        r.value = q / hold;
        r.se = u_se / hold;
    } else {
        r.value = q;
        r.se = q_se;
    }
    return r;
}

/* An edge of the material: z = z[i0] + t (z[i1] - z[i0]) (t in [0, 1] at
 * a crossing of H, t > 1 at the grid's upper end, t < 0 at its lower end),
 * its SE, and i0, i1, t for interpolating another field there. */
typedef struct {
    double z, se, t;
    size_t i0, i1;
} edge_at;

static int material_edge(const cg_scalar_profile *p, int upper, edge_at *e)
{
    double h = half_max_phi(p);
    if (p->n < 2)
        return 0;
    if (upper) {
        size_t k = top_index(p, h);
        if (k >= p->n)
            return 0;
        if (k == p->n - 1) { /* material to the grid's end: the wall */
            e->i0 = k - 1;
            e->i1 = k;
            e->z = p->z[k] + 0.5 * width(p, k);
            e->t = (e->z - p->z[k - 1]) / (p->z[k] - p->z[k - 1]);
            e->se = 0.0;
            return 1;
        }
        cg_scalar_value c = layer_height(p);
        if (!isfinite(c.value))
            return 0;
        e->i0 = k;
        e->i1 = k + 1;
        e->z = c.value;
        e->se = c.se;
        e->t = (c.value - p->z[k]) / (p->z[k + 1] - p->z[k]);
        return 1;
    }
    size_t b = base_index(p, h);
    if (b >= p->n)
        return 0;
    if (b == 0) {
        e->i0 = 0;
        e->i1 = 1;
        e->z = p->z[0] - 0.5 * width(p, 0);
        e->t = (e->z - p->z[0]) / (p->z[1] - p->z[0]);
        e->se = 0.0;
        return 1;
    }
    if (!isfinite(p->phi[b - 1]))
        return 0;
    double d = p->phi[b] - p->phi[b - 1], dz = p->z[b] - p->z[b - 1];
    double a = (h - p->phi[b - 1]) / d;
    double s0 = (1.0 - a) * se_at(p->phi_se, b - 1), s1 = a * se_at(p->phi_se, b);
    e->i0 = b - 1;
    e->i1 = b;
    e->z = p->z[b - 1] + a * dz;
    e->t = a;
    e->se = dz / d * sqrt(s0 * s0 + s1 * s1);
    return 1;
}

static cg_scalar_value gap(const cg_scalar_profile *p)
{
    edge_at lo, hi;
    if (!material_edge(p, 0, &lo) || !material_edge(p, 1, &hi))
        return UNDEFINED;
    cg_scalar_value r = {hi.z - lo.z, sqrt(lo.se * lo.se + hi.se * hi.se)};
    return r;
}

static cg_scalar_value wall_slip(const cg_scalar_profile *p)
{
    edge_at e;
    if (!p->vx || !isfinite(p->top_velocity) || !material_edge(p, 1, &e))
        return UNDEFINED;
    double v0 = p->vx[e.i0], v1 = p->vx[e.i1];
    if (!isfinite(v0) || !isfinite(v1))
        return UNDEFINED;
    double v = v0 + e.t * (v1 - v0), slope = (v1 - v0) / (p->z[e.i1] - p->z[e.i0]);
    double se_v = fabs(1.0 - e.t) * se_at(p->vx_se, e.i0) + fabs(e.t) * se_at(p->vx_se, e.i1);
    double se_z = slope * e.se;
    cg_scalar_value r = {p->top_velocity - v, sqrt(se_v * se_v + se_z * se_z)};
    return r;
}

/* |szz| at the base over the weight per unit area above the base point */
static cg_scalar_value base_stress_over_weight(const cg_scalar_profile *p)
{
    double h = half_max_phi(p), trace = CG_SCALAR_TRACE * 2.0 * h;
    size_t b = base_index(p, h);
    if (!p->szz || b >= p->n || !isfinite(p->szz[b]) || !isfinite(p->g_normal) || p->n < 2)
        return UNDEFINED;
    if (!p->rho && !isfinite(p->rho_p))
        return UNDEFINED;
    double w_sum = 0, w_se = 0;
    for (size_t k = b; k < p->n; k++) {
        double rho = p->rho ? p->rho[k] : p->rho_p * p->phi[k];
        double rho_se = p->rho ? se_at(p->rho_se, k) : p->rho_p * se_at(p->phi_se, k);
        if (!(p->phi[k] > trace) || !isfinite(rho))
            continue;
        double c = (k == b ? 0.5 : 1.0) * width(p, k);
        w_sum += c * rho;
        w_se += c * rho_se;
    }
    cg_scalar_value s = {fabs(p->szz[b]), se_at(p->szz_se, b)},
                    w = {fabs(p->g_normal) * w_sum, fabs(p->g_normal) * w_se};
    return ratio(s, w);
}

cg_scalar_value cg_scalar_compute(cg_scalar_kind kind, const cg_scalar_profile *p)
{
    if (!p->phi || !p->z || p->n == 0)
        return UNDEFINED;
    double h = half_max_phi(p);
    if (!isfinite(h))
        return UNDEFINED;
    switch (kind) {
    case CG_SCALAR_LAYER_HEIGHT:
    case CG_SCALAR_BED_HEIGHT: return layer_height(p);
    case CG_SCALAR_BULK_PHI: {
        cg_scalar_value top = layer_height(p);
        size_t b = base_index(p, h);
        if (!isfinite(top.value) || b >= p->n)
            return UNDEFINED;
        double z0 = p->z[b], depth = top.value - z0;
        return mean_over(p, p->phi, p->phi_se, 0, z0 + 0.25 * depth, z0 + 0.75 * depth);
    }
    case CG_SCALAR_SURFACE_VELOCITY: {
        size_t k = top_index(p, h);
        if (!p->vx || k >= p->n || !isfinite(p->vx[k]))
            return UNDEFINED;
        cg_scalar_value r = {p->vx[k], se_at(p->vx_se, k)};
        return r;
    }
    case CG_SCALAR_DEPTH_AVERAGED_VELOCITY: return flow(p, 1);
    case CG_SCALAR_FLOW_RATE: return flow(p, 0);
    case CG_SCALAR_BASE_FRICTION: {
        size_t k = base_index(p, h);
        if (!p->sxz || !p->szz || k >= p->n)
            return UNDEFINED;
        cg_scalar_value a = {fabs(p->sxz[k]), se_at(p->sxz_se, k)},
                        b = {fabs(p->szz[k]), se_at(p->szz_se, k)};
        return ratio(a, b);
    }
    case CG_SCALAR_MEAN_PHI: return mean_over(p, p->phi, p->phi_se, 0, -INFINITY, INFINITY);
    case CG_SCALAR_WALL_SHEAR_STRESS: return mean_over(p, p->sxz, p->sxz_se, 1, -INFINITY, INFINITY);
    case CG_SCALAR_WALL_FRICTION:
        return ratio(mean_over(p, p->sxz, p->sxz_se, 1, -INFINITY, INFINITY),
                     mean_over(p, p->szz, p->szz_se, 1, -INFINITY, INFINITY));
    case CG_SCALAR_MEAN_P: return mean_over(p, p->P, p->P_se, 0, -INFINITY, INFINITY);
    case CG_SCALAR_MU:
        return ratio(mean_over(p, p->sxz, p->sxz_se, 1, -INFINITY, INFINITY),
                     mean_over(p, p->P, p->P_se, 0, -INFINITY, INFINITY));
    case CG_SCALAR_MEAN_T: return mean_over(p, p->T, p->T_se, 0, -INFINITY, INFINITY);
    case CG_SCALAR_GAP: return gap(p);
    case CG_SCALAR_WALL_SLIP: return wall_slip(p);
    case CG_SCALAR_BASE_STRESS_OVER_WEIGHT: return base_stress_over_weight(p);
    case CG_SCALAR_COUNT: break;
    }
    return UNDEFINED;
}
