/* cg_run.c: the `ekmcompare cg` pipeline (see cg_run.h): the
 * grid, and the loop over the selected snapshots; the steps are in
 * cg_input.c (dumps -> particles), contacts.c (pair dumps), steadiness.c
 * (--steady), window.c (averaging windows) and cg_output.c (writers). */
#include "cg_run.h"

#include "xdmf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "atomic.h"
#include "cg2d_run.h"
#include "cg_input.h"
#include "cg_output.h"
#include "kernel.h"
#include "steadiness.h"
#include "window.h"

#define CG_MAX_BINS 1e7 /* most bins of a grid sized by dz */

static ekm_status make_grid(const cg_run_opts *o, const cg_input *src, double width, cg_grid *g,
                            ekm_error *err)
{
    g->lo = o->have_range ? o->range_lo : src->lo;
    g->hi = o->have_range ? o->range_hi : src->hi;
    if (!(g->hi > g->lo))
        return EKM_FAIL(err, EKM_EUSAGE, "--range: expected lo < hi, got %g:%g", g->lo, g->hi);
    g->axis = o->axis;
    g->periodic = src->periodic && !o->have_range;
    g->reflect = !src->periodic && !o->have_range;
    double L = g->hi - g->lo;
    if (o->bins > 0)
        g->n = o->bins;
    else {
        double dz = o->dz > 0 ? o->dz : 0.5 * width;
        if (!(dz > 0))
            return EKM_FAIL(err, EKM_EUSAGE, "%s: no particles to size the grid: give --bins or --dz",
                            src->snap.where);
        double nb = ceil(L / dz - 1e-9);
        if (nb < 1)
            nb = 1;
        if (nb > CG_MAX_BINS && o->dz > 0)
            return EKM_FAIL(err, EKM_EUSAGE, "--dz: expected at most 1e7 bins, got %.3g", nb);
        if (nb > CG_MAX_BINS && o->have_range)
            return EKM_FAIL(err, EKM_EUSAGE,
                            "--range: expected at most 1e7 bins of dz = %.4g m (half the kernel width), got "
                            "%.3g: give --bins or --dz",
                            dz, nb);
        if (nb > CG_MAX_BINS) /* the grid is the dump's box, sized by the dump's particles */
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: ITEM: BOX BOUNDS: %c: expected a box the grid can hold (at most 1e7 bins of "
                            "dz = %.4g m, half the %s), got %.6g .. %.6g m (%.3g bins): give --range, --bins "
                            "or --dz",
                            src->snap.box_where[o->axis], "xyz"[o->axis], dz,
                            o -> width > 0 ? "kernel width" : "mean particle diameter", g->lo, g->hi, nb);
        g->n = (size_t)nb;
    }
    g->dz = L / (double)g->n;
    return EKM_OK;
}

ekm_status cg_run(const cg_run_opts *o, ekm_error *err)
{
    if (o->axis2 >= 0)
        return cg2d_run(o, err);
    if (o->ninputs == 0)
        return EKM_FAIL(err, EKM_EUSAGE, "cg: expected at least one dump file");
    if (!o->out && !o->csv)
        return EKM_FAIL(err, EKM_EUSAGE, "cg: expected -o OUT.h5 and/or --csv OUT.csv");
    cg_run_info info;
    memset(&info, 0, sizeof info);
    size_t used = 0;
    for (size_t i = 0; i < o->ninputs && used + 2 < sizeof info.inputs; i++)
        used += (size_t)snprintf(info.inputs + used, sizeof info.inputs - used, "%s%s", i ? "\n" : "",
                                 o->inputs[i]);
    used = 0;
    for (size_t i = 0; i < o->npairs && used + 2 < sizeof info.pairs; i++)
        used +=
            (size_t)snprintf(info.pairs + used, sizeof info.pairs - used, "%s%s", i ? "\n" : "", o->pairs[i]);
    if (o->nstress && o->npairs)
        return EKM_FAIL(err, EKM_EUSAGE,
                        "cg: expected --stress or --pairs, not both (the contact stress would count twice)");
    if (o->npairs && o->npaircols != 9 && o->npaircols != 5)
        return EKM_FAIL(err, EKM_EUSAGE,
                        "--pairs: expected --pair-columns with 9 (x1,y1,z1,x2,y2,z2,fx,fy,fz) "
                        "or 5 (id1,id2,fx,fy,fz) names");
    if (o->nstress)
        snprintf(info.stress, sizeof info.stress, "kinetic + per-atom %s %s %s %s %s %s", o->stress[0],
                 o->stress[1], o->stress[2], o->stress[3], o->stress[4], o->stress[5]);
    else if (o->npairs)
        snprintf(info.stress, sizeof info.stress,
                 "kinetic + contacts from pair dumps (branch line integral), %s",
                 o->npaircols == 9 ? "positions" : "atom ids");
    else
        snprintf(info.stress, sizeof info.stress, "kinetic only");
    ekm_status rc = cg_opts_refuse_inputs(o, err);
    if (rc)
        return rc;
    double t_start = -INFINITY;
    if (o->steady && (rc = cg_steadiness_start(o, &t_start, err)))
        return rc;
    info.steady = o->steady;
    info.t_start = t_start;

    cg_input src;
    cg_input_init(&src, o);
    cg_kernel *k = NULL;
    cg_profile *prof = NULL;
    cg_grid g;
    memset(&g, 0, sizeof g);
    cg_window fz;
    memset(&fz, 0, sizeof fz);
    double *prim = NULL;
    cg_window_results r;
    memset(&r, 0, sizeof r);
    long cur_w = -1;
    double t0 = 0, tw0 = 0, tw1 = 0, tsel0 = 0, tsel1 = 0;
    size_t count = 0, nout = 0;
    while ((rc = cg_input_next(&src, err)) == EKM_OK) {
        if (src.t < t_start)
            continue;
        if (!prof) {
            double width = o->width > 0 ? o->width : (src.dcount > 0 ? src.dsum / src.dcount : 0.0);
            if (!(width > 0) && strcmp(o->kernel, "bins")) {
                rc = EKM_FAIL(err, EKM_EUSAGE, "%s: the first snapshot has no atoms: give --width",
                              src.snap.where);
                break;
            }
            info.width = width;
            if ((rc = make_grid(o, &src, width, &g, err)))
                break;
            if ((rc = cg_kernel_alloc(&k, o->kernel, width, err)))
                break;
            /* a width from the particles (not --width) too wide for the box
             * is the dump's error */
            if (!(o->width > 0) && (g.periodic || g.reflect) && k->type != CG_KERNEL_BINS &&
                k->cutoff > g.hi - g.lo) {
                rc = EKM_FAIL(err, EKM_EINPUT,
                              "%s: the mean particle diameter %.6g m (the kernel width: --width not given) "
                              "gives a kernel support of %.6g m, longer than the box along %c (%.6g m): "
                              "expected particles much smaller than the box, or give --width",
                              src.snap.where, width, k->cutoff, "xyz"[o->axis], g.hi - g.lo);
                break;
            }
            if ((rc = cg_profile_alloc(&prof, k, &g, o->tmode, o->exact, err)))
                break;
            if ((rc = cg_window_alloc(&fz, &g, err)))
                break;
            prim = malloc(CG_NPRIM * g.n * sizeof(double));
            r.n = g.n;
            if (!prim) {
                rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
                break;
            }
            info.area = src.pt.area;
            info.wall = g.periodic ? "periodic" : g.reflect ? "walls: kernel reflected" : "open (--range)";
            t0 = src.t;
            tsel0 = src.t;
        }
        long wi = o->every        ? (long)(count / o->every)
                  : o->window > 0 ? (long)floor((src.t - t0) / o->window)
                                  : 0;
        if (wi != cur_w && cur_w >= 0) {
            double d = src.dcount > 0 ? src.dsum / src.dcount : info.width;
            if ((rc = cg_window_finish(&fz, &r, 0.5 * (tw0 + tw1), d, o->rho_p, err)))
                break;
        }
        if (wi != cur_w) {
            cur_w = wi;
            tw0 = src.t;
        }
        tw1 = src.t;
        tsel1 = src.t;
        if ((rc = cg_profile_snapshot(prof, &src.pt, prim, err)))
            break;
        if (!g.periodic)
            for (size_t i = 0; i < src.pt.n; i++)
                nout += (src.pt.s[i] < g.lo || src.pt.s[i] > g.hi);
        cg_window_add(&fz, prim);
        count++;
    }
    if (rc == EKM_EOF) {
        rc = EKM_OK;
        if (count == 0)
            rc = EKM_FAIL(err, EKM_EINPUT, "%s: no snapshots selected (%zu read)", o->inputs[0], src.nread);
    }
    info.d = src.dcount > 0 ? src.dsum / src.dcount : info.width;
    if (!rc)
        rc = cg_window_finish(&fz, &r, 0.5 * (tw0 + tw1), info.d, o->rho_p, err);
    info.nread = src.nread;
    info.nused = count;
    if (!rc) {
        if (o->every)
            snprintf(info.window, sizeof info.window,
                     "t = %.9g .. %.9g s, %zu snapshots, one profile per %zu snapshots", tsel0, tsel1, count,
                     o->every);
        else if (o->window > 0)
            snprintf(info.window, sizeof info.window,
                     "t = %.9g .. %.9g s, %zu snapshots, one profile per %.9g s", tsel0, tsel1, count,
                     o->window);
        else
            snprintf(info.window, sizeof info.window, "t = %.9g .. %.9g s, %zu snapshots", tsel0, tsel1,
                     count);
        info.nout = nout;
        if (nout && o->log)
            fprintf(o->log,
                    "note: %zu particle-snapshots outside the grid [%.6g, %.6g] m (a shrink-wrapped box, or "
                    "--range): only their kernel tails inside are counted\n",
                    nout, g.lo, g.hi);
        if (src.nrepeat && o->log)
            fprintf(o->log, "note: skipped %zu snapshots whose step was already read\n", src.nrepeat);
        int wrote_h5 = 0;
        if (o->out && !(rc = cg_output_h5(o, &g, &r, k, &info, err)))
            wrote_h5 = 1;
        if (!rc && o->csv)
            rc = cg_output_csv(o, &g, &r, err);
        if (rc && wrote_h5)
            unlink(o->out); /* no partial results if the CSV failed */
        if (!rc && o->log)
            fprintf(o->log,
                    "ekmcompare cg: %zu of %zu snapshots, %zu profile(s) x %zu bins (%s, width %.4g m, "
                    "dz %.4g m) -> %s%s%s\n",
                    count, src.nread, r.nt, g.n, k ? cg_kernel_name(k) : "?", info.width, g.dz,
                    o->out ? o->out : "", o->out && o->csv ? ", " : "", o->csv ? o->csv : "");
    }
    cg_input_close(&src);
    cg_kernel_free(k);
    cg_profile_free(prof);
    cg_window_free(&fz);
    free(prim);
    cg_window_results_free(&r);
    return rc;
}
