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
};

static const struct {
    const char *set, *list;
} SETS[] = {
    {"chute", "layer_height,bulk_phi,surface_velocity,depth_averaged_velocity,flow_rate,base_friction"},
    {"shear_cell", "mean_phi,wall_shear_stress,wall_friction"},
    {"filling", "bed_height,mean_phi"},
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
    case CG_SCALAR_COUNT: break;
    }
    return UNDEFINED;
}
