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
