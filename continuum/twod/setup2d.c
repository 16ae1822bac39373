/* setup2d.c: the semi-implicit 2D stepper's life cycle (step2d.h):
 * its grid, work arrays (step2d_impl.h), PETSc vectors, matrices and
 * linear solvers, and its initial state (the scenario's, or a 1D state
 * in every column, solid regime included). */
#include "step2d_impl.h"

#include <stdlib.h>
#include <string.h>

/* The initial state: the scenario's (state.h) or init, in every column;
 * a free or inflow end's face takes its column's 1D value too. */
static ekm_status initial_state(ekm2d_step *st, const ekm_state *init, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    ekm_state *s1 = NULL;
    if (!init) {
        s1 = ekm_state_alloc(g->nz, st->sc->length);
        if (!s1)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D initial state)");
        ekm_state_init(s1, st->sc);
        init = s1;
    }
    PetscScalar ***u;
    PetscErrorCode pe = DMStagVecGetArray(g->dm, st->Ul, &u);
    if (!pe) {
        for (PetscInt j = g->gz0; j < g->gz0 + g->gnz; j++)
            for (PetscInt i = g->gx0; i < g->gx0 + g->gnx; i++) {
                PetscScalar *v = u[j][i];
                if (j < g->nz) {
                    v[g->s_phi] = init->phi[j];
                    v[g->s_T] = init->T[j];
                    v[g->s_vx] = ekm2d_side_face(g, i) ? 0.0 : init->u[j];
                }
                if (j <= g->nz)
                    v[g->s_vz] = init->w[j];
                if (g->s_sxz >= 0 && j <= g->nz) { /* the solid regime's state */
                    v[g->s_sxz] = init->sxz[j];
                    if (j < g->nz) {
                        v[g->s_sxx] = init->sxx[j];
                        v[g->s_syy] = init->syy[j];
                        v[g->s_szz] = init->szz[j];
                        v[g->s_solid] = init->solid[j];
                        v[g->s_rate] = init->rate_prev[j];
                    }
                }
            }
        pe = DMStagVecRestoreArray(g->dm, st->Ul, &u);
    }
    if (!pe)
        pe = DMLocalToGlobal(g->dm, st->Ul, INSERT_VALUES, st->U);
    ekm_state_free(s1);
    if (pe)
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error setting the initial state");
    return EKM_OK;
}

/* A system's linear solver (options prefix ekm_v_ or ekm_t_; any
 * -ekm_v_ksp_* / -ekm_v_pc_* option overrides it).  The velocity system:
 * from EKM2D_AMG_CELLS (16384) cells GMRES with hypre's BoomerAMG (strong
 * threshold 0.7: the viscosities jump by decades from cell to cell), set
 * up anew for every solve, to rtol 1e-12 (a PETSc without hypre: as
 * below); below, on one rank LU as
 * GMRES's preconditioner, kept across steps while it converges in few
 * iterations (ekm2d_kept_solve), on several ranks GMRES with block Jacobi
 * (ILU) to 1e-12 (BoomerAMG's setup per solve costs more there: the 9 x
 * 30 filling on 2 ranks 54 s against 16 s).  Measured on one core (docs/model/twod.md "Linear solvers in
 * 2D", a dense layer settling, 10 steps): the velocity solves of 32 x 32
 * cells 0.054 s with LU against 0.100 s with BoomerAMG, of 64 x 64 0.40
 * against 0.28 s, of 256 x 256 39 against 9.5 s (equal fields to 4e-15);
 * the 18 x 60 filling 2.2 against 3.7 s; in a run, where the LU is kept
 * across steps, the 112 x 56 pile to t = 0.3 s 125 against 254 s
 * (2026-12-07).  No parallel LU (MUMPS or a
 * redundant LU: 115 ms against 8 ms per solve measured earlier).
 * The temperature system: on one rank an exact LU per Newton iteration
 * (its cells' T span twenty decades, and a Krylov tolerance relative to
 * the whole residual would leave a cold bed cell's update to round-off of
 * the hot stream's; a kept factorisation measured 8 % less time in the
 * solves on the 18 x 60 filling, 2026-12-06: not worth that); on several
 * ranks GMRES with block Jacobi (ILU) to 1e-12. */
static ekm_status set_up_ksp(KSP ksp, Mat A, const char *prefix, int velocity, long cells, MPI_Comm comm,
                             ekm_error *err)
{
    PC pc;
    int size = 1;
    MPI_Comm_size(comm, &size);
    PTRY(KSPSetOperators(ksp, A, A), "KSPSetOperators");
    PTRY(KSPSetOptionsPrefix(ksp, prefix), "KSPSetOptionsPrefix");
    PTRY(KSPGetPC(ksp, &pc), "KSPGetPC");
    PetscBool hypre = PETSC_FALSE, given = PETSC_TRUE;
    char name[64];
    snprintf(name, sizeof name, "-%spc_hypre_boomeramg_strong_threshold", prefix);
    PTRY(PetscHasExternalPackage("hypre", &hypre), "PetscHasExternalPackage");
    if (velocity && cells >= EKM2D_AMG_CELLS && hypre) {
        /* the strong threshold goes through the options database (PCHYPRE
         * has no setter for it): set for this KSPSetFromOptions only, unless
         * the user gave it */
        PTRY(PetscOptionsHasName(NULL, NULL, name, &given), "PetscOptionsHasName");
        if (!given)
            PTRY(PetscOptionsSetValue(NULL, name, "0.7"), "PetscOptionsSetValue");
        PTRY(KSPSetType(ksp, KSPGMRES), "KSPSetType");
        PTRY(PCSetType(pc, PCHYPRE), "PCSetType");
        PTRY(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
        PTRY(KSPSetTolerances(ksp, 1e-12, 1e-300, PETSC_DEFAULT, 500), "KSPSetTolerances");
    } else if (velocity && size == 1) {
        PTRY(KSPSetType(ksp, KSPGMRES), "KSPSetType");
        PTRY(PCSetType(pc, PCLU), "PCSetType");
        PTRY(KSPSetTolerances(ksp, 1e-13, 1e-300, PETSC_DEFAULT, 30), "KSPSetTolerances");
    } else if (size == 1) {
        PTRY(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
        PTRY(PCSetType(pc, PCLU), "PCSetType");
    } else {
        PTRY(KSPSetType(ksp, KSPGMRES), "KSPSetType");
        PTRY(PCSetType(pc, PCBJACOBI), "PCSetType");
        PTRY(KSPSetTolerances(ksp, 1e-12, 1e-50, PETSC_DEFAULT, 1000), "KSPSetTolerances");
    }
    PTRY(KSPSetErrorIfNotConverged(ksp, PETSC_FALSE), "KSPSetErrorIfNotConverged");
    PTRY(KSPSetFromOptions(ksp), "KSPSetFromOptions");
    if (!given)
        PTRY(PetscOptionsClearValue(NULL, name), "PetscOptionsClearValue");
    return EKM_OK;
}

PetscErrorCode ekm2d_kept_solve(KSP ksp, int *keep, long *refactors, Vec b, Vec x, KSPConvergedReason *why)
{
    KSPType type;
    PC pc;
    PetscBool lu = PETSC_FALSE;
    PetscCall(KSPGetType(ksp, &type));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCLU, &lu));
    const int kept = strcmp(type, KSPPREONLY) != 0 && lu && *keep;
    PetscCall(KSPSetReusePreconditioner(ksp, kept ? PETSC_TRUE : PETSC_FALSE));
    PetscCall(KSPSolve(ksp, b, x));
    PetscCall(KSPGetConvergedReason(ksp, why));
    if (*why < 0 && kept) {
        PetscCall(KSPSetReusePreconditioner(ksp, PETSC_FALSE));
        PetscCall(KSPSolve(ksp, b, x));
        PetscCall(KSPGetConvergedReason(ksp, why));
        ++*refactors;
    }
    PetscInt its = 0;
    PetscCall(KSPGetIterationNumber(ksp, &its));
    *keep = its <= EKM2D_REFACTOR_ITS;
    return 0;
}

ekm_status ekm2d_step_create(const ekm_scenario *sc, MPI_Comm comm, const ekm_state *init, ekm2d_step **out,
                             ekm_error *err)
{
    *out = NULL;
    ekm_status rc = ekm2d_step_supported(sc, err);
    if (rc != EKM_OK)
        return rc;
    ekm2d_step *st = calloc(1, sizeof *st);
    if (!st)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D step)");
    st->sc = sc;
    st->dt_solid = st->dt_solid_floor = INFINITY;
    rc = ekm2d_grid_create(sc, comm, &st->g, err);
    if (rc != EKM_OK) {
        free(st);
        return rc;
    }
    *out = st;
    const ekm2d_grid *g = &st->g;
    const size_t n = ekm2d_grid_box_size(g);
    st->Fx = calloc(n, sizeof(double));
    st->Fz = calloc(n, sizeof(double));
    st->phi_new = calloc(n, sizeof(double));
    st->rhoT = calloc(n, sizeof(double));
    st->T_star = calloc(n, sizeof(double));
    st->prop = calloc(n, sizeof *st->prop);
    st->dry = calloc(n, 1);
    st->K = calloc(n, sizeof(double));
    st->fill = calloc(n, sizeof(double));
    st->rhs_x = calloc(n, sizeof(double));
    st->rhs_z = calloc(n, sizeof(double));
    st->pu_x = calloc(n, sizeof(double));
    st->pu_z = calloc(n, sizeof(double));
    st->T_it = calloc(n, sizeof(double));
    st->T_lin = calloc(n, sizeof(double));
    st->T_change = calloc(n, sizeof(double));
    st->upd = calloc(n, sizeof(double));
    st->src = calloc(n, sizeof *st->src);
    st->eta_c = calloc(n, sizeof(double));
    st->eta_c_stamp = calloc(n, sizeof(long));
    int solid_ok = 1;
    if (sc->hypo.enabled) {
        st->solid = calloc(n, 1);
        st->solid_c = calloc(n, 1);
        st->rate_old = calloc(n, sizeof *st->rate_old);
        st->rate_c_old = calloc(n, sizeof *st->rate_c_old);
        st->hyp = calloc(n, sizeof *st->hyp);
        st->hyp_c = calloc(n, sizeof *st->hyp_c);
        st->t0_c = calloc(n, sizeof(double));
        st->T_keep = calloc(n, sizeof(double));
        st->eta_new = calloc(n, sizeof(double));
        st->sxz_c = calloc(n, sizeof(double));
        solid_ok = st->solid && st->solid_c && st->rate_old && st->rate_c_old && st->hyp && st->hyp_c &&
                   st->t0_c && st->T_keep && st->eta_new && st->sxz_c;
    }
    if (!solid_ok || !st->eta_c || !st->eta_c_stamp || !st->Fx || !st->Fz || !st->phi_new || !st->rhoT ||
        !st->T_star || !st->prop || !st->dry || !st->K || !st->fill || !st->rhs_x || !st->rhs_z ||
        !st->pu_x || !st->pu_z || !st->T_it || !st->T_lin || !st->T_change || !st->upd || !st->src) {
        ekm2d_step_destroy(st);
        *out = NULL;
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D step, %d x %d cells)", g->nx, g->nz);
    }
    for (size_t k = 0; k < n; k++)
        st->fill[k] = 1.0; /* no surface cell until phase 4 says so (surface2d.c) */
    PetscErrorCode pe = DMCreateGlobalVector(g->dm, &st->U);
    pe = pe ? pe : VecDuplicate(st->U, &st->U_back);
    pe = pe ? pe : DMCreateLocalVector(g->dm, &st->Ul);
    pe = pe ? pe : VecDuplicate(st->U, &st->W);
    pe = pe ? pe : VecDuplicate(st->Ul, &st->Wl);
    pe = pe ? pe : DMCreateMatrix(g->dmv, &st->A);
    pe = pe ? pe : DMCreateGlobalVector(g->dmv, &st->V);
    pe = pe ? pe : VecDuplicate(st->V, &st->Vb);
    pe = pe ? pe : DMCreateLocalVector(g->dmv, &st->Vl);
    pe = pe ? pe : KSPCreate(comm, &st->ksp_v);
    pe = pe ? pe : DMCreateMatrix(g->dmt, &st->J);
    pe = pe ? pe : DMCreateGlobalVector(g->dmt, &st->dT);
    pe = pe ? pe : VecDuplicate(st->dT, &st->R);
    pe = pe ? pe : VecDuplicate(st->dT, &st->Tn);
    pe = pe ? pe : DMCreateLocalVector(g->dmt, &st->Tl);
    pe = pe ? pe : VecDuplicate(st->Tl, &st->Rl);
    pe = pe ? pe : KSPCreate(comm, &st->ksp_t);
    pe = pe ? pe : MatSetOption(st->A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE);
    pe = pe ? pe : MatSetOption(st->J, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE);
    if (pe) {
        ekm2d_step_destroy(st);
        *out = NULL;
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error creating the vectors and matrices");
    }
    const long cells = (long)g->nx * g->nz;
    rc = set_up_ksp(st->ksp_v, st->A, "ekm_v_", 1, cells, comm, err);
    if (rc == EKM_OK)
        rc = set_up_ksp(st->ksp_t, st->J, "ekm_t_", 0, cells, comm, err);
    PetscClassId cls;
    if (rc == EKM_OK && (PetscClassIdRegister("ekm2d step", &cls) ||
                         PetscLogEventRegister("ekm2dExplicit", cls, &st->ev_explicit) ||
                         PetscLogEventRegister("ekm2dVelAssemble", cls, &st->ev_v_asm) ||
                         PetscLogEventRegister("ekm2dVelSolve", cls, &st->ev_v_solve) ||
                         PetscLogEventRegister("ekm2dTemperature", cls, &st->ev_temp) ||
                         PetscLogEventRegister("ekm2dRegimes", cls, &st->ev_regime)))
        rc = EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error registering its log events");
    PetscBool monitor = PETSC_FALSE;
    if (rc == EKM_OK && PetscOptionsGetBool(NULL, NULL, "-ekm_step_monitor", &monitor, NULL))
        rc = EKM_FAIL(err, EKM_EINPUT, "-ekm_step_monitor: expected a boolean (or nothing)");
    st->monitor = monitor == PETSC_TRUE;
    if (rc == EKM_OK)
        rc = initial_state(st, init, err);
    if (rc != EKM_OK) {
        ekm2d_step_destroy(st);
        *out = NULL;
    }
    return rc;
}

void ekm2d_step_destroy(ekm2d_step *st)
{
    if (!st)
        return;
    KSPDestroy(&st->ksp_v);
    KSPDestroy(&st->ksp_t);
    MatDestroy(&st->A);
    MatDestroy(&st->J);
    VecDestroy(&st->U);
    VecDestroy(&st->U_back);
    VecDestroy(&st->Ul);
    VecDestroy(&st->W);
    VecDestroy(&st->Wl);
    VecDestroy(&st->V);
    VecDestroy(&st->Vb);
    VecDestroy(&st->Vl);
    VecDestroy(&st->dT);
    VecDestroy(&st->R);
    VecDestroy(&st->Tn);
    VecDestroy(&st->Tl);
    VecDestroy(&st->Rl);
    free(st->Fx);
    free(st->Fz);
    free(st->phi_new);
    free(st->fill);
    free(st->rhoT);
    free(st->T_star);
    free(st->prop);
    free(st->dry);
    free(st->K);
    free(st->rhs_x);
    free(st->rhs_z);
    free(st->pu_x);
    free(st->pu_z);
    free(st->T_it);
    free(st->T_lin);
    free(st->T_change);
    free(st->upd);
    free(st->src);
    free(st->eta_c);
    free(st->eta_c_stamp);
    free(st->solid);
    free(st->solid_c);
    free(st->rate_old);
    free(st->rate_c_old);
    free(st->hyp);
    free(st->hyp_c);
    free(st->t0_c);
    free(st->T_keep);
    free(st->eta_new);
    free(st->sxz_c);
    ekm2d_grid_destroy(&st->g);
    free(st);
}
