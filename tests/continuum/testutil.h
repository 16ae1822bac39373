/* testutil.h: run a scenario in-process for the continuum tests. */
#ifndef EKM_TESTUTIL_H
#define EKM_TESTUTIL_H

#include <stddef.h>

#include "run.h"
#include "scenario.h"
#include "state.h"
#include "step.h"

typedef struct {
    ekm_scenario sc;
    ekm_state *s;
    ekm_stepper *st;
    ekm_run_stats stats;
    ekm_error err;
} test_run;

typedef ekm_status (*test_frame_fn)(void *ctx, const ekm_state *s, const ekm_stepper *st, ekm_error *err);

/* Path of a file in the source tree (scenarios/..., tests/continuum/data/...). */
const char *test_path(const char *relative);

/* Load `scenario` (relative to the source tree) with overrides, run it to
 * t_end calling frame (may be NULL) at every output.  Returns the status;
 * r must be released with test_run_free() in every case. */
ekm_status test_run_scenario(test_run *r, const char *scenario, const char *const *sets, size_t n_sets,
                             test_frame_fn frame, void *ctx);
/* The same with every hook of ekm_run (frame and/or per-step) and an
 * optional setup called on the loaded scenario before the state is
 * initialised (e.g. to set fields that are not scenario keys). */
typedef void (*test_setup_fn)(ekm_scenario *sc, void *ctx);
ekm_status test_run_scenario_hooks(test_run *r, const char *scenario, const char *const *sets, size_t n_sets,
                                   const ekm_run_hooks *hooks, test_setup_fn setup, void *setup_ctx);
void test_run_free(test_run *r);

#endif
