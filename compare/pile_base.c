/* pile_base.c: the base pressure profile of a pile (see pile_base.h). */
#include "ekm_version.h"
#include "pile_base.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "atomic.h"
#include "dump.h"
#include "h5.h"

#define BASE_MAX_BINS 1e7

/* Dump columns asked of the reader. */
enum { B_X, B_XU, B_XS, B_XSU, B_TYPE, B_FZ, B_RADIUS, B_DIAMETER, B_NCOL };
static const char *const base_cols[B_NCOL] = {"x", "xu", "xs", "xsu", "type", "fz", "radius", "diameter"};

void cg_base_opts_apply(cg_base_opts *o, const ekm_cg_value *v)
{
    switch (v->id) {
    case EKM_CG_OUT: o->out = v->text; break;
    case EKM_CG_CSV: o->csv = v->text; break;
    case EKM_CG_RANGE:
        o->range_lo = v->x;
        o->range_hi = v->y;
        o->have_range = 1;
        break;
    default: cg_select_apply(&o->select, v); break; /* --dt, --from, --to, --steps, or not base's */
    }
}

cg_base_opts cg_base_opts_default(void)
{
    cg_base_opts o;
    memset(&o, 0, sizeof o);
    o.floor_type = 2;
    return o;
}

typedef struct {
    const cg_base_opts *o;
    int have_grid;
    size_t n;              /* bins */
    double lo, hi, dx;     /* grid [m] */
    double centre;         /* fold centre [m] */
    double box_lo, box_hi; /* first run's box along x [m] */
    double *sum;           /* n: sum of fz of one snapshot [N] */
    double *cnt;           /* n: floor grains per bin (one snapshot) */
    double *snaps;         /* selected snapshots' profiles of the current run, nsnap x n [Pa] */
    size_t nsnap, snap_cap;
    double *runs; /* R x n: each run's mean profile [Pa] */
    size_t nruns;
    double y_period; /* L_y of the first snapshot [m] */
    double load_sum; /* sum over runs of the mean floor load -sum fz [N] */
    size_t nfloor;   /* floor grains of the first snapshot */
    size_t nread, nused, nout;
    int y_not_periodic;
    int have_step;
    int64_t step_lo, step_hi; /* selected steps, over every run */
} base_state;

static ekm_status missing(const cg_snapshot *s, const char *what, ekm_error *err)
{
    return EKM_FAIL(err, EKM_EINPUT, "%s: ITEM: ATOMS has no column %s", s->where, what);
}

static int position_flavour(const cg_snapshot *s)
{
    for (int f = B_X; f <= B_XSU; f++)
        if (s->present[f])
            return f;
    return -1;
}

/* The grid from the first snapshot: symmetric about the centre. */
static ekm_status make_grid(base_state *st, const cg_snapshot *s, ekm_error *err)
{
    const cg_base_opts *o = st->o;
    double lo = s->lo[0], hi = s->hi[0];
    st->box_lo = lo;
    st->box_hi = hi;
    if (o->have_range) {
        lo = o->range_lo;
        hi = o->range_hi;
    }
    double c = o->have_centre ? o->centre : 0.5 * (lo + hi);
    if (o->have_centre && o->have_range && fabs(lo + hi - 2.0 * c) > 1e-9 * (hi - lo))
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--range: expected a range symmetric about --centre %.9g m (for the folding), got "
                        "%.9g:%.9g",
                        c, lo, hi);
    if (o->have_centre && !o->have_range) {
        if (!(c > lo && c < hi))
            return EKM_FAIL(err, EKM_EUSAGE,
                            "--centre: expected a centre inside the box (%.9g .. %.9g m), got %.9g", lo, hi,
                            c);
        double h = fmin(c - lo, hi - c);
        lo = c - h;
        hi = c + h;
    }
    double dx = o->dx;
    if (!o->bins && !(dx > 0)) {
        /* two floor-grain diameters */
        double dsum = 0.0;
        size_t nd = 0;
        for (size_t i = 0; i < (size_t)s->natoms; i++) {
            const double *row = s->data + i * s->nsel;
            if (row[B_TYPE] != (double)o->floor_type)
                continue;
            if (s->present[B_RADIUS]) {
                dsum += 2.0 * row[B_RADIUS];
                nd++;
            } else if (s->present[B_DIAMETER]) {
                dsum += row[B_DIAMETER];
                nd++;
            }
        }
        if (nd == 0)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "%s: no floor grain (type %d) with a radius or diameter column to size the bins: "
                            "give --dx or --bins",
                            s->where, o->floor_type);
        dx = 2.0 * dsum / (double)nd;
    }
    double L = hi - lo;
    double nb = o->bins ? (double)o->bins : ceil(L / dx - 1e-9);
    if (nb < 1)
        nb = 1;
    if (nb > BASE_MAX_BINS)
        return EKM_FAIL(err, EKM_EUSAGE, "--dx: expected at most 1e7 bins, got %.3g", nb);
    st->n = (size_t)nb;
    st->lo = lo;
    st->hi = hi;
    st->dx = L / (double)st->n;
    st->centre = c;
    st->sum = calloc(st->n, sizeof *st->sum);
    st->cnt = calloc(st->n, sizeof *st->cnt);
    st->runs = malloc(o->ninputs * st->n * sizeof *st->runs);
    if (!st->sum || !st->cnt || !st->runs)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    st->y_period = s->hi[1] - s->lo[1];
    st->y_not_periodic = !s->periodic[1];
    st->have_grid = 1;
    return EKM_OK;
}

static double x_of(const cg_snapshot *s, const double *row, int flav)
{
    double x = row[flav];
    if (flav >= B_XS)
        x = s->lo[0] + x * (s->hi[0] - s->lo[0]);
    if (s->periodic[0]) {
        double L = s->hi[0] - s->lo[0];
        x = s->lo[0] + fmod(x - s->lo[0], L);
        if (x < s->lo[0])
            x += L;
    }
    return x;
}

/* One snapshot's profile appended to st->snaps. */
static ekm_status add_snapshot(base_state *st, const cg_snapshot *s, ekm_error *err)
{
    const cg_base_opts *o = st->o;
    int flav = position_flavour(s);
    if (flav < 0)
        return missing(s, "'x' (nor xu, xs, xsu)", err);
    if (!s->present[B_TYPE])
        return missing(s, "'type' (the floor grains are type --floor-type)", err);
    if (!s->present[B_FZ])
        return missing(s, "'fz' (ekmcompare base needs the forces on the floor grains: dump fx fy fz)", err);
    if (s->triclinic)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: expected an orthogonal box (ekmcompare base), got a triclinic one", s->where);
    size_t nfloor = 0;
    for (size_t i = 0; i < (size_t)s->natoms; i++)
        nfloor += s->data[i * s->nsel + B_TYPE] == (double)o->floor_type;
    if (nfloor == 0)
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: expected floor grains (atoms of type %d, --floor-type), got none", s->where,
                        o->floor_type);
    if (st->nfloor == 0)
        st->nfloor = nfloor;
    if (!st->have_grid) {
        ekm_status rc = make_grid(st, s, err);
        if (rc)
            return rc;
    } else if (!st->o->have_range && st->nruns > 0 && st->nsnap == 0) {
        double L = st->box_hi - st->box_lo;
        if (fabs(s->lo[0] - st->box_lo) > 1e-9 * L || fabs(s->hi[0] - st->box_hi) > 1e-9 * L)
            return EKM_FAIL(
                err, EKM_EINPUT,
                "%s: ITEM: BOX BOUNDS: x: expected the box of the first run (%.9g .. %.9g m), got "
                "%.9g .. %.9g m: the runs share one grid (or give --range)",
                s->box_where[0], st->box_lo, st->box_hi, s->lo[0], s->hi[0]);
    }
    double Ly = s->hi[1] - s->lo[1];
    memset(st->sum, 0, st->n * sizeof *st->sum);
    memset(st->cnt, 0, st->n * sizeof *st->cnt);
    for (size_t i = 0; i < (size_t)s->natoms; i++) {
        const double *row = s->data + i * s->nsel;
        if (row[B_TYPE] != (double)o->floor_type)
            continue;
        double x = x_of(s, row, flav), u = (x - st->lo) / st->dx;
        if (!(u >= 0.0 && u < (double)st->n)) {
            st->nout++;
            continue;
        }
        size_t k = (size_t)u;
        st->sum[k] += row[B_FZ];
        st->cnt[k] += 1.0;
    }
    if (st->nsnap == st->snap_cap) {
        size_t c = st->snap_cap ? 2 * st->snap_cap : 16;
        double *p = realloc(st->snaps, c * st->n * sizeof *p);
        if (!p)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        st->snaps = p;
        st->snap_cap = c;
    }
    double *prof = st->snaps + st->nsnap * st->n, area = st->dx * Ly;
    for (size_t k = 0; k < st->n; k++)
        prof[k] = st->cnt[k] > 0 ? -st->sum[k] / area : NAN;
    st->nsnap++;
    return EKM_OK;
}

/* The selected snapshots of one run -> st->runs[irun]. */
static ekm_status read_run(base_state *st, const char *path, size_t irun, ekm_error *err)
{
    const cg_base_opts *o = st->o;
    cg_dump *d = NULL;
    cg_snapshot s;
    memset(&s, 0, sizeof s);
    ekm_status rc = cg_dump_open(&d, path, base_cols, B_NCOL, err);
    if (rc)
        return rc;
    cg_dump_expect(d, B_RADIUS, CG_DUMP_RADIUS);
    cg_dump_expect(d, B_DIAMETER, CG_DUMP_DIAMETER);
    cg_dump_expect(d, B_TYPE, CG_DUMP_INTEGER);
    st->nsnap = 0;
    int have_last = 0;
    int64_t last_step = 0;
    cg_time_order order = {0, 0.0};
    while ((rc = cg_dump_next(d, &s, err)) == EKM_OK) {
        st->nread++;
        if (have_last && s.step <= last_step)
            continue; /* a repeated step (restart overlap) */
        have_last = 1;
        last_step = s.step;
        /* the times, when known, increase (cg_snapshot_time); needed for
         * --from/--to */
        double t = 0.0;
        if ((s.has_time || cg_select_needs_time(&o->select)) &&
            (rc = cg_snapshot_time(&s, o->select.dt, &order, &t, err)))
            break;
        if (!cg_select_keeps(&o->select, s.step, t))
            continue;
        if ((rc = add_snapshot(st, &s, err)))
            break;
        if (!st->have_step || s.step < st->step_lo)
            st->step_lo = s.step;
        if (!st->have_step || s.step > st->step_hi)
            st->step_hi = s.step;
        st->have_step = 1;
    }
    if (rc == EKM_EOF) {
        rc = EKM_OK;
        if (cg_dump_truncated(d) && o->log)
            fprintf(o->log, "warning: %s\n", cg_dump_warning(d));
        if (st->nsnap == 0)
            rc = EKM_FAIL(err, EKM_EINPUT, "%s: no snapshots selected", path);
    }
    cg_dump_close(d);
    cg_snapshot_free(&s);
    if (rc)
        return rc;
    size_t first = o->last && o->last < st->nsnap ? st->nsnap - o->last : 0, used = st->nsnap - first;
    double *run = st->runs + irun * st->n, load = 0.0;
    for (size_t k = 0; k < st->n; k++) {
        double sum = 0.0;
        for (size_t j = first; j < st->nsnap; j++)
            sum += st->snaps[j * st->n + k];
        run[k] = sum / (double)used;
        if (isfinite(run[k]))
            load += run[k] * st->dx * st->y_period;
    }
    st->load_sum += load;
    st->nused += used;
    st->nruns = irun + 1;
    return EKM_OK;
}

static ekm_status write_h5(const base_state *st, const double *p, const double *se, const double *fold,
                           ekm_error *err)
{
    const cg_base_opts *o = st->o;
    ekm_h5_file *w;
    ekm_status rc = ekm_h5_create(&w, o->out, err);
    if (rc)
        return rc;
    double *xc = malloc(st->n * sizeof *xc);
    if (!xc) {
        ekm_h5_abort(w);
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    for (size_t k = 0; k < st->n; k++)
        xc[k] = st->lo + ((double)k + 0.5) * st->dx;
    const size_t dims2[2] = {st->nruns, st->n};
    rc = ekm_h5_write_field(w, "x", 1, &st->n, xc, err);
    free(xc);
    if (!rc)
        rc = ekm_h5_write_field(w, "p_base", 1, &st->n, p, err);
    if (!rc)
        rc = ekm_h5_write_field(w, "p_base_se", 1, &st->n, se, err);
    if (!rc)
        rc = ekm_h5_write_field(w, "p_base_se_fold", 1, &st->n, fold, err);
    if (!rc)
        rc = ekm_h5_write_field(w, "p_base_runs", 2, dims2, st->runs, err);
    char inputs[4096] = "", window[256], ftype[32];
    size_t used = 0;
    for (size_t i = 0; i < o->ninputs && used + 2 < sizeof inputs; i++)
        used += (size_t)snprintf(inputs + used, sizeof inputs - used, "%s%s", i ? "\n" : "", o->inputs[i]);
    snprintf(window, sizeof window, "steps %lld .. %lld, %zu snapshots over %zu run(s)%s",
             (long long)st->step_lo, (long long)st->step_hi, st->nused, st->nruns,
             o->last ? " (the last --last of each run)" : "");
    snprintf(ftype, sizeof ftype, "%d", o->floor_type);
    const struct {
        const char *name, *value;
    } strs[] = {{"inputs", inputs},
                {"axis", "x"},
                {"quantity", "base pressure -sum(fz of the floor grains in a bin)/(dx y_period)"},
                {"floor_type", ftype},
                {"window", window},
                {"standard_error", "p_base_se: across the runs, sd/sqrt(runs); p_base_se_fold: "
                                   "|p(x) - p(2 centre - x)|/2"},
                {"code_version", EKMBENCH_VERSION}};
    for (size_t i = 0; i < sizeof strs / sizeof strs[0] && !rc; i++)
        rc = ekm_h5_attr_set_string(w, NULL, strs[i].name, strs[i].value, err);
    const struct {
        const char *name;
        double value;
    } nums[] = {{"dx", st->dx},
                {"lo", st->lo},
                {"hi", st->hi},
                {"centre", st->centre},
                {"y_period", st->y_period},
                {"floor_load", st->load_sum / (double)st->nruns},
                {"floor_grains", (double)st->nfloor},
                {"runs", (double)st->nruns},
                {"snapshots_read", (double)st->nread},
                {"snapshots_used", (double)st->nused},
                {"floor_grains_outside_grid", (double)st->nout}};
    for (size_t i = 0; i < sizeof nums / sizeof nums[0] && !rc; i++)
        rc = ekm_h5_attr_set_double(w, NULL, nums[i].name, nums[i].value, err);
    if (rc) {
        ekm_h5_abort(w);
        return rc;
    }
    return ekm_h5_commit(w, err);
}

static ekm_status write_csv(const base_state *st, const double *p, const double *se, const double *fold,
                            ekm_error *err)
{
    ekm_atomic out;
    ekm_status rc = ekm_atomic_open(&out, st->o->csv, err);
    if (rc)
        return rc;
    fputs("x,p_base,p_base_se,p_base_se_fold\n", out.fp);
    for (size_t k = 0; k < st->n; k++)
        fprintf(out.fp, "%.9g,%.9g,%.9g,%.9g\n", st->lo + ((double)k + 0.5) * st->dx, p[k], se[k], fold[k]);
    return ekm_atomic_commit(&out, err);
}

static ekm_status refuse_inputs(const cg_base_opts *o, ekm_error *err)
{
    ekm_status rc = EKM_OK;
    if (o->out)
        rc = ekm_atomic_check_target(o->out, err);
    if (!rc && o->csv)
        rc = ekm_atomic_check_target(o->csv, err);
    if (!rc && o->out)
        rc = ekm_atomic_refuse_input(o->out, o->inputs, o->ninputs, err);
    if (!rc && o->csv)
        rc = ekm_atomic_refuse_input(o->csv, o->inputs, o->ninputs, err);
    if (!rc && o->out && o->csv)
        rc = ekm_atomic_refuse_input(o->csv, &o->out, 1, err);
    return rc;
}

ekm_status cg_base_run(const cg_base_opts *o, ekm_error *err)
{
    if (o->ninputs == 0)
        return EKM_FAIL(err, EKM_EUSAGE, "base: expected at least one dump file (one per run)");
    if (!o->out && !o->csv)
        return EKM_FAIL(err, EKM_EUSAGE, "base: expected -o OUT.h5 and/or --csv OUT.csv");
    ekm_status rc = refuse_inputs(o, err);
    if (rc)
        return rc;
    base_state st;
    memset(&st, 0, sizeof st);
    st.o = o;
    for (size_t j = 0; j < o->ninputs && !rc; j++)
        rc = read_run(&st, o->inputs[j], j, err);
    double *p = NULL, *se = NULL, *fold = NULL;
    if (!rc) {
        p = malloc(st.n * sizeof *p);
        se = malloc(st.n * sizeof *se);
        fold = malloc(st.n * sizeof *fold);
        if (!p || !se || !fold)
            rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    }
    if (!rc) {
        size_t R = st.nruns;
        for (size_t k = 0; k < st.n; k++) {
            double sum = 0.0, ss = 0.0;
            for (size_t j = 0; j < R; j++)
                sum += st.runs[j * st.n + k];
            p[k] = sum / (double)R;
            for (size_t j = 0; j < R; j++)
                ss += (st.runs[j * st.n + k] - p[k]) * (st.runs[j * st.n + k] - p[k]);
            se[k] = R >= 2 ? sqrt(ss / (double)(R - 1) / (double)R) : NAN;
        }
        for (size_t k = 0; k < st.n; k++)
            fold[k] = 0.5 * fabs(p[k] - p[st.n - 1 - k]);
        if (st.nout && o->log)
            fprintf(o->log, "note: %zu floor-grain snapshots outside the grid [%.6g, %.6g] m (not counted)\n",
                    st.nout, st.lo, st.hi);
        if (st.y_not_periodic && o->log)
            fprintf(o->log, "note: the box is not periodic in y: p is per unit of its y length %.6g m\n",
                    st.y_period);
        int wrote_h5 = 0;
        if (o->out && !(rc = write_h5(&st, p, se, fold, err)))
            wrote_h5 = 1;
        if (!rc && o->csv)
            rc = write_csv(&st, p, se, fold, err);
        if (rc && wrote_h5)
            unlink(o->out);
        if (!rc && o->log)
            fprintf(o->log,
                    "ekmcompare base: %zu run(s), %zu of %zu snapshots, %zu bins of %.4g m about x = %.6g m, "
                    "floor load %.6g N -> %s%s%s\n",
                    st.nruns, st.nused, st.nread, st.n, st.dx, st.centre, st.load_sum / (double)st.nruns,
                    o->out ? o->out : "", o->out && o->csv ? ", " : "", o->csv ? o->csv : "");
    }
    free(p);
    free(se);
    free(fold);
    free(st.sum);
    free(st.cnt);
    free(st.snaps);
    free(st.runs);
    return rc;
}
