/* grid2d.h: the 2D grid of the semi-implicit step (step2d.h): geometry,
 * the PETSc DMStag layouts and the data of the two ends (walls, free
 * surfaces, inflows through one or more inlet segments).
 *
 * nx x nz cells of dx = width/nx by dz = length/nz [m]; x periodic or
 * bounded by side walls at x = 0 and x = width, z bounded by the bottom
 * (z = 0) and top (z = length) ends of the scenario ([bottom], [top]).
 *
 *   dm    the state: phi [-] and T [m^2/s^2] at the cell centres
 *         (DMSTAG_ELEMENT), vx [m/s] on the x-faces (DMSTAG_LEFT), vz [m/s]
 *         on the z-faces (DMSTAG_DOWN); box stencil of width 2 (the face
 *         momentum's convection reaches two cells: flux.h).  With the
 *         solid regime ([hypo] enabled) also the solid stresses sxx, syy,
 *         szz [Pa], the flag solid (0 or 1) and the rate of the last
 *         switch test [1/s] at the cells, sxz [Pa] at the corners
 *         (DMSTAG_DOWN_LEFT: the solid's shear stress, or the flow's of
 *         the last step where the corner is not solid: regime2d.h)
 *   dmv   the velocity system's unknowns: vx and vz on the faces
 *   dmt   the temperature system's unknowns: T at the cell centres
 *
 * Each column of cells is the 1D solver's grid (state.h): cell (i, j)
 * spans [i dx, (i+1) dx] x [j dz, (j+1) dz]; x-face (i, j) is its left
 * face, z-face (i, j) its bottom face; corner (i, j) its lower left corner.
 * A state uniform in x is the 1D state in every column: vx of the x-faces
 * of row j is the 1D u_j, vz of the z-faces of row j the 1D w_j.
 *
 * A top wall held at a normal pressure ([top] pressure) moves as one body
 * and the grid stretches with it, as the 1D grid (step.c): dz = L/nz
 * changes every step and z-face j moves at j w_grid, w_grid = (dL/dt)/nz;
 * the mass and heat fluxes are taken relative to the moving faces.
 */
#ifndef EKM2D_GRID2D_H
#define EKM2D_GRID2D_H

#include <petscdmstag.h>

#include "scenario.h"
#include "status.h"

typedef struct {
    const ekm_scenario *sc;
    MPI_Comm comm;
    int nx, nz;                 /* cells along x and z */
    double dx, dz;              /* cell sizes [m] (dz changes with a moving top wall) */
    int top_moving;             /* 1: the top wall is held at a pressure and moves (the grid stretches) */
    double w_grid;              /* moving top wall: its speed over nz, z-face j moves at j w_grid [m/s] */
    int periodic;               /* 1: periodic in x */
    double side_conductance[2]; /* side walls x = 0, x = width: 1/(dx/2 + slip_length) [1/m] */
    int n_inlets[2];            /* bottom, top: the inlet segments (one: the whole end without) */
    /* bottom, top: each segment's first and last face column, and the
     * fraction [-] of those two faces' width the segment covers (1 between
     * them): an inlet edge inside a face lets that face carry its share */
    PetscInt inlet_lo[2][EKM_INLETS_MAX], inlet_hi[2][EKM_INLETS_MAX];
    double inlet_cover_lo[2][EKM_INLETS_MAX], inlet_cover_hi[2][EKM_INLETS_MAX];
    /* bottom, top: a wall with a plate ([bottom] plate_width): its first and
     * last face column (without one: 0 and nx - 1) */
    PetscInt plate_lo[2], plate_hi[2];
    DM dm, dmv, dmt;                 /* state, velocity unknowns, temperature unknowns */
    PetscInt s_phi, s_T, s_vx, s_vz; /* slots of dm's arrays */
    PetscInt s_sxx, s_syy, s_szz;    /* ... the solid regime's (-1 without it) */
    PetscInt s_solid, s_rate, s_sxz;
    PetscInt v_vx, v_vz;         /* slots of dmv's arrays */
    PetscInt t_T;                /* slot of dmt's arrays */
    PetscInt x0, z0, nxl, nzl;   /* this rank's cells: x0 .. x0 + nxl - 1, z0 .. z0 + nzl - 1 */
    PetscInt gx0, gz0, gnx, gnz; /* its ghosted box (dm's ghost corners, extra face points included) */
} ekm2d_grid;

/* The data of one end (bottom or top) at one time. */
typedef struct {
    ekm_bc_kind kind;  /* wall, free or inflow (an inflow outside [t_start, t_stop): wall) */
    double w;          /* inflow: the inlet faces' vz [m/s] */
    double phi_in;     /* inflow: the entering phi [-] */
    double u_in, T_in; /* inflow: the entering vx [m/s] and T [m^2/s^2] */
    double u_wall;     /* wall: tangential speed [m/s] */
    double w_wall;     /* wall: its normal speed (a moving top wall: dL/dt; else 0) [m/s] */
    double
        conductance; /* wall (also an inflow end beside its inlet): 1/(dz/2 + slip_length) [1/m]; free: 0 */
    int n_inlets;    /* inflow: its segments q < n_inlets, face columns lo[q] .. hi[q] */
    PetscInt inlet_lo[EKM_INLETS_MAX], inlet_hi[EKM_INLETS_MAX];
    double inlet_cover_lo[EKM_INLETS_MAX], inlet_cover_hi[EKM_INLETS_MAX]; /* [-], as the grid's */
    /* wall: the plate's face columns plate_lo .. plate_hi (the whole end
     * without [bottom]/[top] plate_width); the faces outside are open */
    PetscInt plate_lo, plate_hi;
} ekm2d_end;

/* The grid of sc on comm (collective).  EKM_EINPUT: an inlet segment that
 * covers no face; EKM_EINTERNAL: a PETSc error. */
ekm_status ekm2d_grid_create(const ekm_scenario *sc, MPI_Comm comm, ekm2d_grid *g, ekm_error *err);
void ekm2d_grid_destroy(ekm2d_grid *g);

/* End `top` (0: bottom, 1: top) at time t [s]. */
ekm2d_end ekm2d_grid_end(const ekm2d_grid *g, int top, double t);

/* Face column i (a periodic image wrapped) of end e is an open inlet face
 * (in one of its segments). */
static inline int ekm2d_inlet_face(const ekm2d_grid *g, const ekm2d_end *e, PetscInt i)
{
    if (e->kind != EKM_BC_INFLOW)
        return 0;
    if (g->periodic)
        i = (i % g->nx + g->nx) % g->nx;
    for (int q = 0; q < e->n_inlets; q++)
        if (i >= e->inlet_lo[q] && i <= e->inlet_hi[q])
            return 1;
    return 0;
}

/* The phi an entering flow carries through z-face column i of end e: the
 * inflow's phi_in times the fraction of the face its segment covers (1
 * inside the segment, less at an edge that cuts a face), 0 beside the
 * inlets, so that the inflow is rho_p phi_in |w| inlet_width on any grid. */
static inline double ekm2d_inlet_phi(const ekm2d_grid *g, const ekm2d_end *e, PetscInt i)
{
    if (e->kind != EKM_BC_INFLOW)
        return 0.0;
    if (g->periodic)
        i = (i % g->nx + g->nx) % g->nx;
    for (int q = 0; q < e->n_inlets; q++)
        if (i >= e->inlet_lo[q] && i <= e->inlet_hi[q])
            return e->phi_in * (i == e->inlet_lo[q]   ? e->inlet_cover_lo[q]
                                : i == e->inlet_hi[q] ? e->inlet_cover_hi[q]
                                                      : 1.0);
    return 0.0;
}

/* z-face column i of end e is open: a free end, or a wall's face beside
 * its plate ([bottom] plate_width): zero stress, its vz that of the face
 * inwards, material leaves and nothing enters (ekm2d_flux_z). */
static inline int ekm2d_open_face(const ekm2d_grid *g, const ekm2d_end *e, PetscInt i)
{
    if (e->kind == EKM_BC_FREE)
        return 1;
    if (e->kind != EKM_BC_WALL)
        return 0;
    if (g->periodic)
        i = (i % g->nx + g->nx) % g->nx;
    return i < e->plate_lo || i > e->plate_hi;
}

/* vz of z-face column i of end e when it is prescribed [m/s]: an open
 * inlet face's w, a wall's speed (0 unless it moves), else 0. */
static inline double ekm2d_end_face_w(const ekm2d_grid *g, const ekm2d_end *e, PetscInt i)
{
    return e->kind == EKM_BC_WALL ? e->w_wall : ekm2d_inlet_face(g, e, i) ? e->w : 0.0;
}

/* Cell (i, j) exists (in the domain, or a periodic image). */
static inline int ekm2d_cell_exists(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return j >= 0 && j < g->nz && (g->periodic || (i >= 0 && i < g->nx));
}

/* (i, j) lies in this rank's ghosted box. */
static inline int ekm2d_in_box(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return i >= g->gx0 && i < g->gx0 + g->gnx && j >= g->gz0 && j < g->gz0 + g->gnz;
}

/* x-face column i lies on a side wall (no periodic image). */
static inline int ekm2d_side_face(const ekm2d_grid *g, PetscInt i)
{
    return !g->periodic && (i == 0 || i == g->nx);
}

/* Index of point (i, j) of the ghosted box in a work array of
 * ekm2d_grid_box_size() entries (cells, faces and corners alike). */
static inline size_t ekm2d_box_index(const ekm2d_grid *g, PetscInt i, PetscInt j)
{
    return (size_t)(j - g->gz0) * (size_t)(g->gnx + 1) + (size_t)(i - g->gx0);
}

static inline size_t ekm2d_grid_box_size(const ekm2d_grid *g)
{
    return (size_t)(g->gnx + 1) * (size_t)(g->gnz + 1);
}

#endif
