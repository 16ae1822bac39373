/* test_scalars.c: the scalar observables (scalars.h) and their SEs on a
 * profile worked out by hand. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "scalars.h"
#include "test_util.h"

/* Five bins of width 1 at z = 0.5 .. 4.5: phi = 0.6, 0.6, 0.6, 0.2, 0 (SE
 * 0.01, 0.01, 0.01, 0.02, 0.01), vx = 1, 2, 3, 4, NaN (SE 0.1), sxz = -1,
 * szz = -2, P = 2 (SE 0.1), T = 1e-3, 2e-3, 3e-3, 0, NaN (SE 1e-4).
 * H = 0.3; the material is bins 0..2. */
static const double Z[5] = {0.5, 1.5, 2.5, 3.5, 4.5};
static const double PHI[5] = {0.6, 0.6, 0.6, 0.2, 0.0}, PHI_SE[5] = {0.01, 0.01, 0.01, 0.02, 0.01};
static const double VX[5] = {1, 2, 3, 4, NAN}, VX_SE[5] = {0.1, 0.1, 0.1, 0.1, 0.1};
static const double SXZ[5] = {-1, -1.5, -1, -1, -1}, SZZ[5] = {-2, -2, -2, -2, -2};
static const double S_SE[5] = {0.1, 0.1, 0.1, 0.1, 0.1};
static const double PP[5] = {2, 2, 2, 2, 2};
static const double TT[5] = {1e-3, 2e-3, 3e-3, 0, NAN}, T_SE[5] = {1e-4, 1e-4, 1e-4, 1e-4, 1e-4};

static cg_scalar_profile profile(void)
{
    cg_scalar_profile p = {5,    Z,    PHI,  VX,   SXZ,  SZZ,  PP,  TT,  PHI_SE, VX_SE,
                           S_SE, S_SE, S_SE, T_SE, NULL, NULL, NAN, NAN, NAN};
    return p;
}

static cg_scalar_value get(const char *name, const cg_scalar_profile *p)
{
    int k = cg_scalar_lookup(name);
    assert_true(k >= 0);
    return cg_scalar_compute((cg_scalar_kind)k, p);
}

static void test_hand_computed(void **state)
{
    (void)state;
    cg_scalar_profile p = profile();
    /* crossing between bins 2 and 3: a = (0.6 - 0.3)/0.4 = 0.75, h = 3.25;
     * se = 1/0.4 sqrt((0.25 x 0.01)^2 + (0.75 x 0.02)^2) */
    cg_scalar_value v = get("layer_height", &p);
    assert_close(v.value, 3.25, 1e-15);
    assert_close(v.se, 2.5 * sqrt(0.0025 * 0.0025 + 0.015 * 0.015), 1e-15);
    /* q = 0.6 (1 + 2 + 3) + 0.2 x 4 = 4.4 (bin 4 has phi = 0); SE the sum
     * of sqrt((vx se_phi)^2 + (phi se_vx)^2) */
    v = get("flow_rate", &p);
    assert_close(v.value, 4.4, 1e-14);
    assert_close(v.se, sqrt(1e-4 + 36e-4) + sqrt(4e-4 + 36e-4) + sqrt(9e-4 + 36e-4) + sqrt(64e-4 + 4e-4),
                 1e-14);
    assert_string_equal(cg_scalar_units(CG_SCALAR_FLOW_RATE), "m^2/s");
    /* 4.4 / (0.6 x 3 + 0.2) = 2.2; SE the phi-weighted mean of 0.1 */
    v = get("depth_averaged_velocity", &p);
    assert_close(v.value, 2.2, 1e-14);
    assert_close(v.se, 0.1, 1e-15);
    /* the highest bin in material is bin 2 */
    v = get("surface_velocity", &p);
    assert_close(v.value, 3.0, 0);
    assert_close(v.se, 0.1, 0);
    /* base z = 0.5, depth 2.75: middle half 1.1875 .. 2.5625 = bins 1, 2 */
    v = get("bulk_phi", &p);
    assert_close(v.value, 0.6, 1e-15);
    assert_close(v.se, 0.01, 1e-15);
    /* |sxz|/|szz| at bin 0 = 0.5, se = 0.5 sqrt(0.1^2 + 0.05^2) */
    v = get("base_friction", &p);
    assert_close(v.value, 0.5, 1e-15);
    assert_close(v.se, 0.5 * sqrt(0.01 + 0.0025), 1e-15);
    /* means over bins 0..2: |sxz| = 3.5/3, P = 2, T = 2e-3 (SEs the mean SE) */
    v = get("wall_shear_stress", &p);
    assert_close(v.value, 3.5 / 3.0, 1e-15);
    assert_close(v.se, 0.1, 1e-15);
    v = get("mu", &p);
    assert_close(v.value, 3.5 / 6.0, 1e-15);
    assert_close(v.se, 3.5 / 6.0 * sqrt(pow(0.1 / (3.5 / 3.0), 2) + pow(0.05, 2)), 1e-15);
    v = get("wall_friction", &p);
    assert_close(v.value, 3.5 / 6.0, 1e-15);
    v = get("mean_T", &p);
    assert_close(v.value, 2e-3, 1e-18);
    assert_close(v.se, 1e-4, 1e-19);
    v = get("mean_phi", &p);
    assert_close(v.value, 0.6, 1e-15);
    v = get("mean_P", &p);
    assert_close(v.value, 2.0, 0);
}

/* A layer that reaches the top of the grid has no free surface: the layer
 * height (and what depends on it) is NaN; a missing field or SE gives NaN. */
static void test_undefined(void **state)
{
    (void)state;
    const double full[5] = {0.6, 0.6, 0.6, 0.6, 0.6};
    cg_scalar_profile p = profile();
    p.phi = full;
    assert_true(isnan(get("layer_height", &p).value));
    assert_true(isnan(get("bulk_phi", &p).value));
    assert_close(get("mean_phi", &p).value, 0.6, 1e-15);
    p = profile();
    p.sxz = NULL;
    assert_true(isnan(get("base_friction", &p).value));
    p = profile();
    p.phi_se = NULL;
    cg_scalar_value v = get("layer_height", &p);
    assert_close(v.value, 3.25, 1e-15);
    assert_true(isnan(v.se));
}

/* A shear cell as the DEM sees it: six bins of width 1 at z = 0.5 .. 5.5,
 * phi = 0.1, 0.5, 0.6, 0.6, 0.5, 0.1 (SE 0.02), H = 0.3. Lower edge: phi
 * rises through 0.3 halfway between bins 0 and 1, z = 1; upper edge
 * halfway between bins 4 and 5, z = 5; each edge's SE
 * 1/0.4 sqrt((0.5 x 0.02)^2 x 2) = 0.025 sqrt(2), the gap's the two in
 * quadrature, 0.05. vx at the upper edge halfway between 0.40 and 0.44 =
 * 0.42, the wall at 0.5: slip 0.08; SE from vx (0.5 x 0.01 + 0.5 x 0.01)
 * and from the edge (slope 0.04 x 0.025 sqrt(2)) in quadrature. */
static void test_shear_cell_gap_and_slip(void **state)
{
    (void)state;
    const double z[6] = {0.5, 1.5, 2.5, 3.5, 4.5, 5.5};
    const double phi[6] = {0.1, 0.5, 0.6, 0.6, 0.5, 0.1}, phi_se[6] = {0.02, 0.02, 0.02, 0.02, 0.02, 0.02};
    const double vx[6] = {0.0, 0.1, 0.2, 0.3, 0.40, 0.44}, vx_se[6] = {0.01, 0.01, 0.01, 0.01, 0.01, 0.01};
    cg_scalar_profile p;
    memset(&p, 0, sizeof p);
    p.n = 6;
    p.z = z;
    p.phi = phi;
    p.phi_se = phi_se;
    p.vx = vx;
    p.vx_se = vx_se;
    p.rho_p = p.g_normal = NAN;
    p.top_velocity = 0.5;
    cg_scalar_value v = get("gap", &p);
    assert_close(v.value, 4.0, 1e-14);
    assert_close(v.se, 0.05, 1e-15);
    assert_string_equal(cg_scalar_units(CG_SCALAR_GAP), "m");
    v = get("wall_slip", &p);
    assert_close(v.value, 0.08, 1e-15);
    assert_close(v.se, sqrt(0.01 * 0.01 + pow(0.04 * 0.025 * sqrt(2.0), 2)), 1e-15);
    /* no wall velocity known: no slip */
    p.top_velocity = NAN;
    assert_true(isnan(get("wall_slip", &p).value));
}

/* The EKM's shear cell: material to both ends of the grid (four cells of 1
 * at 0.5 .. 3.5). The edges are the grid's ends, 0 and 4: the gap is the
 * wall-to-wall distance, SE 0. vx of a no-slip Couette flow (0.1 z, the
 * wall at 0.4) extrapolated from the two top cells to z = 4 is the wall's:
 * slip 0; its SE with t = (4 - 2.5)/1 = 1.5 is 0.5 x 0.01 + 1.5 x 0.01. */
static void test_shear_cell_grid_ends(void **state)
{
    (void)state;
    const double z[4] = {0.5, 1.5, 2.5, 3.5}, phi[4] = {0.6, 0.6, 0.6, 0.6};
    const double vx[4] = {0.05, 0.15, 0.25, 0.35}, vx_se[4] = {0.01, 0.01, 0.01, 0.01};
    cg_scalar_profile p;
    memset(&p, 0, sizeof p);
    p.n = 4;
    p.z = z;
    p.phi = phi;
    p.vx = vx;
    p.rho_p = p.g_normal = NAN;
    p.top_velocity = 0.4;
    cg_scalar_value v = get("gap", &p);
    assert_close(v.value, 4.0, 0);
    assert_close(v.se, 0.0, 0);
    v = get("wall_slip", &p);
    assert_close(v.value, 0.0, 1e-15);
    assert_true(isnan(v.se)); /* no vx SE */
    p.vx_se = vx_se;
    v = get("wall_slip", &p);
    assert_close(v.se, 0.02, 1e-15);
}

/* A resting bed: five bins of 1 at z = 0.5 .. 4.5, phi = 0.5, 0.5, 0.5, 0,
 * 0 (SE 0.01), rho_p = 1000, gravity -10 along z. The weight per unit area
 * above the base point (bin 0, half of it counted) is
 * 10 x 1000 x (0.25 + 0.5 + 0.5) = 12500, its SE 10 x 1000 x (0.5 + 1 + 1)
 * x 0.01 = 250; |szz| at the base 12500 +- 250: ratio 1, SE sqrt(2) x 0.02. */
static void test_base_stress_over_weight(void **state)
{
    (void)state;
    const double z[5] = {0.5, 1.5, 2.5, 3.5, 4.5}, phi[5] = {0.5, 0.5, 0.5, 0, 0};
    const double phi_se[5] = {0.01, 0.01, 0.01, 0.01, 0.01};
    const double szz[5] = {-12500, -7500, -2500, 0, 0}, szz_se[5] = {250, 250, 250, 250, 250};
    const double rho[5] = {500, 500, 500, 0, 0}, rho_se[5] = {10, 10, 10, 10, 10};
    cg_scalar_profile p;
    memset(&p, 0, sizeof p);
    p.n = 5;
    p.z = z;
    p.phi = phi;
    p.phi_se = phi_se;
    p.szz = szz;
    p.szz_se = szz_se;
    p.rho_p = 1000;
    p.g_normal = -10;
    p.top_velocity = NAN;
    cg_scalar_value v = get("base_stress_over_weight", &p);
    assert_close(v.value, 1.0, 1e-15);
    assert_close(v.se, sqrt(2.0) * 0.02, 1e-15);
    /* the bulk density given (a CG file's rho): the same weight */
    p.rho = rho;
    p.rho_se = rho_se;
    p.rho_p = NAN;
    v = get("base_stress_over_weight", &p);
    assert_close(v.value, 1.0, 1e-15);
    assert_close(v.se, sqrt(2.0) * 0.02, 1e-15);
    /* without gravity, or without a density, it is undefined */
    p.g_normal = NAN;
    assert_true(isnan(get("base_stress_over_weight", &p).value));
    p.g_normal = -10;
    p.rho = NULL;
    assert_true(isnan(get("base_stress_over_weight", &p).value));
}

static void test_names_and_sets(void **state)
{
    (void)state;
    assert_int_equal(cg_scalar_lookup("flow_rate"), CG_SCALAR_FLOW_RATE);
    assert_int_equal(cg_scalar_lookup("flow"), -1);
    assert_string_equal(cg_scalar_set("shear_cell"),
                        "mean_phi,wall_shear_stress,wall_friction,gap,wall_slip");
    assert_string_equal(cg_scalar_set("filling"), "bed_height,mean_phi,base_stress_over_weight");
    assert_int_equal(cg_scalar_per_time(CG_SCALAR_BASE_STRESS_OVER_WEIGHT), 1);
    assert_int_equal(cg_scalar_per_time(CG_SCALAR_GAP), 0);
    assert_null(cg_scalar_set("chutes"));
    assert_int_equal(cg_scalar_per_time(CG_SCALAR_BED_HEIGHT), 1);
    assert_int_equal(cg_scalar_per_time(CG_SCALAR_LAYER_HEIGHT), 0);
    assert_null(cg_scalar_name(CG_SCALAR_COUNT));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_computed),           cmocka_unit_test(test_undefined),
        cmocka_unit_test(test_shear_cell_gap_and_slip), cmocka_unit_test(test_shear_cell_grid_ends),
        cmocka_unit_test(test_base_stress_over_weight), cmocka_unit_test(test_names_and_sets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
