/* fit.h: calibration of EKM material parameters on steady homogeneous
 * simple shear (`ekmcompare fit --rheology`, docs/compare.md).
 *
 * Model: the closure's steady homogeneous shear (law/closure.h: the EKM's
 * ekm_homog_shear, law/homogeneous.h, or another style's) at each point's phi
 * and gdot, which are taken as exact. Residuals (model - data)/SE for
 * the chosen observables (P, |sxz|, T, mu). GSL multifit_nlinear trust
 * region (Levenberg-Marquardt) in transformed parameters: log for the
 * positive constants, phi_cp = lo + (1 - lo) s(x) with lo the largest
 * phi of the data (and phi_co when it is held), phi_co = phi_cp s(x),
 * s the logistic function. Several starts: the given start and
 * nstarts - 1 perturbed ones (gsl_rng mt19937, fixed seed); the lowest
 * chi2 is kept.
 *
 * Identifiability: with J the Jacobian of the residuals with respect to
 * p_j, scaled by p_j (SE units per relative change), a parameter whose
 * column norm is below CG_FIT_SENS_MIN (at the start or at the fitted
 * values), or whose |correlation| with a parameter listed before it
 * exceeds CG_FIT_CORR_MAX, is not identifiable: it is held at its start
 * value, the reason recorded, and the others are fitted again.
 * Covariance: (J^T J)^-1 at the best fit, scaled by max(1, chi2/dof)
 * (the GSL manual's convention: the SEs grow when the model does not fit
 * within the data's SEs, never shrink below them).
 */
#ifndef CG_FIT_H
#define CG_FIT_H

#include <stddef.h>

#include "fit_data.h"
#include "closure.h"
#include "model.h"
#include "status.h"

#define CG_FIT_MAXP     12
#define CG_FIT_SENS_MIN 1e-6
#define CG_FIT_CORR_MAX 0.99
#define CG_FIT_WHY_MAX  192

/* The [material] key names that can be fitted, and their count: the
 * EKM's, then every other closure's (closure.h, in the table's order). */
int cg_fit_param_lookup(const char *name); /* index, or -1 if unknown */
const char *cg_fit_param_name(int index);
int cg_fit_param_count(void);
/* The closure style whose own [material] key parameter `index` is; NULL
 * for the EKM's keys (0 .. 11, in ekm_material's order). */
const ekm_closure *cg_fit_param_closure(int index);
/* 1 if closure c reads parameter `index`. */
int cg_fit_param_read_by(const ekm_closure *c, int index);
/* The value of parameter `index` in m. */
double cg_fit_param_get(const ekm_material *m, int index);
/* Set parameter `index` of m to v. */
void cg_fit_param_set(ekm_material *m, int index, double v);

/* The generic problem of the trust-region driver (cg_fit_solve): the
 * residual callback and what is fitted. --rheology (cg_fit_run) and
 * --scenario (fit_scen.h) each supply their own residuals. */
typedef struct {
    size_t nres; /* residuals */
    /* (model - data)/SE at material m into r[0..nres); non-zero if the model
     * cannot be evaluated there */
    int (*residuals)(void *ctx, const ekm_material *m, double *r);
    /* optional: a reason why parameter `param` (cg_fit_param_lookup index) has
     * no sensitivity on this data; returns 0 to use the generic reason */
    int (*why_insensitive)(void *ctx, const ekm_material *m, int param, int at_start, char *buf, size_t size);
    /* optional: called once at the best fit; returns the number of residuals
     * that count there (dof = that - parameters fitted); NULL: nres.
     * Non-zero status: the best fit cannot be evaluated. */
    ekm_status (*finish)(void *ctx, const ekm_material *m, size_t *nused, ekm_error *err);
    void *ctx;
    double phi_floor;        /* phi_cp is kept above this (and above phi_co when held) [-] */
    double jac_rel_step;     /* relative step of the identifiability Jacobian (1e-6 for --rheology) */
    double fd_step;          /* GSL's finite-difference step h_df of the trust region (0: GSL's default) */
    double xtol, gtol, ftol; /* gsl_multifit_nlinear_driver's tests (--rheology: 1e-12, 1e-12, 0) */
    size_t max_iter;         /* its iterations per start (--rheology: 500) */
    ekm_material start;      /* start values; also the values of every key not fitted */
    size_t nparams;          /* parameters asked for, in order */
    int param[CG_FIT_MAXP];  /* their indices (cg_fit_param_lookup) */
    int nstarts;             /* starts (>= 1) */
    unsigned long seed;      /* of the perturbed starts */
} cg_fit_spec;

typedef struct {
    const cg_fit_point *pts; /* data points (not owned) */
    size_t npts;
    unsigned fields;            /* bit mask of enum cg_fit_field */
    ekm_material start;         /* start values; also the values of every key not fitted */
    ekm_variant variant;        /* model variant (no effect in simple shear; recorded) */
    const ekm_closure *closure; /* the closure style (closure.h); its steady shear is the model */
    size_t nparams;             /* parameters asked for, in order */
    int param[CG_FIT_MAXP];     /* their indices (cg_fit_param_lookup) */
    int nstarts;                /* starts (>= 1) */
    unsigned long seed;         /* of the perturbed starts */
} cg_fit_problem;

typedef struct {
    size_t nparams;
    int param[CG_FIT_MAXP];
    double value[CG_FIT_MAXP]; /* fitted value, or the start value if not identifiable */
    double se[CG_FIT_MAXP];    /* standard error, NAN if not identifiable */
    double start[CG_FIT_MAXP]; /* start value */
    int identifiable[CG_FIT_MAXP];
    char why_not[CG_FIT_MAXP][CG_FIT_WHY_MAX]; /* reason, "" if identifiable */
    double corr[CG_FIT_MAXP][CG_FIT_MAXP];     /* correlation, NAN if either is not identifiable */
    ekm_material fitted;                       /* start with the fitted values in place */
    size_t nres;                               /* residuals (--rheology: points x fields) */
    size_t nfree;                              /* parameters fitted */
    long dof;                                  /* residuals that count - nfree */
    double chi2;                               /* sum of squared residuals at the best fit */
    double chi2_dof;                           /* chi2 / dof, NAN if dof == 0 */
    double cov_scale;                          /* factor applied to (J^T J)^-1 */
    int starts_run, starts_converged;
    double *resid;     /* --rheology: npts x CG_FIT_NFIELD, NAN for fields not fitted */
    double *model;     /* --rheology: the model's values, same layout */
    double *model_phi; /* --rheology: the model's phi per point (the data's at volume control) */
} cg_fit_result;

/* The driver: multistart trust region, identifiability, covariance.
 * Fills every field of res except resid and model (left NULL). res must
 * be released with cg_fit_result_free() in every case. EKM_EINPUT: fewer
 * residuals than parameters, an impossible start; EKM_ENUMERIC: no start
 * converged. */
ekm_status cg_fit_solve(const cg_fit_spec *sp, cg_fit_result *res, ekm_error *err);

/* --rheology: fit; res must be released with cg_fit_result_free() in every case.
 * EKM_EINPUT: fewer points than parameters, a point outside the model's
 * range (phi >= phi_cp), an impossible start; EKM_ENUMERIC: no start
 * converged. */
ekm_status cg_fit_run(const cg_fit_problem *pb, cg_fit_result *res, ekm_error *err);
void cg_fit_result_free(cg_fit_result *res);

#endif
