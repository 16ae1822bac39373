/* grid2d.c: the 2D grid, its DMStag layouts and the ends (grid2d.h). */
#include "grid2d.h"

#include "bc.h"

#include <math.h>
#include <string.h>

#define TRY(call, what)                                                                \
    do {                                                                               \
        if ((call) != 0) {                                                             \
            ekm2d_grid_destroy(g);                                                     \
            return EKM_FAIL(err, EKM_EINTERNAL, "2D grid: PETSc error in %s", (what)); \
        }                                                                              \
    } while (0)

/* The face columns whose centres lie in [lo, hi] [m], *first .. *last;
 * 0 when none does. */
static int segment_columns(const ekm2d_grid *g, double lo, double hi, PetscInt *first, PetscInt *last)
{
    *first = g->nx;
    *last = -1;
    for (PetscInt i = 0; i < g->nx; i++) {
        const double xc = (i + 0.5) * g->dx;
        if (xc >= lo && xc <= hi) {
            if (i < *first)
                *first = i;
            *last = i;
        }
    }
    return *last >= *first;
}

/* The face columns of end k's inlet segment q (without a segment: all of
 * them): every face the segment [x - w/2, x + w/2] overlaps (by more than
 * 1e-9 of a face, so that an edge on a face boundary takes no neighbour),
 * with the covered fraction of the first and the last; 0 when it covers
 * none. (The plate keeps the face-centre rule: a face is wall or open.) */
static int inlet_columns(ekm2d_grid *g, int k, int q, const ekm_bc *bc)
{
    g->inlet_lo[k][q] = 0;
    g->inlet_hi[k][q] = g->nx - 1;
    g->inlet_cover_lo[k][q] = g->inlet_cover_hi[k][q] = 1.0;
    if (bc->kind != EKM_BC_INFLOW || !isfinite(bc->inlet_width))
        return 1;
    const double lo = bc->inlet_x[q] - 0.5 * bc->inlet_width, hi = bc->inlet_x[q] + 0.5 * bc->inlet_width;
    const double tol = 1e-9 * g->dx;
    PetscInt first = g->nx, last = -1;
    for (PetscInt i = 0; i < g->nx; i++) {
        const double a = fmax(lo, i * g->dx), b = fmin(hi, (i + 1) * g->dx);
        if (b - a <= tol)
            continue;
        const double cover = b - a >= g->dx - tol ? 1.0 : (b - a) / g->dx;
        if (i < first) {
            first = i;
            g->inlet_cover_lo[k][q] = cover;
        }
        last = i;
        g->inlet_cover_hi[k][q] = cover;
    }
    g->inlet_lo[k][q] = first;
    g->inlet_hi[k][q] = last;
    return last >= first;
}

/* The face columns of end k's plate ([bottom]/[top] plate_width, a wall;
 * without one the whole end); 0 when the plate holds none. */
static int plate_columns(ekm2d_grid *g, int k, const ekm_bc *bc)
{
    g->plate_lo[k] = 0;
    g->plate_hi[k] = g->nx - 1;
    if (bc->kind != EKM_BC_WALL || !isfinite(bc->plate_width))
        return 1;
    return segment_columns(g, bc->plate_x - 0.5 * bc->plate_width, bc->plate_x + 0.5 * bc->plate_width,
                           &g->plate_lo[k], &g->plate_hi[k]);
}

ekm_status ekm2d_grid_create(const ekm_scenario *sc, MPI_Comm comm, ekm2d_grid *g, ekm_error *err)
{
    memset(g, 0, sizeof *g);
    g->sc = sc;
    g->comm = comm;
    g->nx = sc->cells_x;
    g->nz = sc->cells;
    g->dx = sc->width / sc->cells_x;
    g->dz = sc->length / sc->cells;
    g->periodic = sc->periodic_x;
    g->top_moving = ekm_boundary_pressure_wall(&sc->top);
    g->side_conductance[0] = 1.0 / (0.5 * g->dx + sc->left.slip_length);
    g->side_conductance[1] = 1.0 / (0.5 * g->dx + sc->right.slip_length);
    const ekm_bc *ends[2] = {&sc->bottom, &sc->top};
    for (int k = 0; k < 2; k++) {
        const int segmented = ends[k]->kind == EKM_BC_INFLOW && isfinite(ends[k]->inlet_width);
        g->n_inlets[k] = segmented ? ends[k]->n_inlets : 1;
        for (int q = 0; q < g->n_inlets[k]; q++)
            if (!inlet_columns(g, k, q, ends[k]))
                return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] inlet_width: the inlet covers no face", sc->source,
                                k ? "top" : "bottom");
        if (!plate_columns(g, k, ends[k]))
            return EKM_FAIL(err, EKM_EINPUT, "%s: [%s] plate_width: the plate holds no face centre",
                            sc->source, k ? "top" : "bottom");
    }
    TRY(DMStagCreate2d(comm, g->periodic ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, g->nx,
                       g->nz, PETSC_DECIDE, PETSC_DECIDE, sc->hypo.enabled ? 1 : 0, 1,
                       sc->hypo.enabled ? 7 : 2, DMSTAG_STENCIL_BOX, 2, NULL, NULL, &g->dm),
        "DMStagCreate2d");
    TRY(DMSetFromOptions(g->dm), "DMSetFromOptions");
    TRY(DMSetUp(g->dm), "DMSetUp");
    TRY(DMStagSetUniformCoordinatesProduct(g->dm, 0.0, sc->width, 0.0, sc->length, 0.0, 0.0),
        "DMStagSetUniformCoordinatesProduct");
    TRY(DMStagGetLocationSlot(g->dm, DMSTAG_ELEMENT, 0, &g->s_phi), "DMStagGetLocationSlot");
    TRY(DMStagGetLocationSlot(g->dm, DMSTAG_ELEMENT, 1, &g->s_T), "DMStagGetLocationSlot");
    TRY(DMStagGetLocationSlot(g->dm, DMSTAG_LEFT, 0, &g->s_vx), "DMStagGetLocationSlot");
    TRY(DMStagGetLocationSlot(g->dm, DMSTAG_DOWN, 0, &g->s_vz), "DMStagGetLocationSlot");
    g->s_sxx = g->s_syy = g->s_szz = g->s_solid = g->s_rate = g->s_sxz = -1;
    if (sc->hypo.enabled) {
        PetscInt *slots[5] = {&g->s_sxx, &g->s_syy, &g->s_szz, &g->s_solid, &g->s_rate};
        for (int k = 0; k < 5; k++)
            TRY(DMStagGetLocationSlot(g->dm, DMSTAG_ELEMENT, 2 + k, slots[k]), "DMStagGetLocationSlot");
        TRY(DMStagGetLocationSlot(g->dm, DMSTAG_DOWN_LEFT, 0, &g->s_sxz), "DMStagGetLocationSlot");
    }
    /* the systems: the same decomposition, a stencil of one cell */
    const PetscInt *lx, *lz;
    PetscInt px, pz;
    TRY(DMStagGetNumRanks(g->dm, &px, &pz, NULL), "DMStagGetNumRanks");
    TRY(DMStagGetOwnershipRanges(g->dm, &lx, &lz, NULL), "DMStagGetOwnershipRanges");
    const DMBoundaryType bx = g->periodic ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
    TRY(DMStagCreate2d(comm, bx, DM_BOUNDARY_NONE, g->nx, g->nz, px, pz, 0, 1, 0, DMSTAG_STENCIL_BOX, 1, lx,
                       lz, &g->dmv),
        "DMStagCreate2d (velocity)");
    TRY(DMSetUp(g->dmv), "DMSetUp");
    TRY(DMSetMatType(g->dmv, MATAIJ), "DMSetMatType");
    TRY(DMStagGetLocationSlot(g->dmv, DMSTAG_LEFT, 0, &g->v_vx), "DMStagGetLocationSlot");
    TRY(DMStagGetLocationSlot(g->dmv, DMSTAG_DOWN, 0, &g->v_vz), "DMStagGetLocationSlot");
    TRY(DMStagCreate2d(comm, bx, DM_BOUNDARY_NONE, g->nx, g->nz, px, pz, 0, 0, 1, DMSTAG_STENCIL_STAR, 1, lx,
                       lz, &g->dmt),
        "DMStagCreate2d (temperature)");
    TRY(DMSetUp(g->dmt), "DMSetUp");
    TRY(DMSetMatType(g->dmt, MATAIJ), "DMSetMatType");
    TRY(DMStagGetLocationSlot(g->dmt, DMSTAG_ELEMENT, 0, &g->t_T), "DMStagGetLocationSlot");
    TRY(DMStagGetCorners(g->dm, &g->x0, &g->z0, NULL, &g->nxl, &g->nzl, NULL, NULL, NULL, NULL),
        "DMStagGetCorners");
    TRY(DMStagGetGhostCorners(g->dm, &g->gx0, &g->gz0, NULL, &g->gnx, &g->gnz, NULL),
        "DMStagGetGhostCorners");
    return EKM_OK;
}

void ekm2d_grid_destroy(ekm2d_grid *g)
{
    if (g->dmt)
        DMDestroy(&g->dmt);
    if (g->dmv)
        DMDestroy(&g->dmv);
    if (g->dm)
        DMDestroy(&g->dm);
}

ekm2d_end ekm2d_grid_end(const ekm2d_grid *g, int top, double t)
{
    const ekm_bc *bc = top ? &g->sc->top : &g->sc->bottom;
    ekm2d_end e = {0};
    e.kind = bc->kind;
    if (bc->kind == EKM_BC_INFLOW && (t < bc->t_start || t >= bc->t_stop))
        e.kind = EKM_BC_WALL; /* closed: a resting wall */
    e.plate_lo = 0;
    e.plate_hi = g->nx - 1;
    if (bc->kind == EKM_BC_WALL) {
        e.plate_lo = g->plate_lo[top];
        e.plate_hi = g->plate_hi[top];
    }
    if (e.kind == EKM_BC_WALL || e.kind == EKM_BC_INFLOW) {
        e.u_wall = bc->kind == EKM_BC_WALL ? bc->velocity : 0.0;
        e.conductance = 1.0 / (0.5 * g->dz + (bc->kind == EKM_BC_WALL ? bc->slip_length : 0.0));
    }
    if (e.kind == EKM_BC_INFLOW) {
        e.w = bc->w;
        e.phi_in = bc->phi;
        e.u_in = bc->u;
        e.T_in = bc->T;
        e.n_inlets = g->n_inlets[top];
        for (int q = 0; q < e.n_inlets; q++) {
            e.inlet_lo[q] = g->inlet_lo[top][q];
            e.inlet_hi[q] = g->inlet_hi[top][q];
            e.inlet_cover_lo[q] = g->inlet_cover_lo[top][q];
            e.inlet_cover_hi[q] = g->inlet_cover_hi[top][q];
        }
    }
    return e;
}
