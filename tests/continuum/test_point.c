/* point.h: the agreement measure of two states on hand-made profiles; a
 * scenario given another material (ekm_scenario_set_material) checked as
 * its [material] would be; the steady policy (ekm_point_solve): Newton's
 * state, the same with the check against a run, and time stepping for a
 * scenario that does not stop when steady. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "point.h"
#include "state.h"
#include "steady_solve.h"
#include "testutil.h"

#define N 6

/* Two columns: material in cells 0-3 (phi 0.5), a dilute tail in 4-5
 * (phi 1e-3: below 0.1 x 0.5, outside the common support). */
static void fill(double *phi, double *vx, double *T, double *P)
{
    for (int j = 0; j < N; j++) {
        phi[j] = j < 4 ? 0.5 : 1e-3;
        vx[j] = 0.1 * (j + 1);
        T[j] = 1e-4 * (j + 1);
        P[j] = 100.0 * (N - j);
    }
}

static void test_agreement_measure(void **state)
{
    (void)state;
    double pa[N], va[N], Ta[N], Pa[N], pb[N], vb[N], Tb[N], Pb[N];
    fill(pa, va, Ta, Pa);
    fill(pb, vb, Tb, Pb);
    ekm_point_view a = {N, pa, va, Ta, Pa, NAN}, b = {N, pb, vb, Tb, Pb, NAN};
    const char *where = NULL;
    assert_true(ekm_point_agreement(&a, &b, &where) == 0.0);
    /* vx of a supported cell 3 % off the run's largest vx in the support (0.4) */
    va[2] += 0.03 * 0.4;
    assert_true(fabs(ekm_point_agreement(&a, &b, &where) - 0.03) < 1e-12);
    assert_string_equal(where, "vx");
    /* T in the dilute tail: outside the support, not counted */
    Ta[5] *= 100.0;
    assert_true(fabs(ekm_point_agreement(&a, &b, &where) - 0.03) < 1e-12);
    /* phi counts over the whole column: the tail's phi doubled is 2e-3 / 0.5 */
    pa[5] = 2e-3;
    assert_true(fabs(ekm_point_agreement(&a, &b, &where) - 0.03) < 1e-12);
    pa[5] = 1e-3 + 0.05 * 0.5;
    assert_true(fabs(ekm_point_agreement(&a, &b, &where) - 0.05) < 1e-12);
    assert_string_equal(where, "phi");
    /* the gap of a pressure-held wall, relative */
    a.gap = 0.0308;
    b.gap = 0.0280;
    assert_true(fabs(ekm_point_agreement(&a, &b, &where) - 0.1) < 1e-12);
    assert_string_equal(where, "gap");
    /* no cell with material in both */
    for (int j = 0; j < N; j++)
        pa[j] = 0.0;
    assert_true(isinf(ekm_point_agreement(&a, &b, &where)));
    assert_string_equal(where, "support");
}

/* Another material: accepted and kept; one the scenario refuses (phi_cp
 * below its initial phi 0.55) is EKM_EINPUT naming the key, and leaves the
 * scenario's material as it was. */
static void test_set_material(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, test_path("scenarios/simple_shear.ini"), NULL, 0, &err), EKM_OK);
    const ekm_material before = sc.material;
    ekm_material m = sc.material;
    m.eta0 *= 2.0;
    assert_int_equal(ekm_scenario_set_material(&sc, &m, &err), EKM_OK);
    assert_true(sc.material.eta0 == 2.0 * before.eta0);
    ekm_material bad = before;
    bad.phi_cp = 0.54;
    bad.phi_co = 0.5;
    assert_int_equal(ekm_scenario_set_material(&sc, &bad, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "[initial] phi: expected a volume fraction in [0, phi_cp)"));
    assert_true(sc.material.eta0 == 2.0 * before.eta0 && sc.material.phi_cp == before.phi_cp);
    ekm_scenario_free(&sc);
}

/* simple_shear stops when steady: its point is Newton's state (the same
 * numbers as ekm_steady_solve's from the initial state), and with the check
 * the run ends steady, agrees within the tolerance, and the state kept is
 * the same one. */
static void test_steady_scenario(void **state)
{
    (void)state;
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, test_path("scenarios/simple_shear.ini"), NULL, 0, &err), EKM_OK);
    ekm_state *s = ekm_state_alloc(sc.cells, sc.length);
    assert_non_null(s);
    ekm_state_init(s, &sc);
    assert_int_equal(ekm_steady_solve(&sc, s, NULL, &err), EKM_OK);

    ekm_point p, q;
    assert_int_equal(ekm_point_solve(&sc, &sc.material, 0, &p, &err), EKM_OK);
    assert_int_equal(p.solver, EKM_POINT_NEWTON);
    assert_int_equal(p.checked, 0);
    assert_int_equal((int)p.n, s->n);
    for (int j = 0; j < s->n; j++)
        assert_true(p.phi[j] == s->phi[j] && p.vx[j] == s->u[j] && p.T[j] == s->T[j] && p.z[j] == s->z[j]);

    assert_int_equal(ekm_point_solve(&sc, &sc.material, 1, &q, &err), EKM_OK);
    printf("  simple_shear: Newton against the run: %.3g of the run's maxima\n", q.agreement);
    assert_int_equal(q.checked, 1);
    assert_int_equal(q.run_steady, 1);
    assert_true(q.agreement <= EKM_POINT_AGREE_TOL);
    assert_int_equal(q.solver, EKM_POINT_NEWTON);
    for (size_t j = 0; j < p.n; j++)
        assert_true(q.phi[j] == p.phi[j] && q.P[j] == p.P[j] && q.sxz[j] == p.sxz[j]);
    ekm_point_free(&p);
    ekm_point_free(&q);
    ekm_state_free(s);
    ekm_scenario_free(&sc);
}

/* A scenario that runs to t_end is time-stepped (never checked); a refused
 * material is the scenario's error. */
static void test_stop_at_t_end(void **state)
{
    (void)state;
    const char *sets[] = {"run.stop=t_end", "run.t_end=0.2"};
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, test_path("scenarios/simple_shear.ini"), sets, 2, &err), EKM_OK);
    ekm_point p;
    assert_int_equal(ekm_point_solve(&sc, &sc.material, 1, &p, &err), EKM_OK);
    assert_int_equal(p.solver, EKM_POINT_RUN);
    assert_int_equal(p.checked, 0);
    for (size_t j = 0; j < p.n; j++)
        assert_true(isfinite(p.phi[j]) && isfinite(p.T[j]) && p.T[j] > 0.0 && isfinite(p.P[j]));
    ekm_point_free(&p);
    ekm_material bad = sc.material;
    bad.eta0 = -1.0;
    assert_int_equal(ekm_point_solve(&sc, &bad, 0, &p, &err), EKM_EINPUT);
    assert_non_null(strstr(err.message, "eta0"));
    assert_null(p.z);
    ekm_scenario_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_agreement_measure),
        cmocka_unit_test(test_set_material),
        cmocka_unit_test(test_steady_scenario),
        cmocka_unit_test(test_stop_at_t_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
