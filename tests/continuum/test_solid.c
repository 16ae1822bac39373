/* The solid (hypoplastic) regime inside the solver: filling ends at rest,
 * switches are continuous, the driven cycle, the tilting layer and the
 * thesis column (docs/model.md, "Solid regime"). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fields.h"
#include "hypo.h"
#include "testutil.h"

/* Filling: the inflow stops at 0.5 s; by t = 10 s every cell of the bed
 * (from the floor up to the first cell with phi < 0.01) is solid, |w| <
 * 1e-9 m/s on every face of the bed, and the bottom normal stress carries
 * the bed's weight to 1e-6.  The dilute tail of the stream (phi < 1e-4,
 * empty cells by the scenario's phi_dry) stays where it was when its cells
 * became empty: reported, and bounded. */
static void test_filling_ends_at_rest(void **state)
{
    (void)state;
    const char *sets[] = {"run.t_end=10", "run.output_dt=0.5"};
    test_run r;
    assert_int_equal(test_run_scenario(&r, "scenarios/filling.ini", sets, 2, NULL, NULL), EKM_OK);
    const ekm_state *s = r.s;
    const ekm_material *m = &r.sc.material;
    int top = 0; /* cells 0..top-1 form the bed */
    while (top < s->n && s->phi[top] >= 0.01)
        top++;
    double w_max = 0.0, weight = 0.0, gas = 0.0, w_gas = 0.0;
    int solid = 0, dense = 0;
    for (int f = 0; f <= top; f++)
        w_max = fmax(w_max, fabs(s->w[f]));
    for (int f = top + 1; f <= s->n; f++)
        w_gas = fmax(w_gas, fabs(s->w[f]));
    for (int j = 0; j < s->n; j++) {
        const double wj = m->rho_p * s->phi[j] * r.sc.gravity * s->dz;
        if (j < top) {
            weight += wj;
            solid += s->solid[j];
            dense += s->phi[j] > m->phi_co;
        } else {
            gas += wj;
        }
    }
    /* the empty cell on the surface: its lower half rests on the bed (the
     * momentum control volume of the surface face) */
    if (top < s->n)
        weight += 0.5 * m->rho_p * s->phi[top] * r.sc.gravity * s->dz;
    /* bottom normal stress: cell 0's stress extrapolated to the floor */
    const double bottom = -s->szz[0] + m->rho_p * s->phi[0] * r.sc.gravity * s->dz / 2;
    printf("filling: bed of %d cells (%d with phi > phi_co, surface cell phi %.4f), %d solid; max |w| in the bed "
           "%.2e m/s; bed weight %.10g Pa, bottom stress %.10g Pa (rel %.2e); remnant above: %.2e of the weight, "
           "max |w| %.2e m/s; switches %ld/%ld, jump max %.2e\n",
           top, dense, s->phi[top - 1], solid, w_max, weight, bottom, bottom / weight - 1, gas / weight, w_gas,
           r.stats.to_solid, r.stats.to_flow, r.stats.jump_max);
    if (solid != top || w_max >= 1e-9)
        for (int j = 0; j <= top && j < s->n; j++)
            printf("  %3d phi %.6f solid %d T %.3e w %.3e szz %.6g\n", j, s->phi[j], s->solid[j], s->T[j], s->w[j],
                   s->szz[j]);
    assert_true(dense > 10);
    assert_int_equal(solid, top);
    assert_true(w_max < 1e-9);
    assert_true(fabs(bottom / weight - 1.0) < 1e-6);
    assert_true(gas / weight < 5e-4); /* measured 2.3e-4 */
    assert_true(r.stats.jump_max < 1e-3);
    test_run_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_filling_ends_at_rest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
