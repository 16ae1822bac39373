/* cg2d_run.c: the `ekmcompare cg --axes x,z` pipeline (see cg2d_run.h). */
#include "ekm_version.h"
#include "cg2d_run.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "atomic.h"
#include "cg2d.h"
#include "cg2d_output.h"
#include "cg_input.h"
#include "window.h"
#include "kernel.h"
#include "stats.h"
#include "steadiness.h"
#include "xdmf.h"

#define CG2D_MAX_CELLS 5e7 /* most cells of a grid */

typedef struct {
    const cg_run_opts *o;
    cg_kernel *k;
    cg2d_profile *prof;
    cg2d_grid g;
    int have_grid;
    size_t ncell;
    double *prim; /* CG_NPRIM x ncell: one snapshot */
    cg_blocks *b; /* the open window */
    double *mean; /* CG_NPRIM x ncell */
    double *fld;  /* CG2D_NFIELD x ncell */
    double *bf;   /* samples x CG2D_NFIELD: one cell's fields per block (or per run) */
    double *series, *work;
    size_t nsample_cap; /* rows of bf, series, work */
    double *runs;       /* ensemble: R x CG_NPRIM x ncell, each run's mean */
    double *run_t;      /* ensemble: each run's window mid-time [s] */
    size_t nruns;
    cg2d_results r;
    /* what the run did, for the attributes */
    double width, dsum, dcount, length_y;
    size_t nread, nused, nout, nrepeat;
    double tsel0, tsel1;
    char x_lo_where[620], z_lo_where[620];
} cg2d_state;

static void results_free(cg2d_results *r)
{
    cg_series_free(r->t, r->nsnap, r->f, r->se, CG2D_NFIELD);
}

static ekm_status results_grow(cg2d_results *r, ekm_error *err)
{
    return cg_series_grow(&r->t, &r->nsnap, r->f, r->se, CG2D_NFIELD, r->ncell, r->nt, &r->cap, 4, err);
}

/* One axis of the grid from the box (lo, hi, periodic) or --range. */
static void make_axis(const cg_run_opts *o, int ax, const cg_input *src, double width, cg_grid *g)
{
    int is_z = (ax == o->axis);
    int ranged = is_z && o->have_range;
    double lo = is_z ? src->lo : src->lo2, hi = is_z ? src->hi : src->hi2;
    int periodic = is_z ? src->periodic : src->periodic2;
    g->lo = ranged ? o->range_lo : lo;
    g->hi = ranged ? o->range_hi : hi;
    g->axis = ax;
    g->periodic = periodic && !ranged;
    g->reflect = !periodic && !ranged;
    size_t bins = is_z ? o->bins : o->bins_x;
    double L = g->hi - g->lo;
    if (bins > 0) {
        g->n = bins;
    } else {
        double dz = o->dz > 0 ? o->dz : 0.5 * width;
        double nb = ceil(L / dz - 1e-9);
        g->n = nb < 1 ? 1 : nb > CG2D_MAX_CELLS ? (size_t)CG2D_MAX_CELLS + 1 : (size_t)nb;
    }
    g->dz = L / (double)g->n;
}

static ekm_status state_grid(cg2d_state *st, const cg_input *src, ekm_error *err)
{
    const cg_run_opts *o = st->o;
    double width = o->width > 0 ? o->width : (src->dcount > 0 ? src->dsum / src->dcount : 0.0);
    if (!(width > 0))
        return EKM_FAIL(err, EKM_EUSAGE, "%s: the first snapshot has no atoms: give --width",
                        src->snap.where);
    st->width = width;
    make_axis(o, o->axis2, src, width, &st->g.gx);
    make_axis(o, o->axis, src, width, &st->g.gz);
    ekm_status rc;
    double cells = (double)st->g.gx.n * (double)st->g.gz.n;
    if (cells > CG2D_MAX_CELLS)
        return EKM_FAIL(err, o->dz > 0 || o->bins ? EKM_EUSAGE : EKM_EINPUT,
                        "%s: expected a grid of at most 5e7 cells, got %zu x %zu (dx = %.4g m, dz = %.4g m): "
                        "give --dz or --bins NX,NZ",
                        src->snap.where, st->g.gx.n, st->g.gz.n, st->g.gx.dz, st->g.gz.dz);
    if ((rc = cg_kernel_alloc(&st->k, o->kernel, width, err)))
        return rc;
    if (!(o->width > 0))
        for (int a = 0; a < 2; a++) {
            const cg_grid *ga = a ? &st->g.gz : &st->g.gx;
            if ((ga->periodic || ga->reflect) && st->k->type != CG_KERNEL_BINS &&
                st->k->cutoff > ga->hi - ga->lo)
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: the mean particle diameter %.6g m (the kernel width: --width not given) "
                                "gives a kernel support of %.6g m, longer than the box along %c (%.6g m): "
                                "expected particles much smaller than the box, or give --width",
                                src->snap.where, width, st->k->cutoff, a ? 'z' : 'x', ga->hi - ga->lo);
        }
    if ((rc = cg2d_profile_alloc(&st->prof, st->k, &st->g, o->tmode, err)))
        return rc;
    st->ncell = cg2d_ncell(&st->g);
    st->r.ncell = st->ncell;
    size_t n = st->ncell;
    st->nsample_cap = o->ensemble ? o->ninputs : CG2D_BLOCKS;
    if ((rc = cg_blocks_alloc(&st->b, CG_NPRIM * n, CG2D_BLOCKS, err)))
        return rc;
    st->prim = malloc(CG_NPRIM * n * sizeof(double));
    st->mean = malloc(CG_NPRIM * n * sizeof(double));
    st->fld = malloc(CG2D_NFIELD * n * sizeof(double));
    st->bf = malloc(st->nsample_cap * CG2D_NFIELD * sizeof(double));
    st->series = malloc(st->nsample_cap * sizeof(double));
    st->work = malloc(st->nsample_cap * sizeof(double));
    if (o->ensemble) {
        st->runs = malloc(o->ninputs * CG_NPRIM * n * sizeof(double));
        st->run_t = malloc(o->ninputs * sizeof(double));
    }
    if (!st->prim || !st->mean || !st->fld || !st->bf || !st->series || !st->work ||
        (o->ensemble && (!st->runs || !st->run_t)))
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory (2D grid of %zu x %zu cells)", st->g.gx.n,
                        st->g.gz.n);
    st->length_y = src->length_avg;
    st->have_grid = 1;
    return EKM_OK;
}

/* A later run's box must give the first run's grid. */
static ekm_status check_same_box(const cg2d_state *st, const cg_input *src, ekm_error *err)
{
    const cg_run_opts *o = st->o;
    const cg_grid *axes[2] = {&st->g.gx, &st->g.gz};
    for (int a = 0; a < 2; a++) {
        int ax = a ? o->axis : o->axis2;
        if (a && o->have_range)
            continue;
        double lo = a ? src->lo : src->lo2, hi = a ? src->hi : src->hi2, L = axes[a]->hi - axes[a]->lo;
        if (fabs(lo - axes[a]->lo) > 1e-9 * L || fabs(hi - axes[a]->hi) > 1e-9 * L)
            return EKM_FAIL(
                err, EKM_EINPUT,
                "%s: ITEM: BOX BOUNDS: %c: expected the box of the first run (%.9g .. %.9g m), got "
                "%.9g .. %.9g m: the runs of an ensemble share one grid",
                src->snap.box_where[ax], "xyz"[ax], axes[a] -> lo, axes[a] -> hi, lo, hi);
    }
    return EKM_OK;
}

/* Fields of st->mean, and their SEs from nsample samples of the kernel
 * sums (samples + j m, times scale: the blocks' sums, or the runs' means),
 * derived cell by cell (no store of every sample's fields): blocking for
 * blocks, plain sd/sqrt(n) for independent runs; appended to r. */
static ekm_status append_window(cg2d_state *st, const double *samples, size_t nsample, double scale,
                                int independent, double t_mid, double nsnap, ekm_error *err)
{
    cg2d_results *r = &st->r;
    ekm_status rc = results_grow(r, err);
    if (rc)
        return rc;
    size_t n = st->ncell, m = CG_NPRIM * n;
    cg2d_profile_derive(st->mean, &st->g, st->fld);
    for (int f = 0; f < CG2D_NFIELD; f++)
        for (size_t c = 0; c < n; c++)
            r->f[f][r->nt * n + c] = st->fld[(size_t)f * n + c];
    for (size_t c = 0; c < n; c++) {
        for (size_t j = 0; j < nsample; j++) {
            double one[CG_NPRIM];
            for (size_t q = 0; q < CG_NPRIM; q++)
                one[q] = samples[j * m + q * n + c] * scale;
            cg2d_derive_cells(one, 1, st->bf + j * CG2D_NFIELD);
        }
        for (int f = 0; f < CG2D_NFIELD; f++) {
            double se = NAN;
            size_t nfin = 0;
            for (size_t j = 0; j < nsample; j++) {
                st->series[j] = st->bf[j * CG2D_NFIELD + (size_t)f];
                nfin += isfinite(st->series[j]) != 0;
            }
            if (independent && nfin >= 2) {
                double sum = 0.0, ss = 0.0;
                for (size_t j = 0; j < nsample; j++)
                    if (isfinite(st->series[j]))
                        sum += st->series[j];
                double mean = sum / (double)nfin;
                for (size_t j = 0; j < nsample; j++)
                    if (isfinite(st->series[j]))
                        ss += (st->series[j] - mean) * (st->series[j] - mean);
                se = sqrt(ss / (double)(nfin - 1) / (double)nfin);
            } else if (!independent && nsample >= 2) {
                se = cg_stats_se(st->series, nsample, st->work);
            }
            r->se[f][r->nt * n + c] = se;
        }
    }
    r->t[r->nt] = t_mid;
    r->nsnap[r->nt] = nsnap;
    r->nt++;
    return EKM_OK;
}

/* Close the open window of a single run: blocking SEs. */
static ekm_status finish_window(cg2d_state *st, double t_mid, ekm_error *err)
{
    cg_blocks *b = st->b;
    cg_blocks_mean(b, st->mean);
    ekm_status rc =
        append_window(st, b->blocks, b->nblocks, 1.0 / (double)b->bsize, 0, t_mid, (double)b->nsnap, err);
    cg_blocks_reset(b);
    return rc;
}

/* The selected snapshots of the inputs of ro (one run, or all of them
 * without --ensemble) into windows or, for an ensemble run, into the
 * run's mean (st->runs[irun]). */
static ekm_status read_run(cg2d_state *st, const cg_run_opts *ro, size_t irun, ekm_error *err)
{
    const cg_run_opts *o = st->o;
    double t_start = -INFINITY;
    ekm_status rc = EKM_OK;
    if (o->steady && (rc = cg_steadiness_start(ro, &t_start, err)))
        return rc;
    cg_input src;
    cg_input_init(&src, ro);
    long cur_w = -1;
    double t0 = 0, tw0 = 0, tw1 = 0;
    size_t count = 0;
    while ((rc = cg_input_next(&src, err)) == EKM_OK) {
        if (src.t < t_start)
            continue;
        if (!st->have_grid) {
            if ((rc = state_grid(st, &src, err)))
                break;
            st->tsel0 = src.t;
        }
        if (count == 0) {
            if (o->ensemble && irun > 0 && (rc = check_same_box(st, &src, err)))
                break;
            t0 = src.t;
        }
        long wi = o->every        ? (long)(count / o->every)
                  : o->window > 0 ? (long)floor((src.t - t0) / o->window)
                                  : 0;
        if (wi != cur_w && cur_w >= 0 && (rc = finish_window(st, 0.5 * (tw0 + tw1), err)))
            break;
        if (wi != cur_w) {
            cur_w = wi;
            tw0 = src.t;
        }
        tw1 = src.t;
        st->tsel1 = src.t;
        const cg2d_particles pt = {.n = src.pt.n,
                                   .x = src.s2,
                                   .z = src.s,
                                   .v = src.v,
                                   .m = src.m,
                                   .vol = src.vol,
                                   .S = src.pt.S,
                                   .length_y = src.length_avg,
                                   .nc = src.pt.nc,
                                   .cx = src.pairs.cs2,
                                   .cz = src.pt.cs,
                                   .cb = src.pt.cb,
                                   .cf = src.pt.cf};
        cg2d_profile_snapshot(st->prof, &pt, st->prim);
        for (size_t i = 0; i < pt.n; i++)
            if (pt.m[i] > 0)
                st->nout += (!st->g.gz.periodic && (pt.z[i] < st->g.gz.lo || pt.z[i] > st->g.gz.hi)) ||
                            (!st->g.gx.periodic && (pt.x[i] < st->g.gx.lo || pt.x[i] > st->g.gx.hi));
        cg_blocks_add(st->b, st->prim);
        count++;
    }
    if (rc == EKM_EOF) {
        rc = EKM_OK;
        if (count == 0)
            rc = EKM_FAIL(err, EKM_EINPUT, "%s: no snapshots selected (%zu read)", ro->inputs[0], src.nread);
    }
    st->dsum += src.dsum;
    st->dcount += src.dcount;
    st->nread += src.nread;
    st->nrepeat += src.nrepeat;
    st->nused += count;
    cg_input_close(&src);
    if (rc)
        return rc;
    if (!o->ensemble)
        return finish_window(st, 0.5 * (tw0 + tw1), err);
    size_t m = CG_NPRIM * st->ncell;
    cg_blocks_mean(st->b, st->runs + irun * m);
    st->run_t[irun] = 0.5 * (tw0 + tw1);
    st->nruns = irun + 1;
    cg_blocks_reset(st->b);
    return EKM_OK;
}

/* The ensemble's one window: fields of the mean over runs, SE across runs. */
static ekm_status finish_ensemble(cg2d_state *st, ekm_error *err)
{
    size_t m = CG_NPRIM * st->ncell, R = st->nruns;
    double tsum = 0.0;
    for (size_t i = 0; i < m; i++) {
        double s = 0.0;
        for (size_t j = 0; j < R; j++)
            s += st->runs[j * m + i];
        st->mean[i] = s / (double)R;
    }
    for (size_t j = 0; j < R; j++)
        tsum += st->run_t[j];
    return append_window(st, st->runs, R, 1.0, 1, tsum / (double)R, (double)st->nused, err);
}

static ekm_status check_options(const cg_run_opts *o, ekm_error *err)
{
    if (o->ninputs == 0)
        return EKM_FAIL(err, EKM_EUSAGE, "cg: expected at least one dump file");
    if (!o->out && !o->csv)
        return EKM_FAIL(err, EKM_EUSAGE, "cg: expected -o OUT.h5 and/or --csv OUT.csv");
    if (o->axis != 2 || o->axis2 != 0)
        return EKM_FAIL(err, EKM_EUSAGE, "--axes: expected x,z (the 2D grid, averaged over y)");
    if (o->nstress && o->npairs)
        return EKM_FAIL(err, EKM_EUSAGE,
                        "cg: expected --stress or --pairs, not both (the contact stress would count twice)");
    if (o->npairs && o->npaircols != 9 && o->npaircols != 5)
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--pairs: expected --pair-columns with 9 (x1,y1,z1,x2,y2,z2,fx,fy,fz) "
                        "or 5 (id1,id2,fx,fy,fz) names");
    if (!strcmp(o->kernel, "bins"))
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--kernel: bins (sphere-slab volumes) has no exact 2D form: expected gauss or lucy "
                        "with --axes x,z");
    if (o->ensemble && (o->every || o->window > 0))
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--ensemble: one window per run (the time average of each run): expected no --every "
                        "or --window");
    if (o->ensemble && o->ninputs < 2)
        return EKM_FAIL(err, EKM_EUSAGE, "--ensemble: expected at least two dumps (independent runs)");
    if (o->bins && !o->bins_x)
        return EKM_FAIL(err, EKM_EUSAGE, "--bins: expected NX,NZ (cells along x and z) with --axes x,z");
    return EKM_OK;
}

ekm_status cg2d_run(const cg_run_opts *o, ekm_error *err)
{
    ekm_status rc = check_options(o, err);
    if (!rc)
        rc = cg_opts_refuse_inputs(o, err);
    if (rc)
        return rc;
    char *inputs = calloc(4096, 1);
    if (!inputs)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    size_t used = 0;
    for (size_t i = 0; i < o->ninputs && used + 2 < 4096; i++)
        used += (size_t)snprintf(inputs + used, 4096 - used, "%s%s", i ? "\n" : "", o->inputs[i]);
    cg2d_state st;
    memset(&st, 0, sizeof st);
    st.o = o;
    if (o->ensemble) {
        for (size_t j = 0; j < o->ninputs && !rc; j++) {
            cg_run_opts ro = *o;
            ro.inputs = o->inputs + j;
            ro.ninputs = 1;
            rc = read_run(&st, &ro, j, err);
        }
        if (!rc)
            rc = finish_ensemble(&st, err);
    } else {
        rc = read_run(&st, o, 0, err);
    }
    char window[256];
    if (o->ensemble)
        snprintf(window, sizeof window, "%zu runs, %zu snapshots in all, one time average per run", st.nruns,
                 st.nused);
    else if (o->every)
        snprintf(window, sizeof window, "t = %.9g .. %.9g s, %zu snapshots, one profile per %zu snapshots",
                 st.tsel0, st.tsel1, st.nused, o->every);
    else if (o->window > 0)
        snprintf(window, sizeof window, "t = %.9g .. %.9g s, %zu snapshots, one profile per %.9g s", st.tsel0,
                 st.tsel1, st.nused, o->window);
    else
        snprintf(window, sizeof window, "t = %.9g .. %.9g s, %zu snapshots", st.tsel0, st.tsel1, st.nused);
    if (!rc) {
        if (st.nout && o->log)
            fprintf(o->log,
                    "note: %zu particle-snapshots outside the grid: only their kernel tails inside are "
                    "counted\n",
                    st.nout);
        if (st.nrepeat && o->log)
            fprintf(o->log, "note: skipped %zu snapshots whose step was already read\n", st.nrepeat);
        const cg2d_output out = {.o = o,
                                 .g = &st.g,
                                 .r = &st.r,
                                 .kernel = cg_kernel_name(st.k),
                                 .inputs = inputs,
                                 .window = window,
                                 .width = st.width,
                                 .d = st.dcount > 0 ? st.dsum / st.dcount : st.width,
                                 .length_y = st.length_y,
                                 .nread = st.nread,
                                 .nused = st.nused,
                                 .nout = st.nout,
                                 .nruns = st.nruns};
        int wrote_h5 = 0;
        if (o->out && !(rc = cg2d_output_h5(&out, err)))
            wrote_h5 = 1;
        if (!rc && o->csv)
            rc = cg2d_output_csv(&out, err);
        if (rc && wrote_h5) {
            char xdmf[EKM_ATOMIC_PATH_MAX + 8];
            ekm_xdmf_path(o->out, xdmf, sizeof xdmf);
            unlink(o->out); /* no partial results if the CSV failed */
            unlink(xdmf);
        }
        if (!rc && o->log)
            fprintf(o->log,
                    "ekmcompare cg --axes x,z: %zu of %zu snapshots%s, %zu window(s) x %zu x %zu cells (%s, "
                    "width %.4g m, dx %.4g m, dz %.4g m) -> %s%s%s\n",
                    st.nused, st.nread, o->ensemble ? " (ensemble)" : "", st.r.nt, st.g.gx.n, st.g.gz.n,
                    cg_kernel_name(st.k), st.width, st.g.gx.dz, st.g.gz.dz, o->out ? o->out : "",
                    o->out && o->csv ? ", " : "", o->csv ? o->csv : "");
    }
    free(inputs);
    cg_kernel_free(st.k);
    cg2d_profile_free(st.prof);
    cg_blocks_free(st.b);
    free(st.prim);
    free(st.mean);
    free(st.fld);
    free(st.bf);
    free(st.series);
    free(st.work);
    free(st.runs);
    free(st.run_t);
    results_free(&st.r);
    return rc;
}
