/* root.c: a bracketed root by GSL's Brent solver (root.h). */
#include "root.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>

ekm_status ekm_root_bracketed(double (*f)(double x, void *params), void *params, double lo, double hi,
                              double *x, ekm_error *err)
{
    gsl_function fn = {f, params};
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!s)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (root solver)");
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    int status = gsl_root_fsolver_set(s, &fn, lo, hi);
    int converged = 0;
    *x = 0.5 * (lo + hi);
    for (int it = 0; status == GSL_SUCCESS && it < 200 && !converged; it++) {
        status = gsl_root_fsolver_iterate(s);
        *x = gsl_root_fsolver_root(s);
        converged = gsl_root_test_interval(gsl_root_fsolver_x_lower(s), gsl_root_fsolver_x_upper(s), 0.0,
                                           1e-15) == GSL_SUCCESS;
    }
    gsl_set_error_handler(old);
    gsl_root_fsolver_free(s);
    if (status != GSL_SUCCESS || !converged || !isfinite(*x))
        return EKM_FAIL(err, EKM_ENUMERIC, "the root in [%g, %g] was not found (%s)", lo, hi,
                        status != GSL_SUCCESS ? gsl_strerror(status) : "no convergence in 200 iterations");
    return EKM_OK;
}
