/* cg_opts.c: the defaults of a cg run and the check of its outputs
 * against its inputs (cg_opts.h). */
#include "cg_opts.h"

#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "xdmf.h"

cg_run_opts cg_opts_default(void)
{
    cg_run_opts o;
    memset(&o, 0, sizeof o);
    o.axis = 2;
    o.axis2 = -1;
    o.kernel = "gauss";
    o.tmode = CG_T_PARTICLE;
    return o;
}

void cg_opts_apply(cg_run_opts *o, cg_opts_names *names, const ekm_cg_value *v)
{
    switch (v->id) {
    case EKM_CG_OUT: o->out = v->text; break;
    case EKM_CG_CSV: o->csv = v->text; break;
    case EKM_CG_AXIS: o->axis = v->axis; break;
    case EKM_CG_AXES:
        o->axis = v->axis;
        o->axis2 = v->axis2;
        break;
    case EKM_CG_ENSEMBLE: o->ensemble = 1; break;
    case EKM_CG_KERNEL: o->kernel = v->text; break;
    case EKM_CG_WIDTH: o->width = v->x; break;
    case EKM_CG_BINS:
        o->bins = v->count;
        if (v->count_x)
            o->bins_x = v->count_x;
        break;
    case EKM_CG_DZ: o->dz = v->x; break;
    case EKM_CG_RANGE:
        o->range_lo = v->x;
        o->range_hi = v->y;
        o->have_range = 1;
        break;
    case EKM_CG_RHO_P: o->rho_p = v->x; break;
    case EKM_CG_DT:
    case EKM_CG_FROM:
    case EKM_CG_TO:
    case EKM_CG_STEPS: cg_select_apply(&o->select, v); break;
    case EKM_CG_STEADY: o->steady = 1; break;
    case EKM_CG_EXACT: o->exact = 1; break;
    case EKM_CG_EVERY: o->every = v->count; break;
    case EKM_CG_WINDOW: o->window = v->x; break;
    case EKM_CG_TEMPERATURE: o->tmode = v->flag ? CG_T_CONSISTENT : CG_T_PARTICLE; break;
    case EKM_CG_STRESS:
        o->nstress = 6;
        for (int c = 0; c < 6; c++) {
            memcpy(names->stress[c], v->names[c], EKM_CG_NAME_MAX);
            o->stress[c] = names->stress[c];
        }
        break;
    case EKM_CG_PAIRS: break; /* a list: the caller's */
    case EKM_CG_PAIR_COLUMNS:
        o->npaircols = v->n_names;
        for (size_t c = 0; c < v->n_names; c++) {
            memcpy(names->paircols[c], v->names[c], EKM_CG_NAME_MAX);
            o->paircols[c] = names->paircols[c];
        }
        break;
    case EKM_CG_TYPES:
        o->ntypes = v->n_types;
        memcpy(o->types, v->types, v->n_types * sizeof v->types[0]);
        break;
    case EKM_CG_EXPECT_SNAPSHOTS: o->expect_snapshots = v->count; break;
    case EKM_CG_QUIET: o->log = NULL; break;
    }
}

/* Every output must be writable, and none may replace an input (dumps and
 * pair dumps), nor the HDF5 output's sidecar or the HDF5 output the CSV:
 * refused before any work. */
ekm_status cg_opts_refuse_inputs(const cg_run_opts *o, ekm_error *err)
{
    size_t n = o->ninputs + o->npairs;
    const char **in = malloc((n + 1) * sizeof *in);
    if (!in)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    for (size_t i = 0; i < o->ninputs; i++)
        in[i] = o->inputs[i];
    for (size_t i = 0; i < o->npairs; i++)
        in[o->ninputs + i] = o->pairs[i];
    ekm_status rc = EKM_OK;
    if (o->out)
        rc = ekm_xdmf_check_name(o->out, "-o", err);
    if (!rc && o->out)
        rc = ekm_atomic_check_target(o->out, err);
    if (!rc && o->csv)
        rc = ekm_atomic_check_target(o->csv, err);
    if (!rc && o->out)
        rc = ekm_atomic_refuse_input(o->out, in, n, err);
    if (!rc && o->out) { /* nor may its XDMF sidecar (written beside it) */
        char xdmf[EKM_ATOMIC_PATH_MAX + 8];
        ekm_xdmf_path(o->out, xdmf, sizeof xdmf);
        rc = ekm_atomic_refuse_input(xdmf, in, n, err);
        if (!rc && o->csv)
            rc = ekm_atomic_refuse_input(xdmf, &o->csv, 1, err);
    }
    if (!rc && o->csv) {
        if (o->out)
            in[n++] = o->out;
        rc = ekm_atomic_refuse_input(o->csv, in, n, err);
    }
    free(in);
    return rc;
}
