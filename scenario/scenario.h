/* scenario.h: a run's parameters, their defaults, and reading them from a
 * scenario INI file (inih) with command-line overrides.
 *
 * ekm owns the sections listed in docs/scenario-format.md ([scenario]
 * [material] [model] [domain] [gravity] [initial] [bottom] [top] [run]
 * [numerics] [hypo]); the keys of the other tools' sections ([dem],
 * [compare], [campaign], [figures]) are checked (name, <engine>./<size>.
 * prefix, type: resolve.h) and kept as written in tool_entries; any other
 * section or key is an error that names the file, line, section and key.
 */
#ifndef EKM_SCENARIO_H
#define EKM_SCENARIO_H

#include <stddef.h>

#include "boundary.h"
#include "model.h"
#include "switching.h"
#include "status.h"

/* When a run ends ([run] stop): at t_end, or when steady (run.h). */
typedef enum { EKM_STOP_T_END = 0, EKM_STOP_STEADY = 1 } ekm_stop;

typedef enum { EKM_CONVECTION_UPWIND = 0, EKM_CONVECTION_TVD = 1 } ekm_convection;

/* The TVD limiters [numerics] limiter may name; the solver's registry
 * (continuum/flux.h) has each of them (tests/continuum/test_flux.c). */
#define EKM_SCENARIO_LIMITERS "minmod vanleer superbee mc"

/* How the normal momentum solve takes the pressure gradient (step.h): implicit,
 * linearised in the next mass update (the step is not bound by the sound
 * speed), or explicit at (phi*, T*) (the acoustic CFL, control.h). */
typedef enum { EKM_COUPLING_IMPLICIT = 0, EKM_COUPLING_EXPLICIT = 1 } ekm_coupling;

typedef struct {
    double cfl; /* Courant number on |w| (+ the sound speed with explicit coupling) [-] */
    ekm_convection convection;
    char limiter[16];             /* TVD limiter name: one of EKM_SCENARIO_LIMITERS */
    double dt_max;                /* largest time step [s] */
    double dt_min;                /* smallest step before giving up [s] */
    double phi_dry;               /* below this phi a cell is empty (vacuum) [-] */
    double phi_vacuum;            /* below this phi a cell cannot compress its neighbour (step.c) [-] */
    double T_floor;               /* lowest T of a non-empty cell [m^2/s^2] */
    double phi_step_max;          /* largest fraction of the gap phi_cp - phi one step may close [-] */
    double solid_relax_step;      /* largest relaxation of the hypoplastic law in one step (dt times
                                   * its relaxation rate, hypo.h) [-] */
    double newton_tol;            /* relative tolerance of the implicit T solve [-] */
    int newton_max;               /* iterations of the implicit T solve before a retry */
    ekm_coupling normal_coupling; /* pressure in the normal momentum solve */
    double thermal_relax_step;    /* implicit coupling: largest relaxation of the kinetic pressure in
                                   * one step (dt times its rate, control.h) [-] */
    int surface_fill;             /* 1: a partly filled surface cell is dense material filling part of
                                   * it (2D only, twod/surface2d.c); 0: a state of its mean phi */
    double solid_lag_tol;         /* 2D: largest change of a solid cell's stress, relative to it, when
                                   * the law's norm is taken at the step's own rates instead of the
                                   * lagged ones (twod/regime2d.c) [-] */
    double gdot_min;              /* a local rheology's (mu_i) cut of its viscosity mu P / |gdot| at
                                   * vanishing shear rate (continuum/local_slab.h) [1/s]; NAN: not
                                   * given (no default: the slab solver of such a closure needs it) */
} ekm_numerics;

/* Where a key's value came from. */
typedef enum {
    EKM_FROM_FILE = 0,
    EKM_FROM_SET,
    EKM_FROM_DEFAULT,
    EKM_FROM_MATERIAL /* the material file (ekm_scenario_load_material) */
} ekm_origin;

/* One key as given (file or --set), kept for provenance in the output. */
typedef struct {
    char name[64];     /* "section.key" (for the other tools' sections the key as
                        * written, with its <engine>./<size>. prefix) */
    char value[160];   /* the value string as written */
    ekm_origin origin; /* EKM_FROM_FILE, EKM_FROM_MATERIAL or EKM_FROM_SET */
    int line;          /* file line, or the position of the --set (from 1) */
} ekm_entry;

typedef struct {
    char name[64]; /* scenario name */
    char description[256];
    char source[512];          /* file it was read from */
    char material_source[512]; /* the material file its [material] came from, "" : none */
    ekm_material material;
    ekm_variant variant;               /* the EKM's variant (closure->variant for an EKM closure) */
    const struct ekm_closure *closure; /* [model] closure (closure.h): ekm_full unless given */
    double length;                     /* domain height, z in [0, length] [m] */
    int cells;                         /* number of finite-volume cells */
    double width;           /* 2D domain: width, x in [0, width] [m]; NAN: not given (the 1D column) */
    int cells_x;            /* 2D domain: cells along x; 1: the 1D column (the only case ekm solves) */
    int periodic_x;         /* 2D domain: 1: periodic in x; 0: walls at x = 0 and x = width */
    double gravity;         /* magnitude G [m/s^2] */
    double angle_deg;       /* tilt of gravity in the x-z plane [deg]: g = G (sin a, -cos a) */
    double angle_rate;      /* the tilt grows at this rate after angle_start [deg/s] */
    double angle_start;     /* [s] */
    double phi_init;        /* initial volume fraction below layer_height [-] */
    double T_init;          /* initial granular temperature [m^2/s^2] */
    double u_init;          /* initial tangential velocity at z = 0 [m/s] */
    double shear_rate_init; /* initial du/dz: u = u_init + shear_rate z [1/s] */
    double layer_height;    /* material fills z < layer_height; vacuum above [m] */
    ekm_bc bottom, top;
    ekm_bc left, right;   /* 2D, periodic_x = 0: the side walls at x = 0 and x = width (wall only:
                           * slip_length; the wall rests) */
    double t_end;         /* end time [s] */
    double output_dt;     /* output interval [s] */
    ekm_stop stop;        /* [run] stop: t_end, or steady (t_end the longest run) */
    double steady_tol;    /* steady when every drift stays below this [1/s] (run.h) */
    double steady_window; /* ... over this long [s] */
    ekm_numerics numerics;
    ekm_hypo_params hypo;
    ekm_entry *entries; /* every key of ekm's sections read, in order (provenance;
                         * the output file's attributes) */
    size_t n_entries;
    ekm_entry *tool_entries; /* every key of [dem] [compare] [campaign] [figures] read,
                              * in order, as written (resolve.h resolves them) */
    size_t n_tool_entries;
} ekm_scenario;

/* Limits of a scenario (docs/scenario-format.md "Limits"): a scenario or
 * material file is a regular file of at most EKM_SCENARIO_MAX_BYTES bytes
 * of text (UTF-8, no control characters but tab, and CR before LF); a run
 * writes at most EKM_SCENARIO_MAX_FRAMES output frames (the initial state
 * and one every output_dt up to t_end). */
#define EKM_SCENARIO_MAX_BYTES  (1024 * 1024)
#define EKM_SCENARIO_MAX_FRAMES 100000

/* A scenario (or material) file's contents in memory. */
typedef struct {
    const char *name; /* the file name of the messages and of ekm_scenario.source */
    const char *text; /* its bytes (need not end in a NUL; a NUL in them is an error) */
    size_t size;      /* bytes in text [B] */
} ekm_scenario_text;

/* Defaults for everything that has one (docs/scenario-format.md). */
void ekm_scenario_init_defaults(ekm_scenario *s);

/* Read a scenario file, then apply overrides "section.key=value" in order.
 * On failure err names the file (or "--set"), line, section and key.
 * Call ekm_scenario_free() in every case. */
ekm_status ekm_scenario_load(ekm_scenario *s, const char *path, const char *const *overrides,
                             size_t n_overrides, ekm_error *err);

/* The same with the whole [material] section taken from material_path
 * (a file of only [material] and comments, as `ekmcompare fit --ini`
 * writes) instead of path's: its keys' provenance is material_path:LINE,
 * any other section there is an error naming material_path:LINE; the
 * overrides still apply last.  material_path NULL: ekm_scenario_load. */
ekm_status ekm_scenario_load_material(ekm_scenario *s, const char *path, const char *material_path,
                                      const char *const *overrides, size_t n_overrides, ekm_error *err);

/* Give s the material m, checked as its [material] section would be when
 * read (ekm_material_check and the scenario's checks that involve the
 * material: phi_cp above the initial and inflow phi, the [hypo] volume
 * fractions); a refused material is EKM_EINPUT (the message names the key
 * where s was given it) and leaves s as it was. For callers that solve one
 * scenario at many materials (continuum/point.h, the calibration). */
ekm_status ekm_scenario_set_material(ekm_scenario *s, const ekm_material *m, ekm_error *err);

/* The same reading texts already in memory (what a file holds): file, and
 * material (NULL: none) as --material's file; no file is opened. */
ekm_status ekm_scenario_load_texts(ekm_scenario *s, const ekm_scenario_text *file,
                                   const ekm_scenario_text *material, const char *const *overrides,
                                   size_t n_overrides, ekm_error *err);

void ekm_scenario_free(ekm_scenario *s);

/* ekm's keys in registry order (the order of docs/scenario-format.md):
 * their number, the section and name of key i < ekm_scenario_key_count(),
 * and the value key i has when it is not given, from the loaded scenario
 * (shortest round-trip number, enum name). Returns 0 when the key has no
 * value to show: a non-finite default (no limit, "never", "-w"), or a
 * [bottom]/[top] key of another boundary type. */
size_t ekm_scenario_key_count(void);
void ekm_scenario_key_name(size_t i, const char **section, const char **key);
int ekm_scenario_key_default(const ekm_scenario *s, size_t i, char *value, size_t size);

/* EKM_OK on the 1D column ([domain] cells_x = 1); a 2D domain is
 * EKM_EUNAVAILABLE "WHERE: [domain] cells_x = N: WHY" (WHERE the file and
 * line of cells_x, or --set), for what cannot solve it: ekm steady (the
 * 1D column only) and an ekm built without the 2D solver (issue 14; `ekm
 * run` hands a 2D scenario to it, continuum/twod/run2d.h). */
ekm_status ekm_scenario_require_1d(const ekm_scenario *s, const char *why, ekm_error *err);

/* The entry named "section.key" in list (n entries), or NULL. */
const ekm_entry *ekm_scenario_entry_find(const ekm_entry *list, size_t n, const char *name);

/* Gravity components [m/s^2] at the start (angle) and at time t. */
double ekm_scenario_gravity_x(const ekm_scenario *s);
double ekm_scenario_gravity_z(const ekm_scenario *s);
double ekm_scenario_angle_at(const ekm_scenario *s, double t);

/* The phi at which the hypoplastic law of a cell at phi takes its
 * density-dependent constants: phi, or [hypo] phi_fixed when set. */
double ekm_scenario_law_phi(const ekm_scenario *s, double phi);

#endif
