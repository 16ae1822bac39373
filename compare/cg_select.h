/* cg_select.h: which snapshots of a dump are used, the selection that
 * `ekmcompare cg` and `ekmcompare base` share (--dt, --from, --to,
 * --steps; `[compare] cg_options`, scenario/cg_keys.h).
 *
 * A snapshot is kept when its step is in [step_a, step_b] (--steps A:B)
 * and its time in [from, to] (--from, --to); its time is ITEM: TIME, or
 * step x dt (--dt) for a dump without it (cg_input.h, cg_snapshot_time). */
#ifndef CG_SELECT_H
#define CG_SELECT_H

#include <stdint.h>

#include "cg_keys.h"

typedef struct {
    double dt;              /* engine time step [s]; 0: need ITEM: TIME */
    int have_from, have_to; /* 1: from, to given */
    double from, to;        /* time selection [s] */
    int have_steps;         /* 1: step_a, step_b given */
    int64_t step_a, step_b; /* step selection, inclusive */
} cg_select;

/* Apply the option v when it is one of the selection's; returns 1 when it
 * was, 0 otherwise (the caller's option). */
int cg_select_apply(cg_select *s, const ekm_cg_value *v);

/* 1 when the selection needs the snapshots' times (--dt, --from, --to). */
int cg_select_needs_time(const cg_select *s);

/* 1 when a snapshot of this step and time [s] is selected. */
int cg_select_keeps(const cg_select *s, int64_t step, double t);

#endif
