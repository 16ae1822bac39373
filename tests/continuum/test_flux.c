/* flux.c: every limiter of the registry against its closed form, the
 * upwind and TVD face fluxes and the face momentum flux on known profiles,
 * an unknown limiter refused with its message. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "flux.h"
#include "scenario.h"

static void assert_close(double got, double want, const char *what, double at)
{
    if (!(fabs(got - want) <= 1e-15 * fmax(1.0, fabs(want))))
        fail_msg("%s at %g: got %.17g, want %.17g", what, at, got, want);
}

/* The closed forms of the four limiters (LeVeque, Finite Volume Methods,
 * 6.12) at the slope ratios r = -1, 0, 0.5, 1, 2, 10. */
#define N_R 6
static const double R[N_R] = {-1.0, 0.0, 0.5, 1.0, 2.0, 10.0};
static const struct {
    const char *name;
    double psi[N_R];
} CLOSED_FORMS[] = {
    /* max(0, min(1, r)) */
    {"minmod", {0.0, 0.0, 0.5, 1.0, 1.0, 1.0}},
    /* (r + |r|)/(1 + |r|) */
    {"vanleer", {0.0, 0.0, 1.0 / 1.5, 1.0, 4.0 / 3.0, 20.0 / 11.0}},
    /* max(0, min(2r, 1), min(r, 2)) */
    {"superbee", {0.0, 0.0, 1.0, 1.0, 2.0, 2.0}},
    /* max(0, min(2r, (1 + r)/2, 2)) */
    {"mc", {0.0, 0.0, 0.75, 1.0, 1.5, 2.0}},
};
#define N_LIMITERS (sizeof CLOSED_FORMS / sizeof CLOSED_FORMS[0])

static void test_limiter_values(void **state)
{
    (void)state;
    for (size_t i = 0; i < N_LIMITERS; i++) {
        const ekm_limiter *lim = NULL;
        ekm_error err = {0};
        assert_int_equal(ekm_limiter_find(CLOSED_FORMS[i].name, &lim, &err), EKM_OK);
        assert_non_null(lim);
        assert_string_equal(lim->name, CLOSED_FORMS[i].name);
        for (int k = 0; k < N_R; k++)
            assert_close(lim->psi(R[k]), CLOSED_FORMS[i].psi[k], CLOSED_FORMS[i].name, R[k]);
    }
}

/* An unknown name: EKM_EINPUT with the key, the name and the known ones;
 * every known one listed has a closed form above (so the registry has no
 * limiter this file does not test). */
static void test_limiter_unknown(void **state)
{
    (void)state;
    const ekm_limiter *lim = NULL;
    ekm_error err = {0};
    assert_int_equal(ekm_limiter_find("koren", &lim, &err), EKM_EINPUT);
    assert_null(lim);
    assert_string_equal(err.message,
                        "[numerics] limiter: unknown limiter 'koren' (known: minmod vanleer superbee mc)");
    const char *known = strstr(err.message, "(known:");
    assert_non_null(known);
    char list[256];
    snprintf(list, sizeof list, "%s", known + strlen("(known:"));
    list[strcspn(list, ")")] = '\0';
    size_t listed = 0;
    for (char *name = strtok(list, " "); name; name = strtok(NULL, " ")) {
        size_t i = 0;
        while (i < N_LIMITERS && strcmp(CLOSED_FORMS[i].name, name) != 0)
            i++;
        if (i == N_LIMITERS)
            fail_msg("limiter '%s' of the registry has no closed form in this test", name);
        listed++;
    }
    assert_int_equal(listed, N_LIMITERS);
}

/* The scenario's list of limiters (EKM_SCENARIO_LIMITERS, what the reader
 * accepts) and the solver's registry name the same limiters: each listed
 * one is found, and the registry's own list (its unknown-name message)
 * is the scenario's, in the same order. */
static void test_limiter_list_is_the_scenarios(void **state)
{
    (void)state;
    char list[128];
    snprintf(list, sizeof list, "%s", EKM_SCENARIO_LIMITERS);
    size_t n = 0;
    for (char *name = strtok(list, " "); name; name = strtok(NULL, " ")) {
        const ekm_limiter *lim = NULL;
        ekm_error err = {0};
        assert_int_equal(ekm_limiter_find(name, &lim, &err), EKM_OK);
        assert_string_equal(lim->name, name);
        n++;
    }
    assert_int_equal(n, N_LIMITERS);
    ekm_error err = {0};
    const ekm_limiter *lim = NULL;
    assert_int_equal(ekm_limiter_find("none", &lim, &err), EKM_EINPUT);
    char want[256];
    snprintf(want, sizeof want, "[numerics] limiter: unknown limiter 'none' (known: %s)",
             EKM_SCENARIO_LIMITERS);
    assert_string_equal(err.message, want);
}

/* q_j = j^2 on 5 cells; inflow values -1 (bottom) and 20 (top). */
#define N 5
static const double Q[N] = {0.0, 1.0, 4.0, 9.0, 16.0};
static const double Q_IN_BOTTOM = -1.0, Q_IN_TOP = 20.0;

static void check_fluxes(const double *F, ekm_limiter_fn psi, const double *want, const char *what)
{
    double qF[N + 1];
    ekm_flux_advect(N, F, Q, Q_IN_BOTTOM, Q_IN_TOP, psi, qF);
    for (int f = 0; f <= N; f++)
        assert_close(qF[f], want[f], what, f);
}

/* Upwind: F q_up; the entering flux carries the inflow value, the leaving
 * one the adjacent cell's. */
static void test_upwind_fluxes(void **state)
{
    (void)state;
    const double up[N + 1] = {2, 2, 2, 2, 2, 2}, down[N + 1] = {-2, -2, -2, -2, -2, -2};
    const double want_up[N + 1] = {2 * Q_IN_BOTTOM, 2 * 0.0, 2 * 1.0, 2 * 4.0, 2 * 9.0, 2 * 16.0};
    const double want_down[N + 1] = {-2 * 0.0, -2 * 1.0, -2 * 4.0, -2 * 9.0, -2 * 16.0, -2 * Q_IN_TOP};
    check_fluxes(up, NULL, want_up, "upwind, upward flow");
    check_fluxes(down, NULL, want_down, "upwind, downward flow");
    /* a face without flow carries nothing */
    const double mixed[N + 1] = {0, 1, 0, -1, 0, 0};
    const double want_mixed[N + 1] = {0, 0.0, 0, -9.0, 0, 0};
    check_fluxes(mixed, NULL, want_mixed, "upwind, mixed flow");
}

/* TVD (minmod): q_f = q_up + psi(r)/2 (q_down - q_up), r = (q_up - q_upup)/(q_down - q_up);
 * first order where the cell behind the upwind one is missing.
 *   upward,   face 2: r = 1/3, q_f = 1 + 1/6 * 3 = 1.5;  face 3: r = 3/5, 5.5;  face 4: r = 5/7, 11.5
 *   downward, face 3: r = 7/5 -> psi 1, 6.5;  face 2: r = 5/3, 2.5;  face 1: r = 3, 0.5 */
static void test_tvd_fluxes(void **state)
{
    (void)state;
    const ekm_limiter *lim = NULL;
    ekm_error err = {0};
    assert_int_equal(ekm_limiter_find("minmod", &lim, &err), EKM_OK);
    const double up[N + 1] = {2, 2, 2, 2, 2, 2}, down[N + 1] = {-2, -2, -2, -2, -2, -2};
    const double want_up[N + 1] = {2 * Q_IN_BOTTOM, 2 * 0.0, 2 * 1.5, 2 * 5.5, 2 * 11.5, 2 * 16.0};
    const double want_down[N + 1] = {-2 * 0.0, -2 * 0.5, -2 * 2.5, -2 * 6.5, -2 * 16.0, -2 * Q_IN_TOP};
    check_fluxes(up, lim->psi, want_up, "minmod, upward flow");
    check_fluxes(down, lim->psi, want_down, "minmod, downward flow");
    /* the face value itself, with superbee at face 3 upward: r = 3/5,
     * psi = max(min(6/5, 1), min(3/5, 2)) = 1: q_f = 4 + 5/2 */
    assert_int_equal(ekm_limiter_find("superbee", &lim, &err), EKM_OK);
    assert_close(ekm_flux_face_value(Q, N, 3, 1, lim->psi), 6.5, "superbee face value", 3);
    /* a flat profile (q_down = q_up) is the upwind value */
    const double flat[N] = {3, 3, 3, 3, 3};
    assert_close(ekm_flux_face_value(flat, N, 2, 1, lim->psi), 3.0, "flat profile", 2);
}

/* Face momentum: out_j = Fc_j w_up, Fc_j = (F_j + F_{j+1})/2, w_up = w_j
 * (the face below) for Fc > 0, w_{j+1} otherwise. */
static void test_face_momentum(void **state)
{
    (void)state;
    const double F[N + 1] = {1, 3, -1, -5, 2, 0};
    const double w[N + 1] = {10, 20, 30, 40, 50, 60};
    const double want[N] = {2 * 10, 1 * 20, -3 * 40, -1.5 * 50, 1 * 50};
    double out[N];
    ekm_flux_face_momentum(N, F, w, out);
    for (int j = 0; j < N; j++)
        assert_close(out[j], want[j], "face momentum", j);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_limiter_values),
        cmocka_unit_test(test_limiter_unknown),
        cmocka_unit_test(test_limiter_list_is_the_scenarios),
        cmocka_unit_test(test_upwind_fluxes),
        cmocka_unit_test(test_tvd_fluxes),
        cmocka_unit_test(test_face_momentum),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
