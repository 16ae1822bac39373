/* agree_cli.c: `ekm agree NEWTON.h5 RUN.h5 [--tol X]` (agree_cli.h). */
#include "agree_cli.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "h5.h"
#include "point.h"
#include "status.h"

/* The last frame of one ekm output: phi, vx, T, P and the gap. */
typedef struct {
    double *field[4]; /* phi, vx, T, P: n each */
    size_t n;
    double gap; /* NAN: no /gap */
    double steady;
} agree_state;

static const char *const AGREE_FIELDS[4] = {"phi", "vx", "T", "P"};

static void agree_state_free(agree_state *a)
{
    for (int f = 0; f < 4; f++)
        free(a->field[f]);
}

static ekm_status agree_read(const char *path, agree_state *a, ekm_error *err)
{
    *a = (agree_state){.gap = NAN, .steady = NAN};
    ekm_h5_file *h = NULL;
    ekm_status st = ekm_h5_open(&h, path, err);
    for (int f = 0; st == EKM_OK && f < 4; f++) {
        int rank = 0;
        size_t dims[EKM_H5_MAX_RANK] = {0};
        double *data = NULL;
        st = ekm_h5_read_double(h, AGREE_FIELDS[f], &rank, dims, &data, err);
        if (st == EKM_OK && (rank != 2 || dims[0] == 0 || dims[1] == 0 || (f > 0 && dims[1] != a->n))) {
            free(data);
            st = EKM_FAIL(err, EKM_EINPUT, "%s: /%s: expected [frames][cells] of an ekm output", path,
                          AGREE_FIELDS[f]);
        }
        if (st == EKM_OK) {
            a->n = dims[1];
            a->field[f] = malloc(a->n * sizeof(double));
            if (!a->field[f])
                st = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
            else
                memcpy(a->field[f], data + (dims[0] - 1) * a->n, a->n * sizeof(double));
            free(data);
        }
    }
    if (st == EKM_OK && ekm_h5_exists(h, "gap")) {
        int rank = 0;
        size_t dims[EKM_H5_MAX_RANK] = {0};
        double *data = NULL;
        st = ekm_h5_read_double(h, "gap", &rank, dims, &data, err);
        if (st == EKM_OK && (rank != 1 || dims[0] == 0))
            st = EKM_FAIL(err, EKM_EINPUT, "%s: /gap: expected one value per frame", path);
        if (st == EKM_OK)
            a->gap = data[dims[0] - 1];
        free(data);
    }
    if (st == EKM_OK && ekm_h5_attr_get_double(h, "/", "steady", &a->steady, NULL) != EKM_OK)
        a->steady = NAN; /* an output of a run that was not to stop when steady */
    if (h)
        ekm_h5_close(h);
    return st;
}

int ekm_agree_cli_main(int argc, char **argv)
{
    const char *paths[2] = {NULL, NULL};
    double tol = EKM_POINT_AGREE_TOL;
    int np = 0;
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--tol") == 0 && i + 1 < argc) {
            char *end = NULL;
            errno = 0;
            tol = strtod(argv[++i], &end);
            if (end == argv[i] || *end || errno == ERANGE || !(tol >= 0.0) || !isfinite(tol)) {
                fprintf(stderr, "ekm agree: --tol '%s': expected a number >= 0\n", argv[i]);
                return ekm_status_exit_code(EKM_EUSAGE);
            }
        } else if (argv[i][0] == '-' || np == 2) {
            fprintf(stderr, "ekm agree: unexpected argument '%s' (see ekm --help)\n", argv[i]);
            return ekm_status_exit_code(EKM_EUSAGE);
        } else {
            paths[np++] = argv[i];
        }
    }
    if (np != 2) {
        fprintf(stderr, "ekm agree: expected NEWTON.h5 RUN.h5 (see ekm --help)\n");
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    ekm_error err = {0};
    agree_state a, b;
    ekm_status st = agree_read(paths[0], &a, &err);
    if (st == EKM_OK) {
        st = agree_read(paths[1], &b, &err);
        if (st == EKM_OK && b.n != a.n)
            st = EKM_FAIL(&err, EKM_EINPUT, "%s: %zu cells, %s: %zu: not the same grid", paths[0], a.n,
                          paths[1], b.n);
        if (st == EKM_OK) {
            const ekm_point_view va = {a.n, a.field[0], a.field[1], a.field[2], a.field[3], a.gap};
            const ekm_point_view vb = {b.n, b.field[0], b.field[1], b.field[2], b.field[3], b.gap};
            const char *where = "";
            const double d = ekm_point_agreement(&va, &vb, &where);
            int code = 0;
            if (b.steady != 1.0) {
                if (isnan(b.steady))
                    printf("disagree: the time-stepped run was not one to stop when steady (no attribute "
                           "steady)\n");
                else
                    printf("disagree: the time-stepped run did not end steady (steady = %g)\n", b.steady);
                code = ekm_status_exit_code(EKM_ENOTSTEADY);
            } else {
                const int ok = d <= tol;
                printf("%s: largest difference %.3g of the run's maximum (%s; tolerance %g)\n",
                       ok ? "agree" : "disagree", d, where, tol);
                code = ok ? 0 : ekm_status_exit_code(EKM_ENOTSTEADY);
            }
            agree_state_free(&a);
            agree_state_free(&b);
            return code;
        }
        agree_state_free(&b);
    }
    agree_state_free(&a);
    ekm_error_print("ekm", &err);
    return ekm_status_exit_code(st);
}
