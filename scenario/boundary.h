/* boundary.h: the boundary of a scenario's domain as the scenario file
 * gives it: the kind of each end and side ([bottom] [top] [left] [right]
 * type) and its values (docs/scenario-format.md). What each kind does to
 * the fields is the solvers' (continuum/bc.h, continuum/twod/bc2d.h).
 */
#ifndef EKM_BOUNDARY_H
#define EKM_BOUNDARY_H

typedef enum {
    EKM_BC_WALL = 0, /* impermeable, adiabatic, tangential speed + slip length */
    EKM_BC_INFLOW,   /* prescribed phi, w, u, T; closes to a wall at t_stop */
    EKM_BC_OUTFLOW,  /* zero gradient of every field */
    EKM_BC_FREE,     /* open to vacuum: zero stress, material may leave */
    EKM_BC_PISTON    /* prescribed w(t) = w, w_return alternating each half period; no slip */
} ekm_bc_kind;

/* The most inlet segments one end may have ([bottom]/[top] inlet_x, a list). */
#define EKM_INLETS_MAX 8

typedef struct {
    ekm_bc_kind kind;
    double velocity;    /* wall: tangential velocity u of the wall; a top wall with shear_rate:
                         * its speed at zero gap, [bottom] velocity (set by the reader: the wall
                         * moves at velocity + shear_rate L(t), bc.h) [m/s] */
    double slip_length; /* wall: Navier slip length, 0 = no slip [m] */
    double phi;         /* inflow: volume fraction entering [-] */
    double w;           /* inflow: normal velocity along +z [m/s] */
    double u;           /* inflow: tangential velocity [m/s] */
    double T;           /* inflow: granular temperature [m^2/s^2] */
    double t_stop;      /* inflow: time it closes to a resting wall [s] */
    double t_start;     /* inflow, 2D: time it opens; a resting wall before [s] */
    /* inflow, 2D: the centres of the inlet segments, [0] .. [n_inlets - 1] [m] */
    double inlet_x[EKM_INLETS_MAX];
    int n_inlets;         /* inflow, 2D: how many segments (1 unless inlet_x lists more) */
    double inlet_width;   /* inflow, 2D: width of each inlet segment, NAN: the whole end; the end's
                           * faces whose centres lie in one are the inlet, the rest a resting wall [m] */
    double plate_x;       /* wall, 2D: centre of the plate the wall is [m] (default: the middle) */
    double plate_width;   /* wall, 2D: width of that plate, NAN: the whole end; the end's faces
                           * whose centres lie outside it are open (free: zero stress, material
                           * leaves, nothing enters) [m] */
    double period;        /* piston: period of the velocity program [s] */
    double w_return;      /* piston: w in the second half of each period, NAN: -w [m/s] */
    double pressure;      /* wall (top only): normal stress held on the moving wall, NAN: the wall
                           * stays put (bc.h, the gap L(t)) [Pa] */
    double pressure_rate; /* wall with pressure: relative gap speed per relative stress
                           * mismatch, dL/dt = rate L (P_top - P)/P [1/s] */
    double shear_rate;    /* wall with pressure (top only): the wall's tangential speed is
                           * [bottom] velocity + shear_rate L(t) at every instant, so the walls
                           * impose the shear rate while the gap L(t) moves; NAN: none [1/s] */
} ekm_bc;

/* The kind's name as a scenario file writes it ("wall", "inflow", ...). */
const char *ekm_boundary_kind_name(ekm_bc_kind kind);

/* The kind named name: 1 and *kind, or 0 for an unknown name. */
int ekm_boundary_kind_of(const char *name, ekm_bc_kind *kind);

/* The kinds' names separated by blanks, for an error message. */
#define EKM_BOUNDARY_KIND_NAMES "wall inflow outflow free piston"

/* 1 if bc is a wall held at a normal pressure (its gap moves: pressure set). */
int ekm_boundary_pressure_wall(const ekm_bc *bc);

/* 1 if bc is a wall whose tangential speed follows its gap (shear_rate set). */
int ekm_boundary_rate_wall(const ekm_bc *bc);

#endif
