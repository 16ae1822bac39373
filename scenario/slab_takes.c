/* slab_takes.c: which scenarios the 1D solver of a closure takes
 * (slab_takes.h). */
#include "slab_takes.h"

#include "boundary.h"
#include "closure.h"

ekm_status ekm_scenario_slab_takes(const ekm_scenario *sc, ekm_error *err)
{
    const char *name = sc->closure->name;
    if (sc->closure->ekm_transport)
        return EKM_OK;
    if (!sc->closure->local_stress || !sc->closure->local_phi)
        return EKM_FAIL(
            err, EKM_EUNAVAILABLE,
            "%s: [model] closure = %s has no slab solver (it runs in ekm homog and ekmcompare fit "
            "--rheology; docs/model/closures.md)",
            sc->source, name);
    const char *why = NULL;
    if (sc->cells_x > 1)
        why = "[domain] cells_x: a 2D domain (the slab solver is 1D)";
    else if (sc->bottom.kind != EKM_BC_WALL)
        why = "[bottom] type: expected wall (the layer rests on a no-slip base)";
    else if (sc->bottom.slip_length != 0.0)
        why = "[bottom] slip_length: expected 0 (no slip)";
    else if (sc->top.kind == EKM_BC_WALL && !ekm_boundary_pressure_wall(&sc->top))
        why =
            "[top]: a wall without pressure (a volume-controlled gap is the closure's homogeneous shear, ekm "
            "homog)";
    else if (sc->top.kind == EKM_BC_WALL && sc->top.slip_length != 0.0)
        why = "[top] slip_length: expected 0 (no slip)";
    else if (sc->top.kind != EKM_BC_WALL && sc->top.kind != EKM_BC_FREE)
        why = "[top] type: expected free or a wall with pressure";
    else if (sc->hypo.enabled)
        why = "[hypo] enabled: the solid regime is the EKM's";
    else if (sc->angle_rate != 0.0)
        why = "[gravity] angle_rate: a tilting slab";
    else if (ekm_scenario_gravity_z(sc) > 0.0)
        why = "[gravity]: expected gravity into the bed (g_z <= 0)";
    else if (sc->top.kind == EKM_BC_FREE && !(ekm_scenario_gravity_z(sc) < 0.0))
        why = "[gravity] magnitude: a free surface needs gravity into the bed (the pressure is the weight "
              "above)";
    else if (sc->top.kind == EKM_BC_WALL && sc->layer_height < sc->length)
        why = "[initial] layer_height: a layer under a top wall fills the gap";
    else if (!(sc->phi_init > 0.0))
        why = "[initial] phi: expected a volume fraction > 0 (it sets the layer's mass)";
    if (why)
        return EKM_FAIL(
            err, EKM_EUNAVAILABLE,
            "%s: %s is not what closure %s's slab solver takes (a no-slip base; a free surface or "
            "a top wall held at a pressure; docs/model/closures.md)",
            sc->source, why, name);
    if (!(sc->numerics.gdot_min > 0.0))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [numerics] gdot_min: missing (closure %s's slab solver needs it: the shear rate "
                        "[1/s] below which its viscosity mu P / |gdot| is cut, docs/model/closures.md)",
                        sc->source, name);
    return EKM_OK;
}
