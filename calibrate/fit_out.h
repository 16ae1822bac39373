/* fit_out.h: the outputs of `ekmcompare fit`: FIT.json (jansson) and an
 * INI file with a [material] section, both written atomically (a
 * temporary name in the target directory, renamed when every output is
 * complete, removed on any error). Format: docs/compare.md. */
#ifndef CG_FIT_OUT_H
#define CG_FIT_OUT_H

#include "fit.h"
#include "fit_scen.h"
#include "status.h"

typedef struct {
    const cg_fit_problem *pb;   /* --rheology, or NULL */
    const cg_fitsc_problem *sc; /* --scenario, or NULL */
    int nstarts;                /* starts requested */
    ekm_variant variant;        /* of the start material */
    const ekm_closure *closure; /* the closure fitted: the [material] keys written are those it reads */
    const cg_fit_result *res;
    const char *start_source; /* "thesis material (ekm_material_thesis)" or the --start file */
    const char *json_path;    /* required */
    const char *ini_path;     /* NULL: none */
} cg_fit_outputs;

/* Write both outputs or neither. EKM_EIO naming the file on failure. */
ekm_status cg_fit_write(const cg_fit_outputs *o, ekm_error *err);

#endif
