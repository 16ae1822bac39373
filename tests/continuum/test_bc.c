/* bc.c: every boundary kind (bc.h) at both ends: the face's normal
 * velocity (prescribed or following the interior face), the values carried
 * in, the wall conductance and wall velocity. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "bc.h"

#define N      4
#define LENGTH 0.2 /* m: dz = 0.05 m */

/* A state with distinct values in every cell and face. */
static ekm_state *make_state(void)
{
    ekm_state *s = ekm_state_alloc(N, LENGTH);
    assert_non_null(s);
    for (int j = 0; j < N; j++) {
        s->phi[j] = 0.1 * (j + 1);
        s->u[j] = 1.0 + j;
        s->T[j] = 0.01 * (j + 1);
    }
    for (int f = 0; f <= N; f++)
        s->w[f] = -0.5 + 0.25 * f;
    return s;
}

static void assert_exact(double got, double want, const char *what)
{
    if (!(got == want || fabs(got - want) <= 1e-15 * fabs(want)))
        fail_msg("%s: got %.17g, want %.17g", what, got, want);
}

static void test_wall(void **state)
{
    (void)state;
    ekm_state *s = make_state();
    const double dz = LENGTH / N;
    ekm_bc bc = {.kind = EKM_BC_WALL, .velocity = 0.3, .slip_length = 0.0};
    for (int side = EKM_SIDE_BOTTOM; side <= EKM_SIDE_TOP; side++) {
        bc.slip_length = 0.0;
        ekm_bc_face b = ekm_bc_evaluate(&bc, (ekm_side)side, 1.0, s);
        assert_int_equal(b.w_follows, 0);
        assert_exact(ekm_bc_face_w(&b, (ekm_side)side, s), 0.0, "wall w");
        assert_exact(b.wall_conductance, 1.0 / (0.5 * dz), "no-slip conductance 1/(dz/2)");
        assert_exact(b.u_wall, 0.3, "wall velocity");
        assert_exact(b.phi_in, 0.0, "wall phi_in");
        /* Navier slip b = 0.02 m: tau = eta (u_wall - u)/(dz/2 + b) */
        bc.slip_length = 0.02;
        b = ekm_bc_evaluate(&bc, (ekm_side)side, 1.0, s);
        assert_exact(b.wall_conductance, 1.0 / (0.5 * dz + 0.02), "slip conductance 1/(dz/2 + b)");
        assert_exact(b.u_wall, 0.3, "slip wall velocity");
        assert_exact(ekm_bc_face_w(&b, (ekm_side)side, s), 0.0, "slip wall w");
    }
    ekm_state_free(s);
}

/* Inflow: w_in with phi, u, T carried in, no shear, until t_stop; from
 * t_stop a resting no-slip wall. */
static void test_inflow(void **state)
{
    (void)state;
    ekm_state *s = make_state();
    const double dz = LENGTH / N;
    const ekm_bc bc = {.kind = EKM_BC_INFLOW,
                       .w = -0.04,
                       .phi = 0.3,
                       .u = 0.7,
                       .T = 2e-3,
                       .t_stop = 5.0,
                       .velocity = 0.9,
                       .slip_length = 0.1};
    for (int side = EKM_SIDE_BOTTOM; side <= EKM_SIDE_TOP; side++) {
        ekm_bc_face b = ekm_bc_evaluate(&bc, (ekm_side)side, 4.999, s);
        assert_int_equal(b.w_follows, 0);
        assert_exact(ekm_bc_face_w(&b, (ekm_side)side, s), -0.04, "inflow w");
        assert_exact(b.phi_in, 0.3, "inflow phi");
        assert_exact(b.u_in, 0.7, "inflow u");
        assert_exact(b.T_in, 2e-3, "inflow T");
        assert_exact(b.wall_conductance, 0.0, "inflow: no shear");
        /* closed: at and after t_stop a resting no-slip wall (the inflow's
         * velocity and slip_length keys do not apply) */
        for (double t = 5.0; t <= 6.0; t += 1.0) {
            b = ekm_bc_evaluate(&bc, (ekm_side)side, t, s);
            assert_int_equal(b.w_follows, 0);
            assert_exact(ekm_bc_face_w(&b, (ekm_side)side, s), 0.0, "closed inflow w");
            assert_exact(b.phi_in, 0.0, "closed inflow phi");
            assert_exact(b.u_wall, 0.0, "closed inflow wall velocity");
            assert_exact(b.wall_conductance, 1.0 / (0.5 * dz), "closed inflow: no-slip conductance");
        }
    }
    ekm_state_free(s);
}

/* Outflow: zero gradient of w, phi, u, T: the face takes the interior
 * face's w and carries the adjacent cell's values; no shear. */
static void test_outflow(void **state)
{
    (void)state;
    ekm_state *s = make_state();
    const ekm_bc bc = {.kind = EKM_BC_OUTFLOW};
    ekm_bc_face b = ekm_bc_evaluate(&bc, EKM_SIDE_BOTTOM, 0.0, s);
    assert_int_equal(b.w_follows, 1);
    assert_exact(ekm_bc_face_w(&b, EKM_SIDE_BOTTOM, s), s->w[1], "outflow bottom w = w_1");
    assert_exact(b.phi_in, s->phi[0], "outflow bottom phi");
    assert_exact(b.u_in, s->u[0], "outflow bottom u");
    assert_exact(b.T_in, s->T[0], "outflow bottom T");
    assert_exact(b.wall_conductance, 0.0, "outflow: no shear");
    b = ekm_bc_evaluate(&bc, EKM_SIDE_TOP, 0.0, s);
    assert_int_equal(b.w_follows, 1);
    assert_exact(ekm_bc_face_w(&b, EKM_SIDE_TOP, s), s->w[N - 1], "outflow top w = w_{n-1}");
    assert_exact(b.phi_in, s->phi[N - 1], "outflow top phi");
    assert_exact(b.u_in, s->u[N - 1], "outflow top u");
    assert_exact(b.T_in, s->T[N - 1], "outflow top T");
    assert_exact(b.wall_conductance, 0.0, "outflow: no shear");
    ekm_state_free(s);
}

/* Free: open to vacuum: w follows the interior, nothing enters, no stress. */
static void test_free_surface(void **state)
{
    (void)state;
    ekm_state *s = make_state();
    const ekm_bc bc = {.kind = EKM_BC_FREE};
    for (int side = EKM_SIDE_BOTTOM; side <= EKM_SIDE_TOP; side++) {
        const ekm_bc_face b = ekm_bc_evaluate(&bc, (ekm_side)side, 0.0, s);
        assert_int_equal(b.w_follows, 1);
        assert_exact(ekm_bc_face_w(&b, (ekm_side)side, s), side == EKM_SIDE_BOTTOM ? s->w[1] : s->w[N - 1],
                     "free w");
        assert_exact(b.phi_in, 0.0, "free: vacuum enters");
        assert_exact(b.u_in, 0.0, "free u_in");
        assert_exact(b.T_in, 0.0, "free T_in");
        assert_exact(b.wall_conductance, 0.0, "free: stress-free");
    }
    ekm_state_free(s);
}

/* Piston of period 2 s: w in [0, 1) s, w_return in [1, 2) s (a step that
 * starts at a reversal takes the new velocity), -w when w_return is unset;
 * zero gradient of phi, u, T; no slip with the piston at rest tangentially. */
static void test_piston(void **state)
{
    (void)state;
    ekm_state *s = make_state();
    const double dz = LENGTH / N;
    ekm_bc bc = {.kind = EKM_BC_PISTON, .w = 0.01, .period = 2.0, .w_return = -0.03};
    const struct {
        double t, w;
    } program[] = {{0.0, 0.01},    {0.5, 0.01}, {0.999, 0.01}, {1.0, -0.03}, {1.5, -0.03},
                   {1.999, -0.03}, {2.0, 0.01}, {2.5, 0.01},   {3.25, -0.03}};
    for (int side = EKM_SIDE_BOTTOM; side <= EKM_SIDE_TOP; side++) {
        const int j = side == EKM_SIDE_BOTTOM ? 0 : N - 1;
        for (size_t k = 0; k < sizeof program / sizeof program[0]; k++) {
            const ekm_bc_face b = ekm_bc_evaluate(&bc, (ekm_side)side, program[k].t, s);
            assert_int_equal(b.w_follows, 0);
            char what[64];
            snprintf(what, sizeof what, "piston w at t = %g s", program[k].t);
            assert_exact(ekm_bc_face_w(&b, (ekm_side)side, s), program[k].w, what);
            assert_exact(b.phi_in, s->phi[j], "piston phi");
            assert_exact(b.u_in, s->u[j], "piston u");
            assert_exact(b.T_in, s->T[j], "piston T");
            assert_exact(b.wall_conductance, 1.0 / (0.5 * dz), "piston: no slip");
            assert_exact(b.u_wall, 0.0, "piston wall velocity");
        }
    }
    bc.w_return = NAN;
    assert_exact(ekm_bc_evaluate(&bc, EKM_SIDE_TOP, 1.5, s).w, -0.01, "piston w_return unset: -w");
    assert_exact(ekm_bc_evaluate(&bc, EKM_SIDE_TOP, 0.5, s).w, 0.01, "piston first half");
    ekm_state_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wall),         cmocka_unit_test(test_inflow), cmocka_unit_test(test_outflow),
        cmocka_unit_test(test_free_surface), cmocka_unit_test(test_piston),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
