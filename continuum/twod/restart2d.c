/* restart2d.c: the stepper's state gathered into an order that does not
 * depend on the ranks, and set back from it (step2d.h: ekm2d_restart).
 *
 * Each rank packs its owned elements (DMStagGetCorners, the extra column
 * and row at the right and top boundary included) with their dof entries
 * and the cell's temperature change; rank 0 gathers the boxes and places
 * them by their global (i, j).  Loading is the reverse: rank 0 broadcasts
 * the whole array and each rank takes its own elements.  The arrays are
 * of the state's size (a 1000 x 1000 grid with the solid regime: about 150
 * MB), as the output's gathered frames are. */
#include "step2d_impl.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

/* This rank's owned elements: i0 .. i0 + ni - 1, j0 .. j0 + nj - 1. */
typedef struct {
    PetscInt i0, j0, ni, nj;
} owned_box;

static PetscErrorCode owned(DM dm, owned_box *b)
{
    PetscInt ex, ez;
    PetscCall(DMStagGetCorners(dm, &b->i0, &b->j0, NULL, &b->ni, &b->nj, NULL, &ex, &ez, NULL));
    b->ni += ex;
    b->nj += ez;
    return 0;
}

void ekm2d_restart_free(ekm2d_restart *r)
{
    if (!r)
        return;
    free(r->values);
    r->values = NULL;
}

/* Pack this rank's elements of u (dm's local array) into buf. */
static void pack(const ekm2d_step *st, PetscScalar ***u, const owned_box *b, int dof, double *buf)
{
    const ekm2d_grid *g = &st->g;
    size_t n = 0;
    for (PetscInt j = b->j0; j < b->j0 + b->nj; j++)
        for (PetscInt i = b->i0; i < b->i0 + b->ni; i++) {
            for (int k = 0; k < dof; k++)
                buf[n++] = u[j][i][k];
            buf[n++] = i < g->nx && j < g->nz ? BOX(st, T_change, i, j) : 0.0;
        }
}

ekm_status ekm2d_step_save(ekm2d_step *st, ekm2d_restart *out, ekm_error *err)
{
    const ekm2d_grid *g = &st->g;
    int rank = 0, size = 1;
    MPI_Comm_rank(g->comm, &rank);
    MPI_Comm_size(g->comm, &size);
    PetscInt dof = 0;
    owned_box b;
    PTRY(DMStagGetEntriesPerElement(g->dm, &dof), "DMStagGetEntriesPerElement");
    PTRY(owned(g->dm, &b), "DMStagGetCorners");
    long sw[2] = {st->to_solid, st->to_flow}, sw_all[2] = {0, 0};
    MPI_Reduce(sw, sw_all, 2, MPI_LONG, MPI_SUM, 0, g->comm);
    *out = (ekm2d_restart){.nx = g->nx,
                           .nz = g->nz,
                           .dof = (int)dof,
                           .t = st->t,
                           .dz = g->dz,
                           .dt_prev = st->dt_prev,
                           .dt_solid = st->dt_solid,
                           .dt_change = st->dt_change,
                           .mass_in = st->mass_in,
                           .solid_lag_max = st->solid_lag_max,
                           .steps = st->steps,
                           .rejected = st->rejected,
                           .newton_total = st->newton_total,
                           .to_solid = sw_all[0],
                           .to_flow = sw_all[1],
                           .solid_floor_steps = st->solid_floor_steps};
    const int per = (int)dof + 1;
    const size_t mine = (size_t)b.ni * (size_t)b.nj * (size_t)per;
    const size_t total = (size_t)(g->nx + 1) * (size_t)(g->nz + 1) * (size_t)per;
    if (total > (size_t)INT_MAX)
        return EKM_FAIL(err, EKM_EINPUT, "2D checkpoint: %d x %d cells are too many to gather on one rank",
                        g->nx, g->nz);
    double *buf = malloc((mine ? mine : 1) * sizeof *buf);
    int *boxes = rank == 0 ? malloc((size_t)size * 4 * sizeof *boxes) : NULL;
    int *counts = rank == 0 ? malloc((size_t)size * 2 * sizeof *counts) : NULL;
    double *all = rank == 0 ? malloc(total * sizeof *all) : NULL;
    out->values = rank == 0 ? calloc(total, sizeof *out->values) : NULL;
    int ok = buf && (rank != 0 || (boxes && counts && all && out->values)), ok_all = 0;
    MPI_Allreduce(&ok, &ok_all, 1, MPI_INT, MPI_MIN, g->comm);
    ekm_status rc = EKM_OK;
    if (!ok_all)
        rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D checkpoint, %d x %d cells)", g->nx, g->nz);
    PetscScalar ***u = NULL;
    if (rc == EKM_OK &&
        (DMGlobalToLocal(g->dm, st->U, INSERT_VALUES, st->Wl) || DMStagVecGetArray(g->dm, st->Wl, &u)))
        rc = EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error in DMStagVecGetArray (checkpoint)");
    if (rc == EKM_OK) {
        pack(st, u, &b, (int)dof, buf);
        DMStagVecRestoreArray(g->dm, st->Wl, &u);
        const int box[4] = {(int)b.i0, (int)b.j0, (int)b.ni, (int)b.nj};
        MPI_Gather(box, 4, MPI_INT, boxes, 4, MPI_INT, 0, g->comm);
        int *displs = counts ? counts + size : NULL;
        if (rank == 0)
            for (int r = 0, at = 0; r < size; r++) {
                counts[r] = boxes[4 * r + 2] * boxes[4 * r + 3] * per;
                displs[r] = at;
                at += counts[r];
            }
        MPI_Gatherv(buf, (int)mine, MPI_DOUBLE, all, counts, displs, MPI_DOUBLE, 0, g->comm);
        if (rank == 0) /* each rank's box to its place */
            for (int r = 0; r < size; r++) {
                const double *src = all + displs[r];
                for (int j = boxes[4 * r + 1]; j < boxes[4 * r + 1] + boxes[4 * r + 3]; j++)
                    for (int i = boxes[4 * r]; i < boxes[4 * r] + boxes[4 * r + 2]; i++, src += per)
                        memcpy(out->values + ((size_t)j * (size_t)(g->nx + 1) + (size_t)i) * (size_t)per, src,
                               (size_t)per * sizeof *src);
            }
    }
    free(buf);
    free(boxes);
    free(counts);
    free(all);
    if (rc != EKM_OK)
        ekm2d_restart_free(out);
    return rc;
}

ekm_status ekm2d_step_load(ekm2d_step *st, const ekm2d_restart *in, ekm_error *err)
{
    ekm2d_grid *g = &st->g;
    int rank = 0;
    MPI_Comm_rank(g->comm, &rank);
    PetscInt dof = 0;
    owned_box b;
    PTRY(DMStagGetEntriesPerElement(g->dm, &dof), "DMStagGetEntriesPerElement");
    PTRY(owned(g->dm, &b), "DMStagGetCorners");
    if (in->nx != g->nx || in->nz != g->nz || in->dof != (int)dof)
        return EKM_FAIL(err, EKM_EINPUT,
                        "2D checkpoint: %d x %d cells with %d entries each, expected %d x %d with %d", in->nx,
                        in->nz, in->dof, g->nx, g->nz, (int)dof);
    const int per = (int)dof + 1;
    const size_t total = (size_t)(g->nx + 1) * (size_t)(g->nz + 1) * (size_t)per;
    if (total > (size_t)INT_MAX)
        return EKM_FAIL(err, EKM_EINPUT, "2D checkpoint: %d x %d cells are too many to scatter from one rank",
                        g->nx, g->nz);
    double *all = rank == 0 ? in->values : malloc(total * sizeof *all);
    int ok = all != NULL, ok_all = 0;
    MPI_Allreduce(&ok, &ok_all, 1, MPI_INT, MPI_MIN, g->comm);
    if (!ok_all) {
        if (rank != 0)
            free(all);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D checkpoint, %d x %d cells)", g->nx, g->nz);
    }
    MPI_Bcast(all, (int)total, MPI_DOUBLE, 0, g->comm);
    PetscScalar ***u = NULL;
    PetscErrorCode pe = VecSet(st->Wl, 0.0);
    pe = pe ? pe : DMStagVecGetArray(g->dm, st->Wl, &u);
    if (!pe) {
        for (PetscInt j = b.j0; j < b.j0 + b.nj; j++)
            for (PetscInt i = b.i0; i < b.i0 + b.ni; i++) {
                const double *src = all + ((size_t)j * (size_t)(g->nx + 1) + (size_t)i) * (size_t)per;
                for (PetscInt k = 0; k < dof; k++)
                    u[j][i][k] = src[k];
                if (i < g->nx && j < g->nz)
                    BOX(st, T_change, i, j) = src[dof];
            }
        pe = DMStagVecRestoreArray(g->dm, st->Wl, &u);
    }
    pe = pe ? pe : DMLocalToGlobal(g->dm, st->Wl, INSERT_VALUES, st->U);
    if (rank != 0)
        free(all);
    if (pe)
        return EKM_FAIL(err, EKM_EINTERNAL, "2D step: PETSc error setting the state from a checkpoint");
    st->t = in->t;
    g->dz = in->dz;
    st->dz_start = st->dz_new = in->dz;
    st->dt_prev = in->dt_prev;
    st->dt_solid = in->dt_solid;
    st->dt_change = in->dt_change;
    st->mass_in = in->mass_in;
    st->solid_lag_max = in->solid_lag_max;
    st->steps = in->steps;
    st->rejected = in->rejected;
    st->newton_total = in->newton_total;
    st->to_solid = rank == 0 ? in->to_solid : 0;
    st->to_flow = rank == 0 ? in->to_flow : 0;
    st->solid_floor_steps = in->solid_floor_steps;
    st->v_keep_factor = 0;
    st->t_keep_factor = 0;
    return EKM_OK;
}
