/* contacts.h: the contacts of a snapshot from pair dumps (`dump local` of
 * compute pair/gran/local or pair/local), matched to the atom snapshot by
 * step.
 *
 * The pair dumps are read in order alongside the atom dumps; pair
 * snapshots of steps the atom dumps do not select are skipped, a missing
 * step is an error. Each contact becomes, for the kernel line integral of
 * cg.h, the partner's coordinate along the profile axis, the branch vector
 * b = r_1 - r_2 (minimum image in the possibly triclinic box: LIGGGHTS
 * writes the partner's own wrapped position across a periodic boundary)
 * and the force on atom 1 by atom 2. Columns: 9 (x1 y1 z1 x2 y2 z2 fx fy
 * fz) or 5 (id1 id2 fx fy fz; positions from the atom snapshot).
 */
#ifndef CG_CONTACTS_H
#define CG_CONTACTS_H

#include <stddef.h>

#include "cg.h"
#include "cg_opts.h"
#include "dump.h"
#include "status.h"

typedef struct {
    size_t ipair;         /* next pair file to open */
    cg_dump *pd;          /* pair dump being read */
    cg_snapshot psnap;    /* pair snapshot */
    int have_pair;        /* psnap read but not used yet */
    size_t ccap;          /* contact capacity */
    double *cs, *cb, *cf; /* contacts: partner coordinate [m], branch [m], force [N] */
    double *cs2;          /* 2D (o->axis2 >= 0): partner coordinate along axis2 [m] */
    double *ids;          /* id-mode: (id, index) pairs sorted by id */
    size_t idcap;
} cg_contacts;

/* The pair snapshot with the atom snapshot sn's step, as contacts of pt
 * (pt->nc, cs, cb, cf point into c; with o->axis2 >= 0 also c->cs2, the
 * partner's coordinate along axis2). o: pair files and columns, the axis.
 * Id mode (5 columns): id_col and pos_col[3] are the columns of the atom
 * ids and of x, y, z in sn->data; pt->s and pt->n are the atoms'. */
ekm_status cg_contacts_match(cg_contacts *c, const cg_run_opts *o, const cg_snapshot *sn, int id_col,
                             const int pos_col[3], cg_particles *pt, ekm_error *err);

/* Close the pair dump and free the buffers (c itself is the caller's). */
void cg_contacts_close(cg_contacts *c);

#endif
