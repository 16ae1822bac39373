/* The implicit pressure coupling of the normal momentum solve ([numerics]
 * normal_coupling, step.h, implicit.h): the steps it takes per model second
 * against the acoustic estimate computed from the run's own states (the
 * steps the explicit scheme's limit cfl dz / max(|w| + c) would have
 * needed), and its results against the explicit coupling's. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "control.h"
#include "testutil.h"

/* Per accepted step: its dt over the acoustic limit of the state it
 * started from (summed: the acoustic estimate of the step count), and
 * which limit of control.c the next step has. */
typedef struct {
    const ekm_scenario *sc;
    double t_prev, acoustic_prev; /* time and acoustic limit of the state before the step [s] */
    double acoustic_steps;        /* sum of dt / acoustic limit [-] */
    long steps;
    long by_limit[7]; /* LIMITS, then any other */
} step_count;

#define N_LIMITS 6
static const char *LIMITS[N_LIMITS] = {"convective",  "acoustic", "thermal relaxation", "solid relaxation",
                                       "compression", "dt_max"};

static ekm_status count_frame(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)st;
    (void)err;
    step_count *c = ctx;
    if (s->steps == 0) {
        c->t_prev = s->t;
        c->acoustic_prev = ekm_control_acoustic_dt(c->sc, s);
    }
    return EKM_OK;
}

static ekm_status count_step(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)st;
    (void)err;
    step_count *c = ctx;
    c->acoustic_steps += (s->t - c->t_prev) / c->acoustic_prev;
    c->steps++;
    c->t_prev = s->t;
    c->acoustic_prev = ekm_control_acoustic_dt(c->sc, s);
    ekm_dt_limit why;
    ekm_control_max_dt(c->sc, s, &why);
    int k = 0;
    while (k < N_LIMITS && strcmp(why.limit, LIMITS[k]) != 0)
        k++;
    c->by_limit[k]++;
    return EKM_OK;
}

static void set_counter_scenario(ekm_scenario *sc, void *ctx)
{
    ((step_count *)ctx)->sc = sc;
}

/* Run `scenario` with the overrides; the counts of its steps in *c. */
static void count_run(test_run *r, const char *scenario, const char *const *sets, size_t n_sets, step_count *c)
{
    memset(c, 0, sizeof *c);
    const ekm_run_hooks hooks = {.frame = count_frame, .step = count_step, .ctx = c};
    assert_int_equal(test_run_scenario_hooks(r, scenario, sets, n_sets, &hooks, set_counter_scenario, c), EKM_OK);
    printf("%s:", scenario);
    for (size_t i = 0; i < n_sets; i++)
        printf(" %s", sets[i]);
    printf("\n  %ld steps (%ld rejected), acoustic estimate %.0f (%.1fx); next step limited by:", c->steps,
           r->stats.rejected, c->acoustic_steps, c->acoustic_steps / c->steps);
    for (int k = 0; k <= N_LIMITS; k++)
        printf(" %s %ld", k < N_LIMITS ? LIMITS[k] : "other", c->by_limit[k]);
    printf("\n");
}

static void test_steps_shear_cell(void **state)
{
    (void)state;
    const char *sets[] = {"domain.cells=1000", "run.t_end=1", "run.output_dt=0.1", "run.stop=t_end"};
    test_run r;
    step_count c;
    count_run(&r, "scenarios/shear_cell.ini", sets, 4, &c);
    test_run_free(&r);
}

static void test_steps_chute(void **state)
{
    (void)state;
    const char *sets[] = {"domain.cells=1000", "run.t_end=1", "run.output_dt=0.1", "run.stop=t_end"};
    test_run r;
    step_count c;
    count_run(&r, "scenarios/chute.ini", sets, 4, &c);
    test_run_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_steps_shear_cell),
        cmocka_unit_test(test_steps_chute),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
