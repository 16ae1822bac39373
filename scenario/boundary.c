/* boundary.c: the boundary kinds' names and predicates (boundary.h). */
#include "boundary.h"

#include <math.h>
#include <string.h>

static const struct {
    ekm_bc_kind kind;
    const char *name;
} KINDS[] = {{EKM_BC_WALL, "wall"},
             {EKM_BC_INFLOW, "inflow"},
             {EKM_BC_OUTFLOW, "outflow"},
             {EKM_BC_FREE, "free"},
             {EKM_BC_PISTON, "piston"}};

const char *ekm_boundary_kind_name(ekm_bc_kind kind)
{
    for (size_t i = 0; i < sizeof KINDS / sizeof KINDS[0]; i++)
        if (KINDS[i].kind == kind)
            return KINDS[i].name;
    return "?";
}

int ekm_boundary_kind_of(const char *name, ekm_bc_kind *kind)
{
    for (size_t i = 0; i < sizeof KINDS / sizeof KINDS[0]; i++)
        if (strcmp(KINDS[i].name, name) == 0) {
            *kind = KINDS[i].kind;
            return 1;
        }
    return 0;
}

int ekm_boundary_pressure_wall(const ekm_bc *bc)
{
    return bc->kind == EKM_BC_WALL && !isnan(bc->pressure);
}

int ekm_boundary_rate_wall(const ekm_bc *bc)
{
    return bc->kind == EKM_BC_WALL && !isnan(bc->shear_rate);
}
