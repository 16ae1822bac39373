/* `ekm homog` (continuum/homog_cli.c): every value it prints equals
 * ekm_homog_shear's for the same material and variant (exactly: the JSON
 * has 17 significant digits), with the scenario's own [material] and with
 * --material FIT.ini plus --set; points with phi >= phi_cp have status
 * "no_steady_state" and a reason; the grid is LO..HI inclusive, phi-major. */
#include <jansson.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "closure.h"
#include "homogeneous.h"
#include "scenario.h"

/* Run `ekm homog ARGS` and parse its stdout (asserts exit 0, valid JSON). */
static json_t *run_homog(const char *args)
{
    char cmd[2048], out[1024];
    snprintf(out, sizeof out, "%s/homog_cli_test.json", EKM_BINARY_DIR);
    snprintf(cmd, sizeof cmd, "'%s' homog %s > '%s'", EKM_BINARY, args, out);
    assert_int_equal(system(cmd), 0);
    json_error_t jerr;
    json_t *root = json_load_file(out, 0, &jerr);
    if (!root)
        fail_msg("%s: not JSON: %s (line %d)", out, jerr.text, jerr.line);
    return root;
}

static double number(const json_t *obj, const char *key)
{
    const json_t *v = json_object_get(obj, key);
    if (!json_is_number(v))
        fail_msg("key '%s': expected a number", key);
    return json_number_value(v);
}

/* Every point of the output against ekm_homog_shear of sc. */
static void check_points(const json_t *root, const ekm_scenario *sc, double lo, double hi, int n_phi,
                         const double *rates, int n_rates)
{
    const json_t *pts = json_object_get(root, "points");
    assert_true(json_is_array(pts));
    assert_int_equal(json_array_size(pts), (size_t)(n_phi * n_rates));
    int ok = 0, none = 0;
    for (int i = 0; i < n_phi; i++) {
        const double phi = lo + (hi - lo) * i / (n_phi - 1);
        for (int j = 0; j < n_rates; j++) {
            const json_t *p = json_array_get(pts, (size_t)(i * n_rates + j));
            assert_true(number(p, "phi") == phi);
            assert_true(number(p, "rate") == rates[j]);
            const char *status = json_string_value(json_object_get(p, "status"));
            assert_non_null(status);
            ekm_homog_state h;
            ekm_error err = {0};
            if (ekm_homog_shear(&sc->material, sc->variant, phi, rates[j], &h, &err) != EKM_OK) {
                assert_true(phi >= sc->material.phi_cp);
                assert_string_equal(status, "no_steady_state");
                assert_string_equal(json_string_value(json_object_get(p, "reason")), err.message);
                assert_null(json_object_get(p, "P"));
                none++;
                continue;
            }
            assert_string_equal(status, "ok");
            assert_true(number(p, "T") == h.T);
            assert_true(number(p, "P") == h.P);
            assert_true(number(p, "P_K") == h.P_K);
            assert_true(number(p, "P_Y") == h.P_Y);
            assert_true(number(p, "abs_sxz") == h.sxz);
            assert_true(number(p, "mu") == h.mu);
            ok++;
        }
    }
    /* the grids below reach phi_cp and cross phi_co (P_Y > 0 somewhere) */
    assert_true(ok > 0 && none > 0);
}

static void test_scenario_material(void **state)
{
    (void)state;
    char args[1024], ini[600];
    snprintf(ini, sizeof ini, "%s/scenarios/simple_shear.ini", EKM_SOURCE_DIR);
    snprintf(args, sizeof args, "'%s' --phi 0.40:0.66:14 --rate 0.3,10,30 --json", ini);
    json_t *root = run_homog(args);
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, ini, NULL, 0, &err), EKM_OK);
    const double rates[] = {0.3, 10.0, 30.0};
    check_points(root, &sc, 0.40, 0.66, 14, rates, 3);
    assert_true(json_is_null(json_object_get(root, "material_file")));
    assert_string_equal(json_string_value(json_object_get(root, "variant")), "full");
    const json_t *mat = json_object_get(root, "material");
    assert_true(number(mat, "eta0") == sc.material.eta0);
    assert_true(number(mat, "phi_cp") == sc.material.phi_cp);
    const json_t *units = json_object_get(root, "units");
    assert_string_equal(json_string_value(json_object_get(units, "P")), "Pa");
    assert_string_equal(json_string_value(json_object_get(units, "T")), "m^2/s^2");
    assert_string_equal(json_string_value(json_object_get(units, "rate")), "1/s");
    ekm_scenario_free(&sc);
    json_decref(root);
}

static void test_material_file_and_set(void **state)
{
    (void)state;
    char fit[600], ini[600], args[2048];
    snprintf(fit, sizeof fit, "%s/homog_cli_fit.ini", EKM_BINARY_DIR);
    snprintf(ini, sizeof ini, "%s/scenarios/simple_shear.ini", EKM_SOURCE_DIR);
    FILE *fp = fopen(fit, "w");
    assert_non_null(fp);
    /* a fitted material unlike the scenario's: lower phi_co, nu != 1 */
    fputs("[material]\nrho_p = 2500\nphi_co = 0.52\nphi_cp = 0.65\nT0 = 2.2\neta0 = 5.1e-4\n"
          "zeta0 = 1e-4\nlambda0 = 3.4e-4\neps0 = 180\nnu = 0.4\nA_h = 200e6\nB_h = 200e6\nalpha = 0\n",
          fp);
    assert_int_equal(fclose(fp), 0);
    snprintf(args, sizeof args,
             "'%s' --material '%s' --set model.variant=thesis --set material.T0=3 --phi 0.45:0.66:8 --rate 5 "
             "--json",
             ini, fit);
    json_t *root = run_homog(args);
    const char *sets[] = {"model.variant=thesis", "material.T0=3"};
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load_material(&sc, ini, fit, sets, 2, &err), EKM_OK);
    assert_true(sc.material.T0 == 3.0 && sc.material.nu == 0.4);
    const double rates[] = {5.0};
    check_points(root, &sc, 0.45, 0.66, 8, rates, 1);
    assert_string_equal(json_string_value(json_object_get(root, "material_file")), fit);
    assert_string_equal(json_string_value(json_object_get(root, "variant")), "thesis");
    /* nu = 0.4 above phi_co: mu below the nu = 1 value sqrt(3 eta0 eps0 / (2 phi)) */
    const json_t *p = json_array_get(json_object_get(root, "points"), 6);
    const double phi = number(p, "phi");
    assert_true(phi > 0.52 && number(p, "P_Y") > 0.0);
    assert_true(number(p, "mu") < sqrt(3.0 * 5.1e-4 * 180.0 / (2.0 * phi)));
    ekm_scenario_free(&sc);
    json_decref(root);
}

/* A closure without a temperature (mu_i): the scenario read with a mu_i
 * material file and --set model.closure=mu_i (overriding the file's
 * variant); T, P_K, P_Y null, P and |sxz| equal to the closure's steady
 * shear bit for bit and to the closed form P = rho_p (d gdot / I)^2,
 * I = (phi_max - phi)/(phi_max - phi_min); phi_max itself has no steady
 * state. */
static void test_mu_i_closure(void **state)
{
    (void)state;
    char mat[600], ini[600], args[2048];
    snprintf(mat, sizeof mat, "%s/homog_cli_mu_i.ini", EKM_BINARY_DIR);
    snprintf(ini, sizeof ini, "%s/scenarios/simple_shear.ini", EKM_SOURCE_DIR);
    FILE *fp = fopen(mat, "w");
    assert_non_null(fp);
    fputs("[material]\nrho_p = 2500\nmu_s = 0.38\nmu_2 = 0.64\nI_0 = 0.28\nphi_max = 0.6\nphi_min = 0.4\n"
          "d = 0.002\n",
          fp);
    assert_int_equal(fclose(fp), 0);
    snprintf(args, sizeof args,
             "'%s' --material '%s' --set model.closure=mu_i --phi 0.5:0.6:5 --rate 10,40 --json", ini, mat);
    json_t *root = run_homog(args);
    assert_string_equal(json_string_value(json_object_get(root, "closure")), "mu_i");
    assert_true(json_is_null(json_object_get(root, "variant")));
    const json_t *material = json_object_get(root, "material");
    assert_int_equal(json_object_size(material), 7);
    assert_true(number(material, "d") == 0.002);
    const char *sets[] = {"model.closure=mu_i"};
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load_material(&sc, ini, mat, sets, 1, &err), EKM_OK);
    const json_t *pts = json_object_get(root, "points");
    assert_int_equal(json_array_size(pts), 10);
    for (size_t i = 0; i < 10; i++) {
        const json_t *p = json_array_get(pts, i);
        const double phi = number(p, "phi"), rate = number(p, "rate");
        const char *status = json_string_value(json_object_get(p, "status"));
        if (i >= 8) { /* phi = phi_max */
            assert_string_equal(status, "no_steady_state");
            assert_non_null(strstr(json_string_value(json_object_get(p, "reason")), "phi_max = 0.6"));
            continue;
        }
        assert_string_equal(status, "ok");
        assert_true(json_is_null(json_object_get(p, "T")) && json_is_null(json_object_get(p, "P_K")) &&
                    json_is_null(json_object_get(p, "P_Y")));
        ekm_homog_state h;
        assert_int_equal(ekm_closure_homog(sc.closure, &sc.material, phi, rate, &h, &err), EKM_OK);
        assert_true(number(p, "P") == h.P && number(p, "abs_sxz") == h.sxz && number(p, "mu") == h.mu);
        const double I = (0.6 - phi) / 0.2, P = 2500.0 * pow(0.002 * rate / I, 2.0);
        assert_true(fabs(h.P / P - 1.0) < 1e-13);
    }
    ekm_scenario_free(&sc);
    json_decref(root);
}

static void test_single_phi(void **state)
{
    (void)state;
    char args[1024];
    snprintf(args, sizeof args, "'%s/scenarios/simple_shear.ini' --phi 0.55:0.55:1 --rate 10 --json",
             EKM_SOURCE_DIR);
    json_t *root = run_homog(args);
    const json_t *pts = json_object_get(root, "points");
    assert_int_equal(json_array_size(pts), 1);
    assert_true(number(json_array_get(pts, 0), "phi") == 0.55);
    json_decref(root);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scenario_material),
        cmocka_unit_test(test_material_file_and_set),
        cmocka_unit_test(test_single_phi),
        cmocka_unit_test(test_mu_i_closure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
