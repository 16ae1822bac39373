#include "steady_cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "bc.h"
#include "cli_args.h"
#include "closure.h"
#include "h5.h"
#include "h5out.h"
#include "local_slab.h"
#include "scenario.h"
#include "steady_solve.h"
#include "xdmf.h"

static int steady_fail(const ekm_error *err, ekm_status st)
{
    ekm_error_print("ekm steady", err);
    return ekm_status_exit_code(st);
}

/* The last row of a [nt][n] dataset into out (n values). */
static ekm_status last_row(ekm_h5_file *f, const char *path, const char *name, int n, double *out,
                           ekm_error *err)
{
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    double *data = NULL;
    ekm_status st = ekm_h5_read_double(f, name, &rank, dims, &data, err);
    if (st != EKM_OK)
        return st;
    if (rank != 2 || dims[0] < 1 || dims[1] != (size_t)n) {
        free(data);
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: /%s has %s%zu cells, the scenario %d ([domain] cells): --from needs a run "
                        "on the same grid",
                        path, name, rank == 2 ? "" : "not [t][z] rows of ", rank == 2 ? dims[1] : 0, n);
    }
    memcpy(out, data + (dims[0] - 1) * dims[1], (size_t)n * sizeof *out);
    free(data);
    return EKM_OK;
}

ekm_status ekm_steady_read_guess(const char *path, const ekm_scenario *sc, ekm_state *s, ekm_error *err)
{
    ekm_h5_file *f = NULL;
    ekm_status st = ekm_h5_open(&f, path, err);
    if (st != EKM_OK)
        return st;
    const int n = sc->cells;
    int rank;
    size_t dims[EKM_H5_MAX_RANK];
    double *z = NULL;
    st = ekm_h5_read_double(f, "z", &rank, dims, &z, err);
    /* /z: the centres of every frame, [nt][nz]; an output written before
     * /z had a row per frame: [nz], the first frame's */
    const size_t cells = rank == 2 ? dims[1] : rank == 1 ? dims[0] : 0;
    if (st == EKM_OK && (rank > 2 || (rank == 2 && dims[0] < 1) || cells != (size_t)n))
        st = EKM_FAIL(err, EKM_EINPUT,
                      "%s: /z has %zu cells, the scenario %d ([domain] cells): --from needs a run on the "
                      "same grid",
                      path, cells, n);
    if (st == EKM_OK && !ekm_boundary_pressure_wall(&sc->top)) {
        /* a fixed grid: the centres of the scenario's cells (the last frame's) */
        const double dz = sc->length / n;
        const double *zl = rank == 2 ? z + (dims[0] - 1) * dims[1] : z;
        for (int j = 0; j < n && st == EKM_OK; j++)
            if (!(fabs(zl[j] - (j + 0.5) * dz) <= 1e-9 * dz))
                st = EKM_FAIL(err, EKM_EINPUT,
                              "%s: /z[%d] = %.9g m, the scenario's cell centre is %.9g m ([domain] length = "
                              "%g m): --from needs a run on the same grid",
                              path, j, zl[j], (j + 0.5) * dz, sc->length);
    }
    double gap = NAN;
    if (st == EKM_OK && ekm_boundary_pressure_wall(&sc->top)) {
        /* the gap of the last frame (a pressure wall stretches the grid) */
        double *g = NULL;
        st = ekm_h5_read_double(f, "gap", &rank, dims, &g, err);
        if (st == EKM_OK && (rank != 1 || dims[0] < 1 || !(g[dims[0] - 1] > 0.0)))
            st = EKM_FAIL(err, EKM_EINPUT, "%s: /gap: expected the gap of every frame (> 0) [m]", path);
        if (st == EKM_OK)
            gap = g[dims[0] - 1];
        free(g);
    }
    free(z);
    if (st == EKM_OK)
        st = last_row(f, path, "phi", n, s->phi, err);
    if (st == EKM_OK)
        st = last_row(f, path, "vx", n, s->u, err);
    if (st == EKM_OK)
        st = last_row(f, path, "T", n, s->T, err);
    ekm_h5_close(f);
    if (st != EKM_OK)
        return st;
    if (!isnan(gap))
        s->dz = gap / n;
    for (int j = 0; j < n; j++) {
        s->z[j] = (j + 0.5) * s->dz;
        if (!(s->phi[j] >= 0.0 && s->phi[j] < sc->material.phi_cp) || !isfinite(s->u[j]) ||
            !(s->T[j] >= 0.0 && isfinite(s->T[j])))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: the last frame's cell %d has phi = %g, vx = %g, T = %g: expected phi in [0, "
                            "%g), finite vx, finite T >= 0",
                            path, j, s->phi[j], s->u[j], s->T[j], sc->material.phi_cp);
    }
    memset(s->w, 0, ((size_t)n + 1) * sizeof *s->w);
    return EKM_OK;
}

/* The output: one frame with the report as root attributes. */
static ekm_status write_output(const char *out, const ekm_scenario *sc, const ekm_state *s,
                               const ekm_steady_report *rep, double mass_initial, ekm_error *err)
{
    /* the time steps taken: the warm-up between Newton attempts and the
     * verification (as ekm run's stats.*, which ekmcompare reads to know an
     * ekm output) */
    const double steps = (double)rep->warm_steps + rep->verify_steps;
    ekm_h5_writer *w = NULL;
    ekm_status st = ekm_h5_writer_open(&w, out, sc, s, err);
    if (st != EKM_OK)
        return st;
    st = ekm_h5_writer_append(w, s, err);
    const struct {
        const char *name;
        double value;
    } attrs[] = {
        {"steady", 1.0},
        {"steady_solver", 1.0},
        {"steady.iterations", (double)rep->iterations},
        {"steady.dry_resolves", (double)rep->dry_resolves},
        {"steady.attempts", (double)rep->attempts},
        {"steady.local_guess", (double)rep->local_guess},
        {"steady.warm_time", rep->warm_time},
        {"steady.warm_steps", (double)rep->warm_steps},
        {"steady.residual_final", rep->residual_final},
        {"steady.update_final", rep->update_final},
        {"steady.verify_change", rep->verify_change},
        {"steady.verify_time", rep->verify_time},
        {"steady.verify_steps", (double)rep->verify_steps},
        {"steady.verify_phi", rep->verify_field[0]},
        {"steady.verify_vx", rep->verify_field[1]},
        {"steady.verify_T", rep->verify_field[2]},
        {"steady.verify_w", rep->verify_field[3]},
        {"steady.verify_gap", rep->verify_field[4]},
        {"stats.wall_time_s", rep->wall_s},
        {"stats.steps", steps},
        {"stats.cell_updates", steps * s->n},
        {"stats.mass_initial", mass_initial},
        {"stats.mass_final", ekm_state_mass(s, sc->material.rho_p)},
        {"stats.mass_in", 0.0},
        {"steady_drift", rep->verify_time > 0.0 ? rep->verify_change / rep->verify_time : 0.0},
    };
    for (size_t i = 0; i < sizeof attrs / sizeof attrs[0] && st == EKM_OK; i++)
        st = ekm_h5_writer_set_attr(w, attrs[i].name, attrs[i].value, err);
    if (st == EKM_OK)
        st = ekm_h5_writer_set_attr_array(w, "steady.residual", rep->residual, (size_t)rep->iterations, err);
    if (st == EKM_OK)
        st = ekm_h5_writer_set_attr_array(w, "steady.delta", rep->delta, (size_t)rep->iterations, err);
    if (st == EKM_OK && ekm_boundary_pressure_wall(&sc->top))
        st = ekm_h5_writer_set_attr(w, "gap_final", rep->gap, err);
    if (st == EKM_OK)
        return ekm_h5_writer_commit(w, err);
    ekm_h5_writer_abort(w);
    return st;
}

/* ekm steady of a local rheology (mu_i): the slab solver's steady solve
 * (local_slab.h), one frame with its report; the same exit codes. */
static int steady_local(const char *out, const char *from, int quiet, const ekm_scenario *sc)
{
    ekm_error err = {0};
    ekm_state *s = ekm_state_alloc(sc->cells, sc->length);
    ekm_local_slab *ls = s ? ekm_local_slab_alloc(sc, &err) : NULL;
    ekm_status st = EKM_OK;
    if (!s)
        st = EKM_FAIL(&err, EKM_ENOMEM, "out of memory (%d cells)", sc->cells);
    else if (!ls)
        st = err.code;
    if (st == EKM_OK)
        st = ekm_local_slab_init(ls, s, &err);
    if (st == EKM_OK && from)
        st = EKM_FAIL(&err, EKM_EUSAGE,
                      "--from: closure %s's steady solve starts from the scenario's initial state (its "
                      "continuation needs no guess)",
                      sc->closure->name);
    ekm_local_slab_steady_report rep;
    const double mass_initial = st == EKM_OK ? ekm_local_slab_mass(sc, s) : 0.0;
    if (st == EKM_OK)
        st = ekm_local_slab_steady(ls, s, &rep, &err);
    ekm_h5_writer *w = NULL;
    if (st == EKM_OK)
        st = ekm_h5_writer_open(&w, out, sc, s, &err);
    if (st == EKM_OK) {
        st = ekm_h5_writer_append(w, s, &err);
        const double steps = (double)rep.warm_steps + rep.verify_steps;
        const struct {
            const char *name;
            double value;
        } attrs[] = {
            {"steady", 1.0},
            {"steady_solver", 1.0},
            {"steady.attempts", (double)rep.attempts},
            {"steady.warm_time", rep.warm_time},
            {"steady.warm_steps", (double)rep.warm_steps},
            {"steady.verify_change", rep.verify_change},
            {"steady.verify_time", rep.verify_time},
            {"steady.verify_steps", (double)rep.verify_steps},
            {"stats.wall_time_s", rep.wall_s},
            {"stats.steps", steps},
            {"stats.cell_updates", steps * s->n},
            {"stats.mass_initial", mass_initial},
            {"stats.mass_final", ekm_local_slab_mass(sc, s)},
            {"stats.mass_in", 0.0},
            {"steady_drift", rep.verify_time > 0.0 ? rep.verify_change / rep.verify_time : 0.0},
            {"local.beyond_cells_max", (double)ekm_local_slab_beyond_max(ls)},
        };
        for (size_t i = 0; i < sizeof attrs / sizeof attrs[0] && st == EKM_OK; i++)
            st = ekm_h5_writer_set_attr(w, attrs[i].name, attrs[i].value, &err);
        if (st == EKM_OK && ekm_boundary_pressure_wall(&sc->top))
            st = ekm_h5_writer_set_attr(w, "gap_final", s->n * s->dz, &err);
        if (st == EKM_OK)
            st = ekm_h5_writer_commit(w, &err);
        else
            ekm_h5_writer_abort(w);
    }
    int code = 0;
    if (st != EKM_OK)
        code = steady_fail(&err, st);
    else if (!quiet)
        printf(
            "%-20s steady  closure %s: %d Newton solves (%.3g s of model time stepped, %ld steps)  verified "
            "over %d steps (max change %.1e)  %5d cells  %.4f s  -> %s\n",
            sc->name, sc->closure->name, rep.attempts, rep.warm_time, rep.warm_steps, rep.verify_steps,
            rep.verify_change, sc->cells, rep.wall_s, out);
    ekm_local_slab_free(ls);
    ekm_state_free(s);
    return code;
}

int ekm_steady_cli_main(int argc, char **argv)
{
    ekm_cli_args args;
    const int usage = ekm_cli_args_parse("steady", argc, argv, 1, 0, &args);
    if (usage) {
        ekm_cli_args_free(&args);
        return usage;
    }
    const char *ini = args.ini, *out = args.out, *material = args.material, *from = args.from;
    const int quiet = args.quiet;
    const char **sets = args.sets; /* freed below (free(sets)) */
    const size_t n_sets = args.n_sets;
    ekm_error err = {0};
    ekm_status st = ekm_cli_args_check_outputs(&args, &err);
    if (st != EKM_OK) {
        free(sets);
        return steady_fail(&err, st);
    }
    ekm_scenario sc;
    st = ekm_scenario_load_material(&sc, ini, material, sets, n_sets, &err);
    free(sets);
    if (st == EKM_OK)
        st = ekm_scenario_require_1d(&sc, "ekm steady solves the 1D column only (cells_x = 1)", &err);
    if (st == EKM_OK && ekm_local_slab_applies(&sc)) {
        const int code = steady_local(out, from, quiet, &sc);
        ekm_scenario_free(&sc);
        return code;
    }
    if (st == EKM_OK)
        st = ekm_steady_supported(&sc, &err);
    if (st != EKM_OK) {
        ekm_scenario_free(&sc);
        return steady_fail(&err, st);
    }
    ekm_state *s = ekm_state_alloc(sc.cells, sc.length);
    if (!s) {
        ekm_scenario_free(&sc);
        EKM_FAIL(&err, EKM_ENOMEM, "out of memory (%d cells)", sc.cells);
        return steady_fail(&err, EKM_ENOMEM);
    }
    ekm_state_init(s, &sc);
    if (from)
        st = ekm_steady_read_guess(from, &sc, s, &err);
    ekm_steady_report rep = {.progress = quiet ? NULL : stderr};
    const double mass_initial = ekm_state_mass(s, sc.material.rho_p);
    if (st == EKM_OK)
        st = ekm_steady_solve(&sc, s, &rep, &err);
    if (st == EKM_OK)
        st = write_output(out, &sc, s, &rep, mass_initial, &err);
    int code = 0;
    if (st != EKM_OK)
        code = steady_fail(&err, st);
    else if (!quiet) {
        char gap[64] = "";
        if (ekm_boundary_pressure_wall(&sc.top))
            snprintf(gap, sizeof gap, "  gap %.9g m", rep.gap);
        printf(
            "%-20s steady  %3d Newton iterations in %d attempts (%.3g s of model time stepped, %ld steps)  "
            "residual %.1e  verified over %d steps (max change %.1e)  %5d cells%s  %.4f s  -> %s\n",
            sc.name, rep.iterations, rep.attempts, rep.warm_time, rep.warm_steps, rep.residual_final,
            rep.verify_steps, rep.verify_change, sc.cells, gap, rep.wall_s, out);
    }
    ekm_state_free(s);
    ekm_scenario_free(&sc);
    return code;
}
