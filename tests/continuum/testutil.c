#include "testutil.h"

#include <stdio.h>
#include <string.h>

const char *test_path(const char *relative)
{
    static char buf[4][1024];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", EKM_SOURCE_DIR, relative);
    return buf[k];
}

ekm_status test_run_scenario_hooks(test_run *r, const char *scenario, const char *const *sets, size_t n_sets,
                                   const ekm_run_hooks *hooks, test_setup_fn setup, void *setup_ctx)
{
    memset(r, 0, sizeof *r);
    ekm_status st = ekm_scenario_load(&r->sc, test_path(scenario), sets, n_sets, &r->err);
    if (st != EKM_OK)
        return st;
    if (setup)
        setup(&r->sc, setup_ctx);
    r->s = ekm_state_alloc(r->sc.cells, r->sc.length);
    if (!r->s)
        return EKM_ENOMEM;
    r->st = ekm_step_alloc(&r->sc, &r->err);
    if (!r->st)
        return EKM_ENOMEM;
    ekm_state_init(r->s, &r->sc);
    st = ekm_run(&r->sc, r->s, r->st, hooks, &r->stats, &r->err);
    if (st != EKM_OK)
        fprintf(stderr, "run of %s failed: %s\n", scenario, r->err.message);
    return st;
}

ekm_status test_run_scenario(test_run *r, const char *scenario, const char *const *sets, size_t n_sets,
                             test_frame_fn frame, void *ctx)
{
    const ekm_run_hooks hooks = {.frame = frame, .ctx = ctx, .progress = 0};
    return test_run_scenario_hooks(r, scenario, sets, n_sets, &hooks, NULL, NULL);
}

void test_run_free(test_run *r)
{
    ekm_step_free(r->st);
    ekm_state_free(r->s);
    ekm_scenario_free(&r->sc);
    memset(r, 0, sizeof *r);
}
