/* closure_ekm.c: the EKM's two variants as closure styles, ekm_full and
 * ekm_thesis (model.h: the law; closure.h). */
#include "closure.h"

static ekm_status ekm_check(const ekm_closure *c, const ekm_material *m, ekm_error *err)
{
    (void)c;
    return ekm_material_check(m, err);
}

static ekm_status ekm_homog(const ekm_closure *c, const ekm_material *m, double phi, double gdot,
                            ekm_homog_state *out, ekm_error *err)
{
    return ekm_homog_shear(m, c->variant, phi, gdot, out, err);
}

static ekm_status ekm_homog_p(const ekm_closure *c, const ekm_material *m, double P, double gdot,
                              ekm_homog_state *out, ekm_error *err)
{
    return ekm_homog_shear_at_pressure(m, c->variant, P, gdot, out, err);
}

const ekm_closure ekm_closure_ekm_full = {
    .name = "ekm_full",
    .about = "the EKM with the full Newtonian normal stress (mu_n = 4/3 eta + zeta; docs/model/law.md)",
    .is_ekm = 1,
    .ekm_transport = 1,
    .variant = EKM_VARIANT_FULL,
    .has_temperature = 1,
    .check = ekm_check,
    .homog = ekm_homog,
    .homog_p = ekm_homog_p,
};

const ekm_closure ekm_closure_ekm_thesis = {
    .name = "ekm_thesis",
    .about = "the EKM of the thesis's Chapter 6 (mu_n = zeta; docs/model/law.md)",
    .is_ekm = 1,
    .ekm_transport = 1,
    .variant = EKM_VARIANT_THESIS,
    .has_temperature = 1,
    .check = ekm_check,
    .homog = ekm_homog,
    .homog_p = ekm_homog_p,
};
