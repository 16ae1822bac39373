/* root.h: the root of a continuous function of one variable in a bracket,
 * by GSL's Brent solver, for the law's inverse relations (the volume
 * fraction at a given pressure: homogeneous.c, model.c). */
#ifndef EKM_ROOT_H
#define EKM_ROOT_H

#include "status.h"

/* The root x of f(x, params) in [lo, hi], where f(lo) and f(hi) have
 * opposite signs (the caller checks), to an interval of 1e-15 relative
 * (at most 200 iterations). EKM_ENUMERIC when the solver stops without it
 * (a NAN of f inside the bracket); *x is then the last estimate. */
ekm_status ekm_root_bracketed(double (*f)(double x, void *params), void *params, double lo, double hi,
                              double *x, ekm_error *err);

#endif
