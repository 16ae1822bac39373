/* switching.h: the rules by which a cell switches between the flow and
 * the solid (hypoplastic) regime, as pure functions of the cell's state
 * and rates: one set of rules for the 1D step (regime.c) and the 2D
 * solver (twod/solver2d.c), thresholds in [hypo] (scenario.h,
 * docs/model/solid.md).
 *
 * The rates are those of plane strain: exx, ezz and the shear rate
 * gamma = |du/dz + dw/dx|; the slab has exx = 0, ezz = w', gamma = |u'|.
 *
 *   flow -> solid  phi > phi_co + phi_margin (or, loose, resting on a solid
 *                  cell with phi >= phi_loose), T < T_ratio Y, and the cell
 *                  compresses (tr < 0, gamma / sqrt2 <= -tr) or rests
 *                  (every rate <= rest_rate); resting but not compressing
 *                  and not loose, while the rates grow, only if its flow
 *                  stress lies inside the limit surface (f_Y < -10
 *                  yield_tol): a cell that has just failed under a growing
 *                  load flows quasi-statically at tiny growing rates;
 *                  turned solid it would fail again at once.
 *   solid -> flow  an empty cell; a loose cell once unloaded (sigma_zz >= 0)
 *                  or without a solid cell below; else on the limit surface
 *                  (f_Y >= -yield_tol), the rate not compression-dominated,
 *                  and the solid's stress within jump_tol (relative) of the
 *                  flow stress at the quasi-static T of the current rates.
 */
#ifndef EKM_SWITCHING_H
#define EKM_SWITCHING_H

#include "model.h"

/* Solid (hypoplastic) regime and its switching thresholds ([hypo]): read by the scenario
 * service (scenario.h), used by the rules below and the solvers. */
typedef struct {
    int enabled;                 /* 0: flow regimes only (the EKM alone) */
    double T_ratio;              /* flow -> solid when T < T_ratio * Y (P_K/P_Y < T_ratio) [-] */
    double phi_margin;           /* flow -> solid only when phi > phi_co + phi_margin [-] */
    double phi_loose;            /* a loose cell (phi <= phi_co + phi_margin) on a solid one turns
                                  * solid (elastic) only when phi >= phi_loose [-] */
    double rest_rate;            /* flow -> solid only when w' <= rest_rate (compressing or at rest) [1/s] */
    double yield_tol;            /* solid -> flow when f_Y >= -yield_tol and the rate is not
                                  * compression-dominated [-] */
    double jump_tol;             /* ... and when the stress differs from the flow stress of the
                                  * current rates by at most jump_tol (relative) [-] */
    double phi_fixed;            /* 0: the rate law's density-dependent constants (P_Y, R, f, a1,
                                  * a2) and its limit surface at the cell's phi; > 0: at this phi
                                  * instead (thesis 6.2.2, "material constants independent of the
                                  * density": an element test of the law) [-] */
    int log;                     /* 1: one line per switch on stderr */
    int carry_over;              /* 1 (always, not a scenario key): the stress (flow -> solid) and T
                                  * (solid -> flow) carry over and solid -> flow waits for the
                                  * jump_tol match; 0 only for tests that show a real stress jump is
                                  * detected: the solid starts at -P_Y (isotropic), T stays frozen,
                                  * no jump_tol gate */
    int initial_solid;           /* [initial] solid: material cells start solid */
    double initial_stress_ratio; /* [initial] stress_ratio: their stress is -ratio P_Y (isotropic) [-] */
    int initial_settled;         /* [initial] settled: instead, phi and stress of a layer at rest
                                  * under the initial gravity, at yield pressure (state.c) */
} ekm_hypo_params;

/* What the rules read of a cell's rates. */
typedef struct {
    int compress; /* tr < 0 and gamma / sqrt 2 <= -tr */
    int at_rest;  /* |exx|, |ezz|, gamma <= rest_rate */
    double rate;  /* sqrt(exx^2 + ezz^2 + gamma^2) [1/s] */
} ekm_switch_rates;

ekm_switch_rates ekm_switch_rates_of(const ekm_hypo_params *h, double exx, double ezz, double gamma);

/* A cell without a limit surface: P_Y <= 0 or phi <= phi_co + phi_margin. */
int ekm_switch_loose(const ekm_material *m, const ekm_hypo_params *h, double phi);

/* The yield temperature the rules compare T with: the cell's own, or for
 * a loose cell that of the solid cell below it (0: none below). */
double ekm_switch_yield_temperature(const ekm_material *m, int loose, double phi, int below_solid,
                                    double phi_below);

typedef enum {
    EKM_SWITCH_STAY = 0, /* no switch */
    EKM_SWITCH_GO = 1,   /* switch */
    EKM_SWITCH_CHECK = 2 /* switch if the caller's stress test passes (ekm_switch_*_passes) */
} ekm_switch_verdict;

/* solid -> flow of a solid cell with f_Y (NAN when loose) and sigma_zz
 * [Pa]; CHECK: the flow-stress jump decides (ekm_switch_jump_passes). */
ekm_switch_verdict ekm_switch_to_flow(const ekm_hypo_params *h, int wet, int loose, double Y, double szz,
                                      double fY, const ekm_switch_rates *r);

/* The jump max|flow stress - solid stress| / max(|sigma_zz|, |sigma_xz|) allows the switch. */
int ekm_switch_jump_passes(const ekm_hypo_params *h, double jump);

/* flow -> solid of a flowing cell with T [m^2/s^2] and the rate of the
 * previous step [1/s]; CHECK: only if its flow stress is inside the limit
 * surface (ekm_switch_inside_passes). */
ekm_switch_verdict ekm_switch_to_solid(const ekm_hypo_params *h, int wet, int loose, double Y, double T,
                                       double phi, const ekm_switch_rates *r, double rate_before);

/* f_Y of the flow stress lets a resting cell with growing rates turn solid. */
int ekm_switch_inside_passes(const ekm_hypo_params *h, double fY);

/* The T [m^2/s^2] a cell takes when it turns to flow: T_qs, the
 * quasi-static T of its rates; for a loose cell the T whose flow stress is
 * its solid sigma_zz (ezz [1/s], szz [Pa]) when there is one; >= T_floor. */
double ekm_switch_flow_temperature(const ekm_material *m, ekm_variant variant, int loose, double phi,
                                   double ezz, double szz, double T_qs, double T_floor);

#endif
