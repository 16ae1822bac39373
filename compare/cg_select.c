/* cg_select.c: the snapshot selection of cg and base (cg_select.h). */
#include "cg_select.h"

int cg_select_apply(cg_select *s, const ekm_cg_value *v)
{
    switch (v->id) {
    case EKM_CG_DT: s->dt = v->x; return 1;
    case EKM_CG_FROM:
        s->from = v->x;
        s->have_from = 1;
        return 1;
    case EKM_CG_TO:
        s->to = v->x;
        s->have_to = 1;
        return 1;
    case EKM_CG_STEPS:
        s->step_a = (int64_t)v->x;
        s->step_b = (int64_t)v->y;
        s->have_steps = 1;
        return 1;
    default: return 0;
    }
}

int cg_select_needs_time(const cg_select *s)
{
    return s->dt > 0 || s->have_from || s->have_to;
}

int cg_select_keeps(const cg_select *s, int64_t step, double t)
{
    if (s->have_steps && (step < s->step_a || step > s->step_b))
        return 0;
    return !((s->have_from && t < s->from) || (s->have_to && t > s->to));
}
