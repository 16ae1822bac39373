/* test_step_alloc: the time loop allocates nothing (issue 12, item 3).
 *
 * The test program replaces the C allocator (malloc, calloc, realloc,
 * free and the aligned forms, glibc's documented way to replace malloc:
 * they forward to glibc's own __libc_* entry points) and counts every
 * allocation, including those of the libraries the solver calls (LAPACK,
 * GSL, libm).  Each scenario is loaded and its state and stepper
 * allocated, then the whole of ekm_run (step-size control, every step,
 * the rejected ones too) must make no allocation at all: the count after
 * the last step equals the count before the run.  The counter is the one
 * global of this test: an allocator has no context argument.
 *
 * Not built with the sanitizers (EKM_SANITIZE): they replace the
 * allocator themselves. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "run.h"
#include "scenario.h"
#include "state.h"
#include "step.h"
#include "testutil.h"

extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t count, size_t size);
extern void *__libc_realloc(void *p, size_t size);
extern void *__libc_memalign(size_t alignment, size_t size);
extern void __libc_free(void *p);

static long allocations; /* allocation calls so far (malloc, calloc, realloc, aligned forms) */

void *malloc(size_t size)
{
    allocations++;
    return __libc_malloc(size);
}

void *calloc(size_t count, size_t size)
{
    allocations++;
    return __libc_calloc(count, size);
}

void *realloc(void *p, size_t size)
{
    allocations++;
    return __libc_realloc(p, size);
}

void free(void *p)
{
    __libc_free(p);
}

void *aligned_alloc(size_t alignment, size_t size)
{
    allocations++;
    return __libc_memalign(alignment, size);
}

void *memalign(size_t alignment, size_t size)
{
    allocations++;
    return __libc_memalign(alignment, size);
}

int posix_memalign(void **out, size_t alignment, size_t size)
{
    allocations++;
    void *p = __libc_memalign(alignment, size);
    if (!p)
        return 12; /* ENOMEM */
    *out = p;
    return 0;
}

typedef struct {
    long before_run;  /* allocations when ekm_run starts */
    long after_steps; /* allocations after the latest step */
    long steps;       /* steps seen by the hook */
} alloc_watch;

static ekm_status watch_step(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err)
{
    (void)s;
    (void)st;
    (void)err;
    alloc_watch *w = ctx;
    w->after_steps = allocations;
    w->steps++;
    return EKM_OK;
}

/* Run `scenario` with overrides (no output frames, stop at t_end) and
 * assert that the loop made no allocation and at least min_steps steps. */
static void run_counting(const char *scenario, const char *const *sets, size_t n_sets, long min_steps)
{
    ekm_scenario sc;
    ekm_error err = {0};
    assert_int_equal(ekm_scenario_load(&sc, test_path(scenario), sets, n_sets, &err), EKM_OK);
    ekm_state *s = ekm_state_alloc(sc.cells, sc.length);
    assert_non_null(s);
    ekm_stepper *st = ekm_step_alloc(&sc, &err);
    assert_non_null(st);
    ekm_state_init(s, &sc);
    alloc_watch w = {0};
    const ekm_run_hooks hooks = {.step = watch_step, .ctx = &w};
    ekm_run_stats stats;
    w.before_run = allocations;
    const ekm_status rc = ekm_run(&sc, s, st, &hooks, &stats, &err);
    if (rc != EKM_OK)
        fprintf(stderr, "%s: %s\n", scenario, err.message);
    assert_int_equal(rc, EKM_OK);
    fprintf(stderr, "  %-24s %6ld steps (%ld rejected), %.2f Newton/step: %ld allocations in the loop\n",
            scenario, w.steps, stats.rejected, (double)stats.newton_iterations / (double)stats.steps,
            w.after_steps - w.before_run);
    assert_true(w.steps >= min_steps);
    assert_int_equal(w.after_steps - w.before_run, 0);
    ekm_step_free(st);
    ekm_state_free(s);
    ekm_scenario_free(&sc);
}

/* Pressure-controlled top wall (the stretching grid), flow regime. */
static void shear_cell_allocates_nothing(void **state)
{
    (void)state;
    const char *sets[] = {"domain.cells=400", "run.t_end=0.02", "run.stop=t_end", "run.output_dt=1"};
    run_counting("scenarios/shear_cell.ini", sets, 4, 100);
}

/* Gravity, a free surface, TVD convection. */
static void chute_allocates_nothing(void **state)
{
    (void)state;
    const char *sets[] = {"run.t_end=0.2", "run.stop=t_end", "run.output_dt=1", "numerics.convection=tvd"};
    run_counting("scenarios/chute.ini", sets, 4, 100);
}

/* Inflow into an empty column, the solid regime switching on. */
static void filling_allocates_nothing(void **state)
{
    (void)state;
    const char *sets[] = {"run.t_end=1", "run.stop=t_end", "run.output_dt=10"};
    run_counting("scenarios/filling.ini", sets, 3, 100);
}

/* A settled solid layer on a tilting base: solid cells and faces. */
static void tilting_layer_allocates_nothing(void **state)
{
    (void)state;
    const char *sets[] = {"run.t_end=1", "run.stop=t_end", "run.output_dt=10"};
    run_counting("scenarios/tilting_layer.ini", sets, 3, 10);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(shear_cell_allocates_nothing),
        cmocka_unit_test(chute_allocates_nothing),
        cmocka_unit_test(filling_allocates_nothing),
        cmocka_unit_test(tilting_layer_allocates_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
