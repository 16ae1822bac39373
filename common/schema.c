/* schema.c: the field table (see schema.h).  EKM = ekm's output
 * (docs/output-format.md), CG = ekmcompare's coarse-grained DEM fields
 * (docs/compare.md); one name has one unit everywhere. */
#include "schema.h"

#include <string.h>

#define SE(name, units, what)                                                         \
    {                                                                                 \
        name "_se", units, "standard error of " what " (blocking over snapshots; CG)" \
    }

static const ekm_field FIELDS[] = {
    {"z", "m",
     "coordinate along the slab normal: cell centres of each frame (EKM 1D, [nt][nz]: a pressure-held wall "
     "moves them), cell centres (EKM 2D, [nz]), bin centres (CG, [nz])"},
    {"x", "m", "bin centres along x (CG with --axis x)"},
    {"y", "m", "bin centres along y (CG with --axis y)"},
    {"t", "s", "output times (EKM), snapshot-window times (CG)"},
    {"gap", "m", "wall-to-wall gap at each output time (EKM with a pressure-controlled top wall)"},
    {"nsnapshots", "1", "number of DEM snapshots averaged into each time row (CG)"},
    {"phi", "1", "solid volume fraction"},
    {"rho", "kg/m^3", "bulk density (CG)"},
    {"vx", "m/s", "tangential velocity along x (EKM: u at the cell centre; CG: momentum/rho)"},
    {"vy", "m/s", "velocity along y (CG: momentum/rho)"},
    {"vz", "m/s", "normal velocity (EKM: mean of the cell's two face values; CG: momentum/rho)"},
    {"T", "m^2/s^2", "granular temperature per degree of freedom"},
    {"P", "Pa", "pressure -tr(sigma)/3, positive in compression"},
    {"sxz", "Pa", "shear stress sigma_xz (EKM: mean of the cell's two face shear stresses)"},
    {"szz", "Pa", "normal stress sigma_zz, negative in compression"},
    {"mu", "1", "stress ratio |sxz|/P (CG, with a contact stress)"},
    {"I", "1", "inertial number |dvx/dz| d / sqrt(P/rho_p) (CG, with a contact stress)"},
    {"regime", "1 (0 empty, 1 kinetic, 2 dense flow, 3 solid)", "the cell's regime (EKM)"},
    SE("phi", "1", "phi"),
    SE("rho", "kg/m^3", "rho"),
    SE("vx", "m/s", "vx"),
    SE("vy", "m/s", "vy"),
    SE("vz", "m/s", "vz"),
    SE("T", "m^2/s^2", "T"),
    SE("P", "Pa", "P"),
    SE("sxz", "Pa", "sxz"),
    SE("szz", "Pa", "szz"),
    SE("mu", "1", "mu"),
    SE("I", "1", "I"),
    /* 2D coarse-graining (ekmcompare cg --axes x,z) and the base pressure
     * (ekmcompare base), docs/compare.md */
    {"kxx", "Pa", "kinetic stress K_xx of the velocity fluctuations, >= 0 (CG 2D)"},
    {"kzz", "Pa", "kinetic stress K_zz of the velocity fluctuations, >= 0 (CG 2D)"},
    {"kxz", "Pa", "kinetic stress K_xz of the velocity fluctuations (CG 2D)"},
    {"sxx", "Pa", "normal stress sigma_xx, negative in compression (CG 2D)"},
    {"cxx", "Pa", "contact stress xx, negative in compression (CG 2D, with a contact stress)"},
    {"czz", "Pa", "contact stress zz, negative in compression (CG 2D, with a contact stress)"},
    {"cxz", "Pa", "contact stress xz (CG 2D, with a contact stress)"},
    SE("kxx", "Pa", "kxx"),
    SE("kzz", "Pa", "kzz"),
    SE("kxz", "Pa", "kxz"),
    SE("sxx", "Pa", "sxx"),
    SE("cxx", "Pa", "cxx"),
    SE("czz", "Pa", "czz"),
    SE("cxz", "Pa", "cxz"),
    {"p_base", "Pa", "base pressure: normal force of the pile on the floor grains per unit floor area"},
    {"p_base_se", "Pa", "standard error of p_base across the runs of the ensemble (independent piles)"},
    {"p_base_se_fold", "Pa", "standard error of p_base from folding: |p(x) - p(mirror of x)|/2"},
    {"p_base_runs", "Pa", "p_base of each run of the ensemble, [runs][bins]"},
};

size_t ekm_field_count(void)
{
    return sizeof FIELDS / sizeof FIELDS[0];
}

const ekm_field *ekm_field_at(size_t i)
{
    return i < ekm_field_count() ? &FIELDS[i] : NULL;
}

const ekm_field *ekm_field_lookup(const char *name)
{
    for (size_t i = 0; i < ekm_field_count(); i++)
        if (strcmp(FIELDS[i].name, name) == 0)
            return &FIELDS[i];
    return NULL;
}

const char *ekm_field_units(const char *name)
{
    const ekm_field *f = ekm_field_lookup(name);
    return f ? f->units : NULL;
}

const char *ekm_field_description(const char *name)
{
    const ekm_field *f = ekm_field_lookup(name);
    return f ? f->description : NULL;
}
