/* cg_input.c: dumps -> selected snapshots -> particles (see cg_input.h). */
#include "cg_input.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static const char *const base_cols[CG_IN_STRESS] = {"x",  "y",  "z",  "xu",   "yu",     "zu",
                                                    "xs", "ys", "zs", "xsu",  "ysu",    "zsu",
                                                    "vx", "vy", "vz", "mass", "radius", "diameter"};

void cg_input_close(cg_input *src)
{
    cg_dump_close(src->d);
    src->d = NULL;
    cg_snapshot_free(&src->snap);
    cg_contacts_close(&src->pairs);
    free(src->s);
    free(src->v);
    free(src->m);
    free(src->vol);
    free(src->rad);
    free(src->S);
    free(src->s2);
    src->s = src->v = src->m = src->vol = src->rad = src->S = src->s2 = NULL;
    src->cap = 0;
}

void cg_input_init(cg_input *src, const cg_run_opts *o)
{
    memset(src, 0, sizeof *src);
    src->o = o;
    /* only the position columns the axis needs are parsed: the axis
     * coordinate, and for scaled ones the later dimensions (triclinic) */
    int idmode = o->npaircols == 5;
    const char *want[CG_IN_NCOL];
    for (size_t j = 0; j < CG_IN_STRESS; j++) {
        int f = (int)j / 3, c = (int)j % 3;
        int need = j >= CG_IN_VX || c == o->axis || (f >= 2 && c > o->axis) || (idmode && f == 0) ||
                   c == o->axis2 || (f >= 2 && o->axis2 >= 0 && c > o->axis2);
        want[j] = need ? base_cols[j] : NULL;
    }
    for (size_t j = 0; j < 6; j++)
        want[CG_IN_STRESS + j] = j < o->nstress ? o->stress[j] : NULL;
    want[CG_IN_ID] = idmode ? "id" : NULL;
    want[CG_IN_TYPE] = o->ntypes ? "type" : NULL;
    /* only the needed columns are asked for: fewer conversions, and a
     * compact snapshot row */
    src->ncols = 0;
    for (size_t j = 0; j < CG_IN_NCOL; j++) {
        src->col[j] = want[j] ? (int)src->ncols : -1;
        if (want[j])
            src->cols[src->ncols++] = want[j];
    }
}

static ekm_status input_grow(cg_input *src, size_t n, ekm_error *err)
{
    if (n <= src->cap)
        return EKM_OK;
    size_t c = src->cap ? src->cap : 1024;
    while (c < n)
        c *= 2;
    double *p[6] = {realloc(src->s, c * sizeof(double)), NULL, NULL, NULL, NULL, NULL};
    if (p[0])
        src->s = p[0];
    p[1] = realloc(src->v, 3 * c * sizeof(double));
    if (p[1])
        src->v = p[1];
    p[2] = realloc(src->m, c * sizeof(double));
    if (p[2])
        src->m = p[2];
    p[3] = realloc(src->vol, c * sizeof(double));
    if (p[3])
        src->vol = p[3];
    p[4] = realloc(src->rad, c * sizeof(double));
    if (p[4])
        src->rad = p[4];
    p[5] = realloc(src->S, 6 * c * sizeof(double));
    if (p[5])
        src->S = p[5];
    for (int i = 0; i < 6; i++)
        if (!p[i])
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory (%zu atoms)", n);
    if (src->o->axis2 >= 0) {
        double *q = realloc(src->s2, c * sizeof(double));
        if (!q)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory (%zu atoms)", n);
        src->s2 = q;
    }
    src->cap = c;
    return EKM_OK;
}

static ekm_status missing(const cg_snapshot *s, const char *what, ekm_error *err)
{
    return EKM_FAIL(err, EKM_EINPUT, "%s: ITEM: ATOMS has no column %s", s->where, what);
}

/* Snapshot columns -> particle arrays. */
#define PR(c)      (src->col[c] >= 0 && pr[src->col[c]])
#define AT(row, c) ((row)[src->col[c]])

/* The position flavour (0 plain, 1 unwrapped, 2 scaled, 3 scaled
 * unwrapped) dumped for axis ax, checked; *flav_out. */
static ekm_status position_flavour(const cg_input *src, int ax, int *flav_out, ekm_error *err)
{
    const cg_snapshot *sn = &src->snap;
    const int *pr = sn->present;
    static const char axname[3] = {'x', 'y', 'z'};
    int flav = -1;
    for (int f = 0; f < 4; f++)
        if (PR(CG_IN_POS + 3 * f + ax)) {
            flav = f;
            break;
        }
    if (flav < 0) {
        char what[64];
        snprintf(what, sizeof what, "'%c' (nor %cu, %cs, %csu)", axname[ax], axname[ax], axname[ax],
                 axname[ax]);
        return missing(sn, what, err);
    }
    int scaled = flav >= 2;
    if (scaled && sn->triclinic && ax < 2)
        for (int c = ax; c < 3; c++)
            if (!PR(CG_IN_POS + 3 * flav + c))
                return missing(sn,
                               c == 1 ? "'ys' (scaled triclinic coordinates need all three)"
                                      : "'zs' (scaled triclinic coordinates need all three)",
                               err);
    *flav_out = flav;
    return EKM_OK;
}

/* Coordinate of an atom (row) along axis ax from flavour flav, wrapped
 * into the box when it is periodic along ax. */
static double axis_coord(const cg_input *src, const double *row, int flav, int ax, const double L[3])
{
    const cg_snapshot *sn = &src->snap;
    const int *pr = sn->present;
    double s;
    if (flav < 2) {
        s = AT(row, CG_IN_POS + 3 * flav + ax);
    } else {
        double q[3];
        for (int c = 0; c < 3; c++)
            q[c] = PR(CG_IN_POS + 3 * flav + c) ? AT(row, CG_IN_POS + 3 * flav + c) : 0.0;
        if (ax == 2)
            s = sn->lo[2] + q[2] * L[2];
        else if (ax == 1)
            s = sn->lo[1] + q[1] * L[1] + (sn->triclinic ? q[2] * sn->tilt[2] : 0.0);
        else
            s = sn->lo[0] + q[0] * L[0] + (sn->triclinic ? q[1] * sn->tilt[0] + q[2] * sn->tilt[1] : 0.0);
    }
    if (sn->periodic[ax]) {
        double lo = sn->lo[ax], hi = sn->hi[ax];
        s = lo + fmod(s - lo, L[ax]);
        if (s < lo)
            s += L[ax];
        if (s >= hi)
            s = lo;
    }
    return s;
}

static ekm_status input_convert(cg_input *src, ekm_error *err)
{
    const cg_run_opts *o = src->o;
    const cg_snapshot *sn = &src->snap;
    const int *pr = sn->present;
    int ax = o->axis, ax2 = o->axis2;
    int flav = -1, flav2 = -1;
    ekm_status prc = position_flavour(src, ax, &flav, err);
    if (!prc && ax2 >= 0)
        prc = position_flavour(src, ax2, &flav2, err);
    if (prc)
        return prc;
    for (int c = 0; c < 3; c++)
        if (!PR(CG_IN_VX + c))
            return missing(sn, c == 0 ? "'vx'" : c == 1 ? "'vy'" : "'vz'", err);
    if (o->npaircols == 5) {
        if (!PR(CG_IN_ID))
            return missing(sn, "'id' (pair dumps with atom ids)", err);
        for (int c = 0; c < 3; c++)
            if (!PR(CG_IN_POS + c))
                return missing(sn,
                               c == 0   ? "'x' (pair dumps with atom ids)"
                               : c == 1 ? "'y' (pair dumps with atom ids)"
                                        : "'z' (pair dumps with atom ids)",
                               err);
    }
    int has_mass = PR(CG_IN_MASS), has_rad = PR(CG_IN_RADIUS), has_diam = PR(CG_IN_DIAMETER);
    if (!has_mass && !(has_rad || has_diam))
        return missing(sn, "'mass', 'radius' or 'diameter'", err);
    if (!has_mass && !(o->rho_p > 0))
        return EKM_FAIL(err, EKM_EUSAGE,
                        "%s: ITEM: ATOMS has no column 'mass': give --rho-p (material density, kg/m^3)",
                        sn->where);
    if (!has_rad && !has_diam && !(o->rho_p > 0))
        return EKM_FAIL(err, EKM_EUSAGE,
                        "%s: ITEM: ATOMS has no column 'radius' or 'diameter' (needed for phi): "
                        "give --rho-p (material density, kg/m^3)",
                        sn->where);
    for (size_t j = 0; j < o->nstress; j++)
        if (!PR(CG_IN_STRESS + j)) {
            char what[96];
            snprintf(what, sizeof what, "'%s' (--stress)", o->stress[j]);
            return missing(sn, what, err);
        }
    if (o->ntypes && !PR(CG_IN_TYPE))
        return missing(sn, "'type' (--types)", err);
    size_t n = (size_t)sn->natoms;
    ekm_status rc = input_grow(src, n, err);
    if (rc)
        return rc;
    double L[3];
    for (int c = 0; c < 3; c++)
        L[c] = sn->hi[c] - sn->lo[c];
    src->lo = sn->lo[ax];
    src->hi = sn->hi[ax];
    src->periodic = sn->periodic[ax];
    if (ax2 >= 0) {
        src->lo2 = sn->lo[ax2];
        src->hi2 = sn->hi[ax2];
        src->periodic2 = sn->periodic[ax2];
        src->length_avg = L[3 - ax - ax2];
    }
    const size_t w = sn->nsel;
    for (size_t i = 0; i < n; i++) {
        const double *row = sn->data + i * w;
        src->s[i] = axis_coord(src, row, flav, ax, L);
        if (ax2 >= 0)
            src->s2[i] = axis_coord(src, row, flav2, ax2, L);
        for (int c = 0; c < 3; c++)
            src->v[3 * i + c] = AT(row, CG_IN_VX + c);
        double r = has_rad ? AT(row, CG_IN_RADIUS) : has_diam ? 0.5 * AT(row, CG_IN_DIAMETER) : -1.0;
        double m = has_mass ? AT(row, CG_IN_MASS) : 0.0;
        if (r >= 0.0) {
            if (!(r > 0.0))
                return EKM_FAIL(err, EKM_EINPUT, "%s: atom %zu: expected a positive radius, got %g",
                                sn->where, i + 1, r);
            src->vol[i] = 4.0 / 3.0 * PI * r * r * r;
            if (!has_mass)
                m = o->rho_p * src->vol[i];
        } else {
            if (!(m > 0.0))
                return EKM_FAIL(err, EKM_EINPUT, "%s: atom %zu: expected a positive mass, got %g", sn->where,
                                i + 1, m);
            src->vol[i] = m / o->rho_p;
            r = cbrt(src->vol[i] * 3.0 / (4.0 * PI));
        }
        if (!(m > 0.0))
            return EKM_FAIL(err, EKM_EINPUT, "%s: atom %zu: expected a positive mass, got %g", sn->where,
                            i + 1, m);
        /* an atom of a type not kept (--types: e.g. frozen wall grains)
         * stays in the arrays, so that pair dumps still find it by index, but
         * with zero mass, volume and stress it adds nothing to any field */
        int keep = 1;
        if (o->ntypes) {
            double ty = AT(row, CG_IN_TYPE);
            keep = 0;
            for (size_t k = 0; k < o->ntypes; k++)
                if (ty == (double)o->types[k])
                    keep = 1;
        }
        src->m[i] = keep ? m : 0.0;
        src->rad[i] = r;
        if (!keep)
            src->vol[i] = 0.0;
        if (keep) {
            src->dsum += 2.0 * r;
            src->dcount += 1.0;
        }
        if (o->nstress)
            for (int c = 0; c < 6; c++)
                src->S[6 * i + c] = keep ? AT(row, CG_IN_STRESS + c) : 0.0;
    }
    src->pt.n = n;
    src->pt.s = src->s;
    src->pt.v = src->v;
    src->pt.m = src->m;
    src->pt.vol = src->vol;
    src->pt.rad = src->rad;
    src->pt.S = o->nstress ? src->S : NULL;
    src->pt.area = L[0] * L[1] * L[2] / L[ax];
    src->pt.nc = 0;
    return EKM_OK;
}

ekm_status cg_input_next(cg_input *src, ekm_error *err)
{
    const cg_run_opts *o = src->o;
    for (;;) {
        if (!src->d) {
            if (src->ifile >= o->ninputs) {
                if (o->expect_snapshots && src->nread != o->expect_snapshots)
                    return EKM_FAIL(
                        err, EKM_EINPUT, "%s%s: expected %zu snapshots (--expect-snapshots), got %zu",
                        o->inputs[0], o->ninputs > 1 ? " ..." : "", o->expect_snapshots, src->nread);
                return EKM_EOF;
            }
            ekm_status rc = cg_dump_open(&src->d, o->inputs[src->ifile++], src->cols, src->ncols, err);
            if (rc)
                return rc;
            /* sizes and masses that make no sense are the dump's error, at
             * their line and column (not a kernel width computed from them) */
            const int checked[3] = {CG_IN_MASS, CG_IN_RADIUS, CG_IN_DIAMETER};
            const cg_dump_check how[3] = {CG_DUMP_POSITIVE, CG_DUMP_RADIUS, CG_DUMP_DIAMETER};
            for (int c = 0; c < 3; c++)
                if (src->col[checked[c]] >= 0)
                    cg_dump_expect(src->d, (size_t)src->col[checked[c]], how[c]);
            /* a velocity of 1e300 overflows m v^2: the dump's error too */
            for (int c = 0; c < 3; c++)
                if (src->col[CG_IN_VX + c] >= 0)
                    cg_dump_expect(src->d, (size_t)src->col[CG_IN_VX + c], CG_DUMP_VELOCITY);
            /* a type or id of 1.5 matches nothing: the dump's error too */
            if (src->col[CG_IN_TYPE] >= 0)
                cg_dump_expect(src->d, (size_t)src->col[CG_IN_TYPE], CG_DUMP_INTEGER);
            if (src->col[CG_IN_ID] >= 0)
                cg_dump_expect(src->d, (size_t)src->col[CG_IN_ID], CG_DUMP_INTEGER);
        }
        ekm_status rc = cg_dump_next(src->d, &src->snap, err);
        if (rc == EKM_EOF) {
            if (cg_dump_truncated(src->d) && o->expect_snapshots)
                return EKM_FAIL(err, EKM_EINPUT, "%s: expected %zu complete snapshots (--expect-snapshots)",
                                cg_dump_truncation(src->d), o->expect_snapshots);
            if (cg_dump_truncated(src->d) && o->log)
                fprintf(o->log, "warning: %s\n", cg_dump_warning(src->d));
            cg_dump_close(src->d);
            src->d = NULL;
            continue;
        }
        if (rc)
            return rc;
        src->nread++;
        const cg_snapshot *sn = &src->snap;
        if (src->have_last && sn->step <= src->last_step) {
            src->nrepeat++;
            continue;
        }
        ekm_status trc = cg_snapshot_time(sn, o->select.dt, &src->order, &src->t, err);
        if (trc)
            return trc;
        src->have_last = 1;
        src->last_step = sn->step;
        if (!cg_select_keeps(&o->select, sn->step, src->t))
            continue;
        ekm_status crc = input_convert(src, err);
        if (crc || !o->npairs || src->skip_pairs)
            return crc;
        const int pos_col[3] = {src->col[CG_IN_POS], src->col[CG_IN_POS + 1], src->col[CG_IN_POS + 2]};
        return cg_contacts_match(&src->pairs, o, sn, src->col[CG_IN_ID], pos_col, &src->pt, err);
    }
}
