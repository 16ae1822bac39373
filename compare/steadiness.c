/* steadiness.c: the drift criterion, MSER-5 and the steady start of
 * `cg --steady` (see steadiness.h). */
#include "steadiness.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cg_input.h"

#define MSER_BATCH 5 /* MSER batch size [snapshots] */

cg_steadiness_verdict cg_steadiness_drift(const double *v, size_t n, double tol)
{
    cg_steadiness_verdict r;
    memset(&r, 0, sizeof r);
    r.samples = n;
    r.tol = tol;
    if (n < CG_STEADINESS_MIN_SAMPLES)
        return r;
    size_t q = n / 4;
    double a = 0, b = 0;
    for (size_t i = n - 2 * q; i < n - q; i++)
        a += v[i];
    for (size_t i = n - q; i < n; i++)
        b += v[i];
    a /= (double)q;
    b /= (double)q;
    double s = (a < 0 ? -a : a) + (b < 0 ? -b : b);
    double drift = 0.0;
    if (s != 0) {
        double dd = (b - a) / (0.5 * s);
        /* the verdict is on the number as printed with 4 digits (run.sh
         * compared its printed drift with the tolerance) */
        char buf[64];
        snprintf(buf, sizeof buf, "%.4g", dd < 0 ? -dd : dd);
        drift = strtod(buf, NULL);
    }
    r.known = 1;
    r.drift = drift;
    r.steady = drift <= tol;
    return r;
}

size_t cg_steadiness_mser(const double *x, size_t n)
{
    size_t nb = n / MSER_BATCH;
    if (nb < 2)
        return 0;
    size_t best_d = 0;
    double best = INFINITY;
    for (size_t d = 0; d <= nb / 2; d++) {
        double sum = 0.0;
        for (size_t j = d; j < nb; j++) {
            double y = 0.0;
            for (size_t i = 0; i < MSER_BATCH; i++)
                y += x[j * MSER_BATCH + i];
            sum += y / MSER_BATCH;
        }
        double mean = sum / (double)(nb - d), ss = 0.0;
        for (size_t j = d; j < nb; j++) {
            double y = 0.0;
            for (size_t i = 0; i < MSER_BATCH; i++)
                y += x[j * MSER_BATCH + i];
            y /= MSER_BATCH;
            ss += (y - mean) * (y - mean);
        }
        double v = ss / ((double)(nb - d) * (double)(nb - d));
        if (v < best * (1.0 - 1e-12)) {
            best = v;
            best_d = d;
        }
    }
    return best_d * MSER_BATCH;
}

static ekm_status push(double **a, size_t *n, size_t *cap, double v, ekm_error *err)
{
    if (*n == *cap) {
        size_t c = *cap ? 2 * *cap : 256;
        double *p = realloc(*a, c * sizeof *p);
        if (!p)
            return EKM_FAIL(err, EKM_ENOMEM, "out of memory");
        *a = p;
        *cap = c;
    }
    (*a)[(*n)++] = v;
    return EKM_OK;
}

ekm_status cg_steadiness_start(const cg_run_opts *o, double *t_start, ekm_error *err)
{
    cg_input src;
    cg_input_init(&src, o);
    src.skip_pairs = 1;
    double *ke = NULL, *com = NULL, *ts = NULL;
    size_t nke = 0, ncom = 0, nts = 0, cke = 0, ccom = 0, cts = 0;
    ekm_status rc;
    int periodic = 0;
    while ((rc = cg_input_next(&src, err)) == EKM_OK) {
        const cg_particles *pt = &src.pt;
        double msum = 0, e = 0, c = 0;
        for (size_t i = 0; i < pt->n; i++) {
            const double *v = pt->v + 3 * i;
            msum += pt->m[i];
            e += pt->m[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            c += pt->m[i] * pt->s[i];
        }
        periodic = src.periodic;
        if ((rc = push(&ke, &nke, &cke, msum > 0 ? e / msum : 0.0, err)) ||
            (rc = push(&com, &ncom, &ccom, msum > 0 ? c / msum : 0.0, err)) ||
            (rc = push(&ts, &nts, &cts, src.t, err)))
            break;
    }
    cg_input_close(&src);
    if (rc == EKM_EOF) {
        rc = EKM_OK;
        if (nts == 0) {
            rc = EKM_FAIL(err, EKM_EINPUT, "%s: no snapshots selected", o->inputs[0]);
        } else {
            size_t k = cg_steadiness_mser(ke, nke);
            if (!periodic) {
                size_t k2 = cg_steadiness_mser(com, ncom);
                if (k2 > k)
                    k = k2;
            }
            *t_start = ts[k];
            if (o->log) {
                if (nts < 10)
                    fprintf(o->log, "note: --steady: only %zu snapshots, using all of them\n", nts);
                else
                    fprintf(
                        o->log,
                        "note: --steady: steady window starts at t = %.9g s (snapshot %zu of %zu, MSER-5)\n",
                        ts[k], k + 1, nts);
                if (nts >= 10 && k >= (nts / 5 / 2) * 5)
                    fprintf(o->log,
                            "warning: --steady: the start is the latest MSER-5 allows (half the selection): "
                            "the run may not be steady yet, or is too short to tell; check with --every or "
                            "give --from\n");
            }
        }
    }
    free(ke);
    free(com);
    free(ts);
    return rc;
}

/* A monitor line's fields: up to max pointers to blank-separated tokens
 * (NUL-terminated in place); returns the number of fields. */
static size_t split_fields(char *line, char **field, size_t max)
{
    size_t nf = 0;
    char *p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t')
            p++;
        if (!*p)
            return nf;
        char *start = p;
        while (*p && *p != ' ' && *p != '\t')
            p++;
        if (nf < max)
            field[nf] = start;
        nf++;
        if (!*p)
            return nf;
        *p++ = '\0';
    }
}

ekm_status cg_steadiness_monitor_read(const char *path, int column, double **v, size_t *n, ekm_error *err)
{
    *v = NULL;
    *n = 0;
    if (column < 1)
        return EKM_FAIL(err, EKM_EUSAGE, "--column: expected a column number >= 1, got %d", column);
    char *field[64];
    if ((size_t)column > sizeof field / sizeof *field)
        return EKM_FAIL(err, EKM_EUSAGE, "--column: expected at most %zu, got %d",
                        sizeof field / sizeof *field, column);
    FILE *fp = fopen(path, "r");
    if (!fp)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: %s", path, strerror(errno));
    char *line = NULL;
    size_t lcap = 0, cap = 0, need = column > 2 ? (size_t)column : 2;
    long lineno = 0;
    ekm_status rc = EKM_OK;
    while (!rc) {
        errno = 0;
        ssize_t len = getline(&line, &lcap, fp);
        if (len < 0) {
            if (ferror(fp))
                rc = EKM_FAIL(err, EKM_EIO, "%s: cannot read: %s", path, strerror(errno));
            break;
        }
        lineno++;
        while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r'))
            line[--len] = '\0';
        if (line[0] == '#')
            continue;
        size_t nf = split_fields(line, field, sizeof field / sizeof *field);
        if (nf < 2)
            continue;    /* not a data line (blank, or one field: run.sh's awk NF >= 2) */
        if (nf < need) { /* a data line without the column: bad input, not "no samples" */
            rc = EKM_FAIL_AT(err, EKM_EINPUT, path, lineno > INT_MAX ? 0 : (int)lineno,
                             "column %d: missing (expected at least %zu columns, got %zu)", column, need, nf);
            break;
        }
        const char *tok = field[column - 1];
        char *end;
        double x = strtod(tok, &end);
        if (end == tok || *end || !isfinite(x)) {
            rc = EKM_FAIL_AT(err, EKM_EINPUT, path, lineno > INT_MAX ? 0 : (int)lineno,
                             "column %d: expected a finite number, got '%s'", column, tok);
            break;
        }
        if (*n == cap) {
            size_t c = cap ? 2 * cap : 256;
            double *p = realloc(*v, c * sizeof *p);
            if (!p) {
                rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
                break;
            }
            *v = p;
            cap = c;
        }
        (*v)[(*n)++] = x;
    }
    free(line);
    fclose(fp);
    if (rc) {
        free(*v);
        *v = NULL;
        *n = 0;
    }
    return rc;
}
