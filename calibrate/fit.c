/* fit.c: the fitting engine of `ekmcompare fit` (see fit.h): the trust-region
 * driver cg_fit_solve, shared by --rheology (cg_fit_run, below) and
 * --scenario (fit_scen.c). */
#include "fit.h"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_vector.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "closure.h"
#include "homogeneous.h"

/* TR_LOG: p = exp(x); TR_PHI_CP: phi_cp = lo + (1 - lo) s(x); TR_PHI_CO:
 * phi_co = phi_cp s(x); for the closures' parameters (closure.h's ranges)
 * TR_ABOVE_PREV: p = prev + exp(x), TR_BELOW_PREV: p = prev s(x),
 * TR_ABOVE_DATA: p = phi_data + (1 - phi_data) s(x), with prev the value
 * of the parameter listed before it in its closure and s the logistic
 * function. */
typedef enum { TR_LOG, TR_PHI_CP, TR_PHI_CO, TR_ABOVE_PREV, TR_BELOW_PREV, TR_ABOVE_DATA } transform;

typedef struct {
    const char *name;
    size_t offset; /* into ekm_material */
    transform tr;
    int enters;     /* 1 if steady homogeneous shear depends on it */
    int yield_only; /* 1 if it acts only through P_Y (phi > phi_co) */
} param_spec;

#define MAT(k) #k, offsetof(ekm_material, k)
static const param_spec PARAMS[] = {
    {MAT(rho_p), TR_LOG, 1, 0},   {MAT(phi_co), TR_PHI_CO, 1, 1}, {MAT(phi_cp), TR_PHI_CP, 1, 0},
    {MAT(T0), TR_LOG, 1, 1},      {MAT(eta0), TR_LOG, 1, 0},      {MAT(zeta0), TR_LOG, 0, 0},
    {MAT(lambda0), TR_LOG, 0, 0}, {MAT(eps0), TR_LOG, 1, 0},      {MAT(nu), TR_LOG, 1, 1},
    {MAT(A_h), TR_LOG, 0, 0},     {MAT(B_h), TR_LOG, 0, 0},       {MAT(alpha), TR_LOG, 0, 0},
};
#undef MAT
#define NPARAM_EKM ((int)(sizeof PARAMS / sizeof PARAMS[0]))

/* The other closures' parameters follow the EKM's: index NPARAM_EKM + s
 * is law_p slot s (closure.h), fitted in log (each is positive). */
static int closure_param_at(int index, const ekm_closure **c, size_t *k)
{
    int slot = index - NPARAM_EKM;
    for (size_t i = 0; slot >= 0 && i < ekm_closure_count(); i++) {
        const ekm_closure *ci = ekm_closure_at(i);
        if ((size_t)slot < ci->nparams) {
            *c = ci;
            *k = (size_t)slot;
            return 1;
        }
        slot -= (int)ci->nparams;
    }
    return 0;
}

int cg_fit_param_count(void)
{
    int n = NPARAM_EKM;
    for (size_t i = 0; i < ekm_closure_count(); i++)
        n += (int)ekm_closure_at(i)->nparams;
    return n;
}

int cg_fit_param_lookup(const char *name)
{
    for (int i = 0; i < cg_fit_param_count(); i++)
        if (!strcmp(cg_fit_param_name(i), name))
            return i;
    return -1;
}

const char *cg_fit_param_name(int index)
{
    const ekm_closure *c;
    size_t k;
    if (index >= 0 && index < NPARAM_EKM)
        return PARAMS[index].name;
    return closure_param_at(index, &c, &k) ? c->params[k].key : "?";
}

const ekm_closure *cg_fit_param_closure(int index)
{
    const ekm_closure *c = NULL;
    size_t k;
    return index >= NPARAM_EKM && closure_param_at(index, &c, &k) ? c : NULL;
}

int cg_fit_param_read_by(const ekm_closure *c, int index)
{
    if (index >= 0 && index < NPARAM_EKM)
        return ekm_closure_reads_ekm_key(c, PARAMS[index].name);
    return cg_fit_param_closure(index) == c;
}

static transform param_transform(int index)
{
    const ekm_closure *c;
    size_t k;
    if (index < NPARAM_EKM)
        return PARAMS[index].tr;
    if (!closure_param_at(index, &c, &k))
        return TR_LOG;
    switch (c->params[k].range) {
    case EKM_PARAM_ABOVE_PREVIOUS: return k > 0 ? TR_ABOVE_PREV : TR_LOG;
    case EKM_PARAM_BELOW_PREVIOUS: return k > 0 ? TR_BELOW_PREV : TR_LOG;
    case EKM_PARAM_PHI_ABOVE_DATA: return TR_ABOVE_DATA;
    default: return TR_LOG;
    }
}

static double *param_ptr(ekm_material *m, int index)
{
    if (index >= NPARAM_EKM) /* its law_p slot or the field it names (closure.h) */
        return ekm_closure_slot_ptr((size_t)(index - NPARAM_EKM), m);
    return (double *)((char *)m + PARAMS[index].offset);
}

double cg_fit_param_get(const ekm_material *m, int index)
{
    ekm_material copy = *m;
    return *param_ptr(&copy, index);
}

void cg_fit_param_set(ekm_material *m, int index, double v)
{
    *param_ptr(m, index) = v;
}

/* ---- the driver's context ---- */

typedef struct {
    const cg_fit_spec *sp;
    ekm_material base; /* start values with held parameters in place */
    size_t nfree;
    int free_param[CG_FIT_MAXP]; /* indices into PARAMS of the fitted ones */
    double lo_cp;                /* lower bound of phi_cp [-] */
    double phi_data;             /* the largest phi of the data [-] (TR_ABOVE_DATA) */
    size_t nres;
} fit_ctx;

static double logistic(double x)
{
    return 1.0 / (1.0 + exp(-x));
}

static double logit(double s)
{
    return log(s / (1.0 - s));
}

static void x_to_material(const fit_ctx *c, const double *x, ekm_material *m)
{
    *m = c->base;
    for (size_t k = 0; k < c->nfree; k++)
        if (param_transform(c->free_param[k]) == TR_PHI_CP)
            m->phi_cp = c->lo_cp + (1.0 - c->lo_cp) * logistic(x[k]);
    for (size_t k = 0; k < c->nfree; k++) {
        const int i = c->free_param[k];
        if (param_transform(i) == TR_LOG)
            *param_ptr(m, i) = exp(x[k]);
        else if (param_transform(i) == TR_PHI_CO)
            m->phi_co = m->phi_cp * logistic(x[k]);
        else if (param_transform(i) == TR_ABOVE_DATA)
            *param_ptr(m, i) = c->phi_data + (1.0 - c->phi_data) * logistic(x[k]);
    }
    /* relative to the previous parameter, once that has its value */
    for (size_t k = 0; k < c->nfree; k++) {
        const int i = c->free_param[k];
        if (param_transform(i) == TR_ABOVE_PREV)
            *param_ptr(m, i) = cg_fit_param_get(m, i - 1) + exp(x[k]);
        else if (param_transform(i) == TR_BELOW_PREV)
            *param_ptr(m, i) = cg_fit_param_get(m, i - 1) * logistic(x[k]);
    }
}

static ekm_status material_to_x(const fit_ctx *c, const ekm_material *m, double *x, ekm_error *err)
{
    for (size_t k = 0; k < c->nfree; k++) {
        const int i = c->free_param[k];
        const double p = cg_fit_param_get(m, i);
        double s;
        switch (param_transform(i)) {
        case TR_LOG:
            if (!(p > 0.0))
                return EKM_FAIL(err, EKM_EINPUT, "start %s = %g: expected a positive start value to fit it",
                                cg_fit_param_name(i), p);
            x[k] = log(p);
            break;
        case TR_PHI_CP:
            s = (p - c->lo_cp) / (1.0 - c->lo_cp);
            if (!(s > 0.0 && s < 1.0))
                return EKM_FAIL(err, EKM_EINPUT,
                                "start phi_cp = %g: expected a value in (%g, 1) (above every point's phi "
                                "and phi_co)",
                                p, c->lo_cp);
            x[k] = logit(s);
            break;
        case TR_PHI_CO:
            s = p / m->phi_cp;
            if (!(s > 0.0 && s < 1.0))
                return EKM_FAIL(err, EKM_EINPUT, "start phi_co = %g: expected a value in (0, phi_cp = %g)", p,
                                m->phi_cp);
            x[k] = logit(s);
            break;
        case TR_ABOVE_DATA:
            s = (p - c->phi_data) / (1.0 - c->phi_data);
            if (!(s > 0.0 && s < 1.0))
                return EKM_FAIL(err, EKM_EINPUT,
                                "start %s = %g: expected a value in (%g, 1) (above every point's phi)",
                                cg_fit_param_name(i), p, c->phi_data);
            x[k] = logit(s);
            break;
        case TR_ABOVE_PREV:
            if (!(p > cg_fit_param_get(m, i - 1)))
                return EKM_FAIL(err, EKM_EINPUT, "start %s = %g: expected a value above %s = %g",
                                cg_fit_param_name(i), p, cg_fit_param_name(i - 1),
                                cg_fit_param_get(m, i - 1));
            x[k] = log(p - cg_fit_param_get(m, i - 1));
            break;
        case TR_BELOW_PREV:
            s = p / cg_fit_param_get(m, i - 1);
            if (!(s > 0.0 && s < 1.0))
                return EKM_FAIL(err, EKM_EINPUT, "start %s = %g: expected a value in (0, %s = %g)",
                                cg_fit_param_name(i), p, cg_fit_param_name(i - 1),
                                cg_fit_param_get(m, i - 1));
            x[k] = logit(s);
            break;
        }
    }
    return EKM_OK;
}

static int resid_gsl(const gsl_vector *x, void *params, gsl_vector *f)
{
    const fit_ctx *c = params;
    double xv[CG_FIT_MAXP];
    for (size_t k = 0; k < c->nfree; k++)
        xv[k] = gsl_vector_get(x, k);
    ekm_material m;
    x_to_material(c, xv, &m);
    double *r = malloc(c->nres * sizeof *r);
    if (!r)
        return GSL_ENOMEM;
    int bad = c->sp->residuals(c->sp->ctx, &m, r);
    for (size_t i = 0; i < c->nres && !bad; i++) {
        if (!isfinite(r[i]))
            bad = 1;
        gsl_vector_set(f, i, r[i]);
    }
    free(r);
    return bad ? GSL_EDOM : GSL_SUCCESS;
}

/* Jacobian of the residuals with respect to the parameters idx[0..np),
 * column j scaled by p_j (p_j dr/dp_j; dr/dp_j when p_j = 0): central
 * differences with step jac_rel_step |p_j|, one-sided where the model's
 * range ends. J is nres x np. */
static ekm_status scaled_jacobian(const fit_ctx *c, const ekm_material *m, const int *idx, size_t np,
                                  gsl_matrix *J, ekm_error *err)
{
    const cg_fit_spec *sp = c->sp;
    const size_t n = c->nres;
    double *rp = malloc(2 * n * sizeof *rp);
    if (!rp)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    double *rm = rp + n;
    for (size_t j = 0; j < np; j++) {
        const double p = cg_fit_param_get(m, idx[j]);
        const double h = p != 0.0 ? sp->jac_rel_step * fabs(p) : 1e-8;
        ekm_material mp = *m, mm = *m;
        *param_ptr(&mp, idx[j]) = p + h;
        *param_ptr(&mm, idx[j]) = p - h;
        const int okp = !sp->residuals(sp->ctx, &mp, rp), okm = !sp->residuals(sp->ctx, &mm, rm);
        double step = 2.0 * h;
        if (!okp && !okm) {
            free(rp);
            return EKM_FAIL(err, EKM_ENUMERIC, "%s = %g: the model cannot be evaluated around it",
                            cg_fit_param_name(idx[j]), p);
        }
        if (!okp || !okm) { /* one-sided: the missing side is r(p) */
            sp->residuals(sp->ctx, m, okp ? rm : rp);
            step = h;
        }
        const double scale = p != 0.0 ? p : 1.0;
        for (size_t i = 0; i < n; i++)
            gsl_matrix_set(J, i, j, scale * (rp[i] - rm[i]) / step);
    }
    free(rp);
    return EKM_OK;
}

static double column_norm(const gsl_matrix *J, size_t j)
{
    gsl_vector_const_view col = gsl_matrix_const_column(J, j);
    return gsl_blas_dnrm2(&col.vector);
}

static void why_insensitive(const cg_fit_spec *sp, const ekm_material *m, int i, double norm, int at_start,
                            char *buf, size_t size)
{
    if (sp->why_insensitive && sp->why_insensitive(sp->ctx, m, i, at_start, buf, size))
        return;
    snprintf(buf, size, "its sensitivity vanishes on the data (|p dr/dp| = %.2g < %g%s)", norm,
             CG_FIT_SENS_MIN, at_start ? " at the start" : " at the fitted values");
}

/* ---- the multistart fit ---- */

static ekm_status fit_free(const fit_ctx *c, const double *xs, double *xbest, double *chi2best,
                           cg_fit_result *res, ekm_error *err)
{
    const size_t n = c->nres, p = c->nfree;
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    fp.trs = gsl_multifit_nlinear_trs_lm;
    if (c->sp->fd_step > 0.0)
        fp.h_df = c->sp->fd_step;
    gsl_multifit_nlinear_workspace *w = gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, n, p);
    gsl_vector *x0 = gsl_vector_alloc(p);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!w || !x0 || !rng) {
        if (w)
            gsl_multifit_nlinear_free(w);
        if (x0)
            gsl_vector_free(x0);
        if (rng)
            gsl_rng_free(rng);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    gsl_rng_set(rng, c->sp->seed);
    gsl_multifit_nlinear_fdf fdf = {
        .f = resid_gsl, .df = NULL, .fvv = NULL, .n = n, .p = p, .params = (void *)c};
    *chi2best = INFINITY;
    for (int s = 0; s < c->sp->nstarts; s++) {
        for (size_t k = 0; k < p; k++) {
            const double width = param_transform(c->free_param[k]) == TR_LOG ? log(3.0) : 2.0;
            const double u = gsl_rng_uniform(rng); /* drawn for every start: start s sees the same numbers */
            gsl_vector_set(x0, k, xs[k] + (s == 0 ? 0.0 : width * (2.0 * u - 1.0)));
        }
        res->starts_run++;
        if (gsl_multifit_nlinear_init(x0, &fdf, w) != GSL_SUCCESS)
            continue;
        int info;
        const int st = gsl_multifit_nlinear_driver(c->sp->max_iter, c->sp->xtol, c->sp->gtol, c->sp->ftol,
                                                   NULL, NULL, &info, w);
        if (st != GSL_SUCCESS)
            continue;
        double chi;
        gsl_blas_ddot(gsl_multifit_nlinear_residual(w), gsl_multifit_nlinear_residual(w), &chi);
        if (!isfinite(chi))
            continue;
        res->starts_converged++;
        if (chi < *chi2best) {
            *chi2best = chi;
            const gsl_vector *xf = gsl_multifit_nlinear_position(w);
            for (size_t k = 0; k < p; k++)
                xbest[k] = gsl_vector_get(xf, k);
        }
    }
    gsl_multifit_nlinear_free(w);
    gsl_vector_free(x0);
    gsl_rng_free(rng);
    if (!isfinite(*chi2best))
        return EKM_FAIL(err, EKM_ENUMERIC, "the fit did not converge from any of %d starts", c->sp->nstarts);
    return EKM_OK;
}

/* ---- the driver ---- */

void cg_fit_result_free(cg_fit_result *res)
{
    if (!res)
        return;
    free(res->resid);
    free(res->model);
    free(res->model_phi);
    res->resid = res->model = res->model_phi = NULL;
}

static void mark_held(cg_fit_result *res, size_t j, ekm_material *base, const ekm_material *start,
                      const char *why)
{
    res->identifiable[j] = 0;
    snprintf(res->why_not[j], CG_FIT_WHY_MAX, "%s", why);
    *param_ptr(base, res->param[j]) = cg_fit_param_get(start, res->param[j]);
}

ekm_status cg_fit_solve(const cg_fit_spec *sp, cg_fit_result *res, ekm_error *err)
{
    memset(res, 0, sizeof *res);
    res->nparams = sp->nparams;
    if (sp->nparams < 1 || sp->nparams > CG_FIT_MAXP)
        return EKM_FAIL(err, EKM_EINPUT, "--params: expected 1 to %d parameters, got %zu", CG_FIT_MAXP,
                        sp->nparams);
    if (sp->nres < sp->nparams)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%zu residual%s for %zu parameters: expected at least as many data points "
                        "as parameters",
                        sp->nres, sp->nres == 1 ? "" : "s", sp->nparams);
    if (sp->nstarts < 1)
        return EKM_FAIL(err, EKM_EINPUT, "--starts: expected at least 1");
    ekm_error merr;
    if (ekm_material_check(&sp->start, &merr) != EKM_OK)
        return EKM_FAIL(err, EKM_EINPUT, "start material: %s", merr.message);
    fit_ctx c = {.sp = sp, .base = sp->start, .nres = sp->nres};
    const double phi_max = sp->phi_floor;
    res->nres = c.nres;
    gsl_matrix *Jall = gsl_matrix_alloc(c.nres, sp->nparams);
    double *r = malloc(c.nres * sizeof *r);
    if (!Jall || !r) {
        if (Jall)
            gsl_matrix_free(Jall);
        free(r);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    for (size_t j = 0; j < sp->nparams; j++) {
        res->param[j] = sp->param[j];
        res->start[j] = res->value[j] = cg_fit_param_get(&sp->start, sp->param[j]);
        res->se[j] = NAN;
        res->identifiable[j] = 1;
        for (size_t i = 0; i < sp->nparams; i++)
            if (i < j && sp->param[i] == sp->param[j]) {
                gsl_matrix_free(Jall);
                free(r);
                return EKM_FAIL(err, EKM_EINPUT, "--params: %s is listed twice",
                                cg_fit_param_name(sp->param[j]));
            }
    }
    c.lo_cp = phi_max;
    c.phi_data = phi_max;
    ekm_status st = EKM_OK;
    /* Sensitivity at the start. */
    st = scaled_jacobian(&c, &sp->start, sp->param, sp->nparams, Jall, err);
    for (size_t j = 0; j < sp->nparams && st == EKM_OK; j++) {
        const double norm = column_norm(Jall, j);
        if (!(norm >= CG_FIT_SENS_MIN)) {
            char why[CG_FIT_WHY_MAX];
            why_insensitive(sp, &sp->start, sp->param[j], norm, 1, why, sizeof why);
            mark_held(res, j, &c.base, &sp->start, why);
        }
    }
    gsl_matrix_free(Jall);
    double cov_s[CG_FIT_MAXP][CG_FIT_MAXP] = {{0}};
    size_t slot[CG_FIT_MAXP]; /* result slot of each free parameter */
    ekm_material best = sp->start;
    double chi2 = 0.0;
    for (size_t round = 0; round <= sp->nparams && st == EKM_OK; round++) {
        c.nfree = 0;
        int phi_co_free = 0;
        for (size_t j = 0; j < sp->nparams; j++)
            if (res->identifiable[j]) {
                slot[c.nfree] = j;
                c.free_param[c.nfree++] = sp->param[j];
                phi_co_free |= param_transform(sp->param[j]) == TR_PHI_CO;
            }
        /* phi_cp stays above every point's phi, and above phi_co when that is held */
        c.lo_cp = phi_co_free ? phi_max : fmax(phi_max, c.base.phi_co);
        best = c.base;
        if (c.nfree == 0) {
            if (sp->residuals(sp->ctx, &best, r))
                st = EKM_FAIL(err, EKM_EINPUT, "the start material cannot be evaluated at every point");
            chi2 = 0.0;
            for (size_t i = 0; i < c.nres; i++)
                chi2 += r[i] * r[i];
            break;
        }
        double xs[CG_FIT_MAXP], xb[CG_FIT_MAXP];
        st = material_to_x(&c, &c.base, xs, err);
        if (st == EKM_OK)
            st = fit_free(&c, xs, xb, &chi2, res, err);
        if (st != EKM_OK)
            break;
        x_to_material(&c, xb, &best);
        gsl_matrix *J = gsl_matrix_alloc(c.nres, c.nfree);
        gsl_matrix *cov = gsl_matrix_alloc(c.nfree, c.nfree);
        if (!J || !cov) {
            if (J)
                gsl_matrix_free(J);
            if (cov)
                gsl_matrix_free(cov);
            st = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
            break;
        }
        st = scaled_jacobian(&c, &best, c.free_param, c.nfree, J, err);
        int changed = 0;
        for (size_t k = 0; k < c.nfree && st == EKM_OK; k++) {
            const double norm = column_norm(J, k);
            if (!(norm >= CG_FIT_SENS_MIN)) {
                char why[CG_FIT_WHY_MAX];
                why_insensitive(sp, &best, c.free_param[k], norm, 0, why, sizeof why);
                mark_held(res, slot[k], &c.base, &sp->start, why);
                changed = 1;
            }
        }
        if (st == EKM_OK && !changed) {
            gsl_multifit_nlinear_covar(J, 1e-12, cov);
            double worst = 0.0;
            size_t wa = 0, wb = 0;
            for (size_t a = 0; a < c.nfree; a++) {
                const double daa = gsl_matrix_get(cov, a, a);
                if (!(daa > 0.0)) { /* dropped by the rank test: dependent on the others */
                    char why[CG_FIT_WHY_MAX];
                    snprintf(why, sizeof why,
                             "linearly dependent on the other parameters on this data (rank-deficient "
                             "Jacobian)");
                    mark_held(res, slot[a], &c.base, &sp->start, why);
                    changed = 1;
                    break;
                }
                for (size_t b = 0; b < a; b++) {
                    const double rho = gsl_matrix_get(cov, a, b) / sqrt(daa * gsl_matrix_get(cov, b, b));
                    if (fabs(rho) > worst) {
                        worst = fabs(rho);
                        wa = a;
                        wb = b;
                    }
                }
            }
            if (!changed && worst > CG_FIT_CORR_MAX) {
                /* hold the one listed later (slot order follows --params) */
                const double rho = gsl_matrix_get(cov, wa, wb) /
                                   sqrt(gsl_matrix_get(cov, wa, wa) * gsl_matrix_get(cov, wb, wb));
                char why[CG_FIT_WHY_MAX];
                snprintf(why, sizeof why, "its correlation with %s is %.4f (|rho| > %g) on this data",
                         cg_fit_param_name(c.free_param[wb]), rho, CG_FIT_CORR_MAX);
                mark_held(res, slot[wa], &c.base, &sp->start, why);
                changed = 1;
            }
            if (!changed)
                for (size_t a = 0; a < c.nfree; a++)
                    for (size_t b = 0; b < c.nfree; b++)
                        cov_s[a][b] = gsl_matrix_get(cov, a, b);
        }
        gsl_matrix_free(J);
        gsl_matrix_free(cov);
        if (!changed)
            break;
    }
    free(r);
    size_t nused = c.nres;
    if (st == EKM_OK && sp->finish)
        st = sp->finish(sp->ctx, &best, &nused, err);
    if (st == EKM_OK) {
        res->fitted = best;
        res->nfree = c.nfree;
        res->chi2 = chi2;
        res->dof = (long)nused - (long)c.nfree;
        res->chi2_dof = res->dof > 0 ? chi2 / (double)res->dof : NAN;
        res->cov_scale = res->dof > 0 ? fmax(1.0, res->chi2_dof) : 1.0;
        for (size_t j = 0; j < sp->nparams; j++) {
            res->value[j] = cg_fit_param_get(&best, sp->param[j]);
            for (size_t i = 0; i < sp->nparams; i++)
                res->corr[j][i] = NAN;
        }
        for (size_t a = 0; a < c.nfree; a++) {
            const double pa = cg_fit_param_get(&best, c.free_param[a]);
            res->se[slot[a]] = sqrt(cov_s[a][a] * res->cov_scale) * (pa != 0.0 ? fabs(pa) : 1.0);
            for (size_t b = 0; b < c.nfree; b++)
                res->corr[slot[a]][slot[b]] = cov_s[a][b] / sqrt(cov_s[a][a] * cov_s[b][b]);
        }
    }
    return st;
}

/* ---- --rheology: steady homogeneous simple shear ---- */

/* Residuals (model - data)/SE at material m into r (nres), and the model
 * values (npts x CG_FIT_NFIELD, may be NULL). Non-zero if the model
 * cannot be evaluated. */
static int model_residuals(const cg_fit_problem *pb, const ekm_material *m, double *r, double *model,
                           double *model_phi)
{
    size_t i = 0;
    for (size_t k = 0; k < pb->npts; k++) {
        const cg_fit_point *pt = &pb->pts[k];
        ekm_homog_state h;
        ekm_error e;
        /* volume control: the model at the data's phi; pressure control: at
         * its P, and phi is the response compared (in the P residual) */
        const ekm_status st =
            pt->at_pressure
                ? ekm_closure_homog_at_pressure(pb->closure, m, pt->value[CG_FIT_P], pt->gdot, &h, &e)
                : ekm_closure_homog(pb->closure, m, pt->phi, pt->gdot, &h, &e);
        if (st != EKM_OK)
            return 1;
        const double mv[CG_FIT_NFIELD] = {
            [CG_FIT_P] = h.P, [CG_FIT_SXZ] = h.sxz, [CG_FIT_T] = h.T, [CG_FIT_MU] = h.mu};
        if (model_phi)
            model_phi[k] = h.phi;
        for (int f = 0; f < CG_FIT_NFIELD; f++) {
            if (model)
                model[k * CG_FIT_NFIELD + f] = mv[f];
            if (!(pb->fields & (1u << f)))
                continue;
            if (f == CG_FIT_P && pt->at_pressure)
                r[i++] = (h.phi - pt->phi) / pt->phi_se;
            else
                r[i++] = (mv[f] - pt->value[f]) / pt->se[f];
        }
    }
    return 0;
}

static int rheology_residuals(void *ctx, const ekm_material *m, double *r)
{
    return model_residuals(ctx, m, r, NULL, NULL);
}

static int all_below_phi_co(const cg_fit_problem *pb, const ekm_material *m)
{
    for (size_t k = 0; k < pb->npts; k++)
        if (pb->pts[k].phi > m->phi_co)
            return 0;
    return 1;
}

static int rheology_why(void *ctx, const ekm_material *m, int i, int at_start, char *buf, size_t size)
{
    const cg_fit_problem *pb = ctx;
    if (!cg_fit_param_read_by(pb->closure, i)) {
        snprintf(buf, size, "closure %s does not read %s", pb->closure->name, cg_fit_param_name(i));
        return 1;
    }
    if (i >= NPARAM_EKM)
        return 0;
    const param_spec *ps = &PARAMS[i];
    if (!ps->enters)
        snprintf(buf, size, "steady homogeneous simple shear does not depend on %s (no gradients, w' = 0)",
                 ps->name);
    else if (ps->yield_only && all_below_phi_co(pb, m))
        snprintf(buf, size, "every point has phi < phi_co (= %g%s): %s", m->phi_co,
                 at_start ? "" : ", as fitted",
                 i == cg_fit_param_lookup("nu") ? "r = P_Y/P_K = 0, nu has no effect"
                                                : "no yield pressure, P_Y = 0");
    else
        return 0;
    return 1;
}

ekm_status cg_fit_run(const cg_fit_problem *pb, cg_fit_result *res, ekm_error *err)
{
    memset(res, 0, sizeof *res);
    res->nparams = pb->nparams;
    if (pb->nparams < 1 || pb->nparams > CG_FIT_MAXP)
        return EKM_FAIL(err, EKM_EINPUT, "--params: expected 1 to %d parameters, got %zu", CG_FIT_MAXP,
                        pb->nparams);
    if (pb->npts < pb->nparams)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%zu point%s for %zu parameters: expected at least as many points (input "
                        "files) as parameters",
                        pb->npts, pb->npts == 1 ? "" : "s", pb->nparams);
    if (pb->fields == 0)
        return EKM_FAIL(err, EKM_EINPUT, "--fields: expected at least one of P, sxz, T, mu");
    if (pb->nstarts < 1)
        return EKM_FAIL(err, EKM_EINPUT, "--starts: expected at least 1");
    /* no closure given: the EKM style of the variant */
    cg_fit_problem with_closure = *pb;
    if (!with_closure.closure)
        with_closure.closure = ekm_closure_of_variant(pb->variant);
    pb = &with_closure;
    if ((pb->fields & (1u << CG_FIT_T)) && !pb->closure->has_temperature)
        return EKM_FAIL(err, EKM_EINPUT,
                        "--fields T: closure %s has no granular temperature (fit P, sxz or mu, e.g. --fields "
                        "P,sxz)",
                        pb->closure->name);
    for (size_t j = 0; j < pb->nparams; j++)
        if (!cg_fit_param_read_by(pb->closure, pb->param[j]))
            return EKM_FAIL(err, EKM_EINPUT, "--params: %s: not a parameter of closure %s",
                            cg_fit_param_name(pb->param[j]), pb->closure->name);
    ekm_error merr;
    if (ekm_closure_check(pb->closure, &pb->start, &merr) != EKM_OK)
        return EKM_FAIL(err, EKM_EINPUT, "start material: %s", merr.message);
    cg_fit_spec sp = {.residuals = rheology_residuals,
                      .why_insensitive = rheology_why,
                      .ctx = (void *)pb,
                      .jac_rel_step = 1e-6,
                      .xtol = 1e-12,
                      .gtol = 1e-12,
                      .ftol = 0.0,
                      .max_iter = 500,
                      .start = pb->start,
                      .nparams = pb->nparams,
                      .nstarts = pb->nstarts,
                      .seed = pb->seed};
    memcpy(sp.param, pb->param, sizeof sp.param);
    double phi_max = 0.0;
    for (size_t k = 0; k < pb->npts; k++) {
        const cg_fit_point *pt = &pb->pts[k];
        if (pt->at_pressure && !((pb->fields & (1u << CG_FIT_P)) && pt->phi_se > 0.0 && isfinite(pt->phi_se)))
            return EKM_FAIL(
                err, EKM_EINPUT,
                "%s: a pressure-controlled point needs --fields P (its residual is that of phi, the "
                "response) and a phi SE > 0 (got %g)",
                pt->file, pt->phi_se);
        if (!pb->closure->is_ekm || pt->at_pressure) {
            /* the closure's own range: its steady shear at the start */
            ekm_homog_state h;
            ekm_error herr;
            const ekm_status hs =
                pt->at_pressure ? ekm_closure_homog_at_pressure(pb->closure, &pb->start, pt->value[CG_FIT_P],
                                                                pt->gdot, &h, &herr)
                                : ekm_closure_homog(pb->closure, &pb->start, pt->phi, pt->gdot, &h, &herr);
            if (hs != EKM_OK)
                return EKM_FAIL(err, EKM_EINPUT, "%s: closure %s at the start material: %s", pt->file,
                                pb->closure->name, herr.message);
        } else if (!(pt->phi > 0.0 && pt->phi < pb->start.phi_cp))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: phi = %g: expected a volume fraction in (0, phi_cp = %g of the start "
                            "material)",
                            pt->file, pt->phi, pb->start.phi_cp);
        phi_max = fmax(phi_max, pt->phi);
        for (int f = 0; f < CG_FIT_NFIELD; f++)
            sp.nres += (pb->fields >> f) & 1u;
    }
    sp.phi_floor = phi_max;
    ekm_status st = cg_fit_solve(&sp, res, err);
    if (st != EKM_OK)
        return st;
    res->resid = malloc(pb->npts * CG_FIT_NFIELD * sizeof *res->resid);
    res->model = malloc(pb->npts * CG_FIT_NFIELD * sizeof *res->model);
    res->model_phi = malloc(pb->npts * sizeof *res->model_phi);
    double *r = malloc(sp.nres * sizeof *r);
    if (!res->resid || !res->model || !res->model_phi || !r) {
        free(r);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    if (model_residuals(pb, &res->fitted, r, res->model, res->model_phi))
        st = EKM_FAIL(err, EKM_ENUMERIC, "the fitted material cannot be evaluated at every point");
    size_t i = 0;
    for (size_t k = 0; k < pb->npts && st == EKM_OK; k++)
        for (int f = 0; f < CG_FIT_NFIELD; f++)
            res->resid[k * CG_FIT_NFIELD + f] = pb->fields & (1u << f) ? r[i++] : NAN;
    free(r);
    return st;
}
