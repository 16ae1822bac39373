/* fit_scen.h: `ekmcompare fit --scenario CASES.json`: [material]
 * parameters fitted to steady DEM profiles (chute, shear cell) by running
 * the EKM in-process (libekm: ekm_scenario_load, ekm_run, ekm_fields_compute)
 * at every trial parameter vector (docs/compare.md, "fit --scenario").
 *
 * CASES.json (written by the campaign from the resolved scenarios):
 *   {"cases": [{"dem": "results/chute/theta22/cg_lammps.h5",
 *               "scenario": "scenarios/chute.ini", "set": ["gravity.angle=22"],
 *               "fields": ["phi","vx","T","P","sxz"], "shift_m": 0, "weight": 1}, ...]}
 * dem and scenario are required (paths relative to the current directory);
 * material (a material file whose [material] replaces the scenario's, as
 * `ekm run --material`: a closure set's start, e.g. scenarios/closures/
 * mu_i.ini with set ["model.closure=mu_i"]; T is then refused in fields
 * when the closure has no temperature), set (default []), fields (default all five), shift_m (default 0,
 * added to the DEM coordinate as `score --shift`) and weight (default 1, > 0: the case's residuals are
 * multiplied by sqrt(weight)) are optional; any other key is an error.
 *
 * Per trial material and case: the scenario is loaded through libekm's
 * reader with the case's set overrides followed by material.K=V (%.17g)
 * for every fitted key (so the reader validates the trial), solved as the
 * campaign's ekm rule does (a [run] stop = steady scenario by Newton from
 * its initial state, ekm_steady_solve; by time stepping, ekm_run, when it
 * has no steady state there or is not a steady scenario), and the state
 * interpolated onto the DEM points exactly as `ekmcompare score --ekm-time
 * last` does (cg_score_locate/cg_score_interp; every DEM window against the
 * EKM's last state, on the cell centres of that state: with a pressure-held
 * wall the grid stretched to its current gap, the last row of the /z an
 * ekm output would have, as score's cg_score_centres takes it). Residuals sqrt(weight) (model - DEM)/SE on
 * the candidate points: inside the EKM's cell-centre range (of the initial grid; with a pressure-held wall,
 * whose gap is a result, any DEM point: one outside the last state's centres then counts as one off the EKM's
 * material below), DEM value finite,
 * SE_DEM > CG_SCORE_SE_FLOOR x RMS of the DEM field (as score), and DEM
 * phi > support x (the largest DEM phi of the case). A candidate counts
 * only where the EKM has material too (its interpolated phi above the same
 * threshold); elsewhere its residual is 0 and it is not counted in dof.
 */
#ifndef CG_FIT_SCEN_H
#define CG_FIT_SCEN_H

#include <stddef.h>

#include "fit.h"
#include "point.h"
#include "scenario.h"
#include "status.h"

/* Profiles a residual can be formed of. */
enum cg_fitsc_field { CG_FITSC_PHI, CG_FITSC_VX, CG_FITSC_T, CG_FITSC_P, CG_FITSC_SXZ, CG_FITSC_NFIELD };
#define CG_FITSC_SUPPORT 0.1 /* default support threshold: fraction of the largest DEM phi */
/* Steps of the finite differences. An EKM run's result is not smooth in the
 * parameters below about 1e-8 relative (the adaptive time steps and the
 * iteration tolerances change it in steps: measured, docs/compare.md), so
 * both Jacobians step 1e-4: GSL's forward differences of the trust region
 * (h_df, in the transformed parameters) and the central differences of the
 * identifiability test (relative to the value). */
#define CG_FITSC_FD_STEP  1e-4
#define CG_FITSC_JAC_STEP 1e-4
/* The trust region's tests: steps below 1e-6 relative (xtol), gradient
 * below 1e-6 (gtol) or a chi2 change below 1e-8 relative (ftol) end a
 * start; at most 100 iterations. Tighter tests (those of --rheology) chase
 * the runs' own round-off for hundreds of evaluations. */
/* The Newton state of a case at the fitted material is kept when the
 * time-stepped run agrees within this fraction of its maxima (the
 * campaign's test, continuum/point.h). */
#define CG_FITSC_AGREE_TOL EKM_POINT_AGREE_TOL
#define CG_FITSC_XTOL      1e-6
#define CG_FITSC_GTOL      1e-6
#define CG_FITSC_FTOL      1e-8
#define CG_FITSC_MAX_ITER  100
#define CG_FITSC_STARTS    1 /* default starts: each evaluation is a set of EKM runs */

const char *cg_fitsc_field_name(int f); /* "phi", "vx", "T", "P", "sxz" */

/* How a case's EKM state was made (continuum/point.h). */
enum cg_fitsc_solver { CG_FITSC_SOLVER_NONE, CG_FITSC_SOLVER_STEADY, CG_FITSC_SOLVER_RUN };

typedef struct {
    char *dem, *scenario; /* paths as given */
    char *material;       /* the case's material file (its [material], as ekm run --material), NULL: none */
    char **set;           /* the case's overrides */
    size_t nset;
    unsigned fields; /* bit mask of cg_fitsc_field: the case's and --fields */
    double shift_m;  /* added to the DEM coordinate [m] */
    double weight;   /* > 0 */
    /* the DEM: ntd windows x nzd bins */
    size_t ntd, nzd;
    double *zd;                                        /* shifted coordinate [m], nzd */
    double *fd[CG_FITSC_NFIELD], *sd[CG_FITSC_NFIELD]; /* [ntd][nzd], NULL if not fitted */
    double *phid;                                      /* DEM phi [ntd][nzd] (support) */
    double phi_threshold;                              /* support threshold [-] */
    size_t *cand[CG_FITSC_NFIELD];                     /* candidate points (j nzd + k) */
    size_t ncand[CG_FITSC_NFIELD];
    size_t nres;         /* sum of ncand */
    double phi_init_max; /* largest phi the scenario starts or feeds with [-] */
    /* the last evaluation */
    size_t used[CG_FITSC_NFIELD];
    double chi2_field[CG_FITSC_NFIELD];
    double chi2;
    double wall_last_s;  /* EKM wall time of the last run [s] */
    double wall_total_s; /* all its runs [s] */
    long runs;
    long steady_solves; /* runs solved by ekm_steady_solve */
    long stepped_runs;  /* runs by time stepping (not steady, or no steady state found by Newton) */
    int last_solver;    /* cg_fitsc_solver of the last run */
    /* the fitted material's Newton state against ekm_run (fit_scen.c solve_case) */
    int check_done;          /* 1: compared */
    int check_run_steady;    /* the run ended steady */
    int check_agrees;        /* 1: the Newton state was kept */
    double check_difference; /* ekm_point_agreement of the two states [-] */
    ekm_scenario sc;         /* the case's scenario with its overrides, read once */
    int sc_loaded;           /* 1: sc was loaded, or its load tried (ekm_scenario_free) */
} cg_fitsc_case;

typedef struct {
    const char *cases_path;
    cg_fitsc_case *cases;
    size_t ncases;
    unsigned fields; /* --fields */
    double support;  /* support threshold, fraction of the largest DEM phi */
    size_t nparams;
    int param[CG_FIT_MAXP]; /* fitted keys (cg_fit_param_lookup) */
    size_t nres;
    int progress; /* 1: a line per evaluation on stderr */
    long evaluations;
    double started_s;  /* monotonic clock at the start */
    double ekm_wall_s; /* all EKM runs [s] */
    int check_final;   /* 1 while the fitted material is evaluated (ekm_point_solve's check) */
} cg_fitsc_problem;

/* Read CASES.json and every case's DEM file and scenario (with its set).
 * Errors: one line naming CASES.json, the case index and key (EKM_EINPUT;
 * EKM_EIO for a file that cannot be opened), the scenario reader's message
 * passed through. pb->fields and pb->support must be set before.
 * cg_fitsc_free() in every case. */
ekm_status cg_fitsc_load(cg_fitsc_problem *pb, const char *cases_path, ekm_error *err);
void cg_fitsc_free(cg_fitsc_problem *pb);

/* The start material: the first case's scenario [material]. */
ekm_status cg_fitsc_start_material(const cg_fitsc_problem *pb, ekm_material *m, ekm_variant *variant,
                                   const ekm_closure **closure, ekm_error *err);

/* The driver's problem (residual callbacks on pb). */
void cg_fitsc_spec(cg_fitsc_problem *pb, const ekm_material *start, cg_fit_spec *sp);

/* Residuals at material m (the fitted keys replaced in every case) into
 * r[0..pb->nres); updates every case's record. Non-zero: a scenario does
 * not load with these values or its EKM run fails. */
int cg_fitsc_residuals(cg_fitsc_problem *pb, const ekm_material *m, double *r);

#endif
