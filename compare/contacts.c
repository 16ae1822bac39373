/* contacts.c: contacts from pair dumps (see contacts.h). */
#include "contacts.h"

#include <math.h>
#include <stdlib.h>

void cg_contacts_close(cg_contacts *c)
{
    cg_dump_close(c->pd);
    c->pd = NULL;
    cg_snapshot_free(&c->psnap);
    free(c->cs);
    free(c->cs2);
    free(c->cb);
    free(c->cf);
    free(c->ids);
    c->cs = c->cs2 = c->cb = c->cf = c->ids = NULL;
    c->ccap = c->idcap = 0;
}

static int cmp_id(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Index of the atom with this id (binary search in c->ids over n atoms), or -1. */
static long find_id(const cg_contacts *c, size_t n, double id)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        double v = c->ids[2 * mid];
        if (v == id)
            return (long)c->ids[2 * mid + 1];
        if (v < id)
            lo = mid + 1;
        else
            hi = mid;
    }
    return -1;
}

/* Minimum image of a branch vector in the (possibly triclinic) box: a
 * contact is never longer than half the box (LIGGGHTS writes the owned,
 * wrapped position of a partner across a periodic boundary). */
static void min_image(const cg_snapshot *sn, double b[3])
{
    double L[3];
    for (int d = 0; d < 3; d++)
        L[d] = sn->hi[d] - sn->lo[d];
    if (sn->periodic[2]) {
        double n = nearbyint(b[2] / L[2]);
        b[0] -= n * sn->tilt[1];
        b[1] -= n * sn->tilt[2];
        b[2] -= n * L[2];
    }
    if (sn->periodic[1]) {
        double n = nearbyint(b[1] / L[1]);
        b[0] -= n * sn->tilt[0];
        b[1] -= n * L[1];
    }
    if (sn->periodic[0])
        b[0] -= L[0] * nearbyint(b[0] / L[0]);
}

ekm_status cg_contacts_match(cg_contacts *c, const cg_run_opts *o, const cg_snapshot *sn, int id_col,
                             const int pos_col[3], cg_particles *pt, ekm_error *err)
{
    ekm_status rc;
    for (;;) {
        if (!c->have_pair) {
            if (!c->pd) {
                if (c->ipair >= o->npairs)
                    return EKM_FAIL(err, EKM_EINPUT,
                                    "%s: no pair-dump snapshot for step %lld (the pair dumps end before)",
                                    sn->where, (long long)sn->step);
                if ((rc = cg_dump_open(&c->pd, o->pairs[c->ipair++], o->paircols, o->npaircols, err)))
                    return rc;
                if (o->npaircols == 5) /* id1 id2 fx fy fz: the atom ids are integers */
                    for (size_t j = 0; j < 2; j++)
                        cg_dump_expect(c->pd, j, CG_DUMP_INTEGER);
            }
            rc = cg_dump_next(c->pd, &c->psnap, err);
            if (rc == EKM_EOF) {
                if (cg_dump_truncated(c->pd) && o->log)
                    fprintf(o->log, "warning: %s\n", cg_dump_warning(c->pd));
                cg_dump_close(c->pd);
                c->pd = NULL;
                continue;
            }
            if (rc)
                return rc;
            c->have_pair = 1;
        }
        if (c->psnap.step < sn->step) {
            c->have_pair = 0;
            continue;
        }
        if (c->psnap.step > sn->step)
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: no pair-dump snapshot for step %lld (the next one is step %lld)", sn->where,
                            (long long)sn->step, (long long)c->psnap.step);
        break;
    }
    c->have_pair = 0;
    const cg_snapshot *ps = &c->psnap;
    for (size_t j = 0; j < o->npaircols; j++)
        if (!ps->present[j])
            return EKM_FAIL(err, EKM_EINPUT, "%s: ITEM: ENTRIES has no column '%s' (--pair-columns)",
                            ps->where, o->paircols[j]);
    size_t nc = (size_t)ps->natoms, w = ps->nsel;
    if (nc > c->ccap) {
        double *a = realloc(c->cs, nc * sizeof *a);
        if (a)
            c->cs = a;
        double *b = realloc(c->cb, 3 * nc * sizeof *b);
        if (b)
            c->cb = b;
        double *f = realloc(c->cf, 3 * nc * sizeof *f);
        if (f)
            c->cf = f;
        double *a2 = o->axis2 >= 0 ? realloc(c->cs2, nc * sizeof *a2) : NULL;
        if (a2)
            c->cs2 = a2;
        if (!a || !b || !f || (o->axis2 >= 0 && !a2))
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory (%zu contacts)", nc);
        c->ccap = nc;
    }
    int ax = o->axis;
    if (o->npaircols == 9) {
        for (size_t k = 0; k < nc; k++) {
            const double *row = ps->data + k * w;
            for (int d = 0; d < 3; d++) {
                c->cb[3 * k + d] = row[d] - row[3 + d];
                c->cf[3 * k + d] = row[6 + d];
            }
            min_image(sn, c->cb + 3 * k);
            c->cs[k] = row[3 + ax];
            if (o->axis2 >= 0)
                c->cs2[k] = row[3 + o->axis2];
        }
    } else {
        size_t n = pt->n;
        if (n > c->idcap) {
            double *p = realloc(c->ids, 2 * n * sizeof *p);
            if (!p)
                return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
            c->ids = p;
            c->idcap = n;
        }
        const double *ad = sn->data;
        size_t aw = sn->nsel;
        for (size_t i = 0; i < n; i++) {
            c->ids[2 * i] = (ad + i * aw)[id_col];
            c->ids[2 * i + 1] = (double)i;
        }
        qsort(c->ids, n, 2 * sizeof(double), cmp_id);
        for (size_t k = 0; k < nc; k++) {
            const double *row = ps->data + k * w;
            long i = find_id(c, n, row[0]), j = find_id(c, n, row[1]);
            if (i < 0 || j < 0)
                return EKM_FAIL(err, EKM_EINPUT, "%s: entry %zu: no atom with id %.0f in %s", ps->where,
                                k + 1, i < 0 ? row[0] : row[1], sn->where);
            for (int d = 0; d < 3; d++) {
                c->cb[3 * k + d] = (ad + (size_t)i * aw)[pos_col[d]] - (ad + (size_t)j * aw)[pos_col[d]];
                c->cf[3 * k + d] = row[2 + d];
            }
            min_image(sn, c->cb + 3 * k);
            c->cs[k] = pt->s[j];
            if (o->axis2 >= 0)
                c->cs2[k] = (ad + (size_t)j * aw)[pos_col[o->axis2]];
        }
    }
    pt->nc = nc;
    pt->cs = c->cs;
    pt->cb = c->cb;
    pt->cf = c->cf;
    return EKM_OK;
}
