/* score.c: the EKM against coarse-grained DEM (see score.h). */
#include "ekm_version.h"
#include "score.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "atomic.h"
#include "h5.h"
#include "metric.h"
#include "schema.h"

#define MAXF 16
static const char *const default_fields[] = {"phi", "vx", "vz", "T", "P", "sxz", "szz"};

cg_score_opts cg_score_opts_default(void)
{
  cg_score_opts o;
  memset(&o, 0, sizeof o);
  return o;
}

/* Linear interpolation in a sorted array x[0..n-1]: index i and fraction a
 * with x[i] + a (x[i+1]-x[i]) = v. Returns 0 if v is outside [x0, x_n-1]. */
static int locate(const double *x, size_t n, double v, size_t *i, double *a)
{
  if (n == 0 || !(v >= x[0] - 1e-12 * fabs(x[0])) || !(v <= x[n - 1] + 1e-12 * fabs(x[n - 1])))
    return 0;
  if (n == 1) { *i = 0; *a = 0.0; return 1; }
  size_t lo = 0, hi = n - 1;
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (x[mid] <= v) lo = mid; else hi = mid;
  }
  *i = lo;
  double dx = x[lo + 1] - x[lo];
  *a = dx > 0 ? (v - x[lo]) / dx : 0.0;
  if (*a < 0) *a = 0;
  if (*a > 1) *a = 1;
  return 1;
}

static int increasing(const double *x, size_t n)
{
  for (size_t i = 1; i < n; i++)
    if (!(x[i] > x[i - 1])) return 0;
  return 1;
}

static void json_num(FILE *fp, double v)
{
  if (isfinite(v)) fprintf(fp, "%.9g", v);
  else fputs("null", fp);
}

/* A number that reads back to the same double (an option to be reused). */
static void json_exact(FILE *fp, double v)
{
  char buf[32];
  if (!isfinite(v)) { fputs("null", fp); return; }
  snprintf(buf, sizeof buf, "%.15g", v);
  if (strtod(buf, NULL) != v) snprintf(buf, sizeof buf, "%.17g", v);
  fputs(buf, fp);
}

static void json_str(FILE *fp, const char *s)
{
  fputc('"', fp);
  for (; *s; s++) {
    if (*s == '"' || *s == '\\') fprintf(fp, "\\%c", *s);
    else if ((unsigned char)*s < 0x20) fprintf(fp, "\\u%04x", *s);
    else fputc(*s, fp);
  }
  fputc('"', fp);
}

static ekm_status write_json(const cg_score_opts *o, const cg_score_field *res, size_t nres,
                      const char *mode, ekm_error *err)
{
  ekm_atomic out;
  ekm_status rc = ekm_atomic_open(&out, o->json, err);
  if (rc) return rc;
  FILE *fp = out.fp;
  fputs("{\n  \"dem\": ", fp);
  json_str(fp, o->dem);
  fputs(",\n  \"ekm\": ", fp);
  json_str(fp, o->ekm);
  fprintf(fp, ",\n  \"time\": \"%s\",\n  \"code_version\": ", mode);
  json_str(fp, EKMBENCH_VERSION);
  /* every option that produced the numbers, so that a reader (the figures,
   * the regression test) needs no scenario file to know or redo them */
  int other_dem = 0;
  for (size_t i = 0; i < nres; i++) other_dem |= res[i].se_both;
  fputs(",\n  \"options\": {\n    \"fields\": [", fp);
  for (size_t i = 0; i < nres; i++) {
    if (i) fputs(", ", fp);
    json_str(fp, res[i].name);
  }
  fprintf(fp, "],\n    \"ekm_time\": \"%s\",\n    \"shift_m\": ", o->ekm_last ? "last" : "interp");
  json_exact(fp, o->shift);
  fprintf(fp, ",\n    \"model\": \"%s\",\n    \"se\": \"%s\",\n    \"se_floor_rel_rms\": ",
          other_dem ? "dem" : "ekm", other_dem ? "dem and model in quadrature" : "dem");
  json_exact(fp, CG_SCORE_SE_FLOOR);
  fputs("\n  }", fp);
  fputs(",\n  \"fields\": {", fp);
  for (size_t i = 0; i < nres; i++) {
    fprintf(fp, "%s\n    \"%s\": {\"points\": %zu, \"points_with_se\": %zu, \"rel_l2\": ",
            i ? "," : "", res[i].name, res[i].points, res[i].points_se);
    json_num(fp, res[i].rel_l2);
    fputs(", \"noise_normalised\": ", fp);
    json_num(fp, res[i].noise);
    fprintf(fp, ", \"se\": \"%s\"}", res[i].se_both ? "both, in quadrature" : "dem");
  }
  fputs("\n  }\n}\n", fp);
  return ekm_atomic_commit(&out, err);
}

/* A dataset of 1 ([n], *nt = 0) or 2 ([nt][n]) dimensions as doubles. */
static ekm_status read_array(ekm_h5_file *f, const char *name, double **data, size_t *nt, size_t *n,
                             ekm_error *err)
{
  int rank;
  size_t dims[EKM_H5_MAX_RANK];
  ekm_status rc = ekm_h5_read_double(f, name, &rank, dims, data, err);
  if (rc) return rc;
  if (rank > 2) {
    free(*data);
    *data = NULL;
    return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected 1 or 2 dimensions", ekm_h5_path(f), name);
  }
  *nt = rank == 2 ? dims[0] : 0;
  *n = rank == 2 ? dims[1] : dims[0];
  return EKM_OK;
}

typedef struct {
  double *zd, *td, *ze, *te;  /* DEM and EKM coordinates and times */
  size_t nzd, ntd, nze, nte;
} axes;

static ekm_status read_axes(ekm_h5_file *dem, ekm_h5_file *ekm, const cg_score_opts *o, axes *ax,
                            ekm_error *err)
{
  char axis[8] = "z";
  size_t nt;
  ekm_status rc = EKM_OK;
  if (ekm_h5_attr_exists(dem, NULL, "axis")) {
    if ((rc = ekm_h5_attr_get_string(dem, NULL, "axis", axis, sizeof axis, err))) return rc;
  } else {
    if (!ekm_h5_exists(dem, "z") && ekm_h5_exists(dem, "x")) strcpy(axis, "x");
    else if (!ekm_h5_exists(dem, "z") && ekm_h5_exists(dem, "y")) strcpy(axis, "y");
  }
  rc = read_array(dem, axis, &ax->zd, &nt, &ax->nzd, err);
  if (!rc && nt) rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected 1 dimension", o->dem, axis);
  if (!rc) rc = read_array(dem, "t", &ax->td, &nt, &ax->ntd, err);
  if (!rc && nt) rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset t: expected 1 dimension", o->dem);
  if (!rc) rc = read_array(ekm, "z", &ax->ze, &nt, &ax->nze, err);
  if (!rc && nt) rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset z: expected 1 dimension", o->ekm);
  if (!rc) rc = read_array(ekm, "t", &ax->te, &nt, &ax->nte, err);
  if (!rc && nt) rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset t: expected 1 dimension", o->ekm);
  if (rc) return rc;
  if (ax->nze == 0 || ax->nte == 0) return EKM_FAIL(err, EKM_EINPUT, "%s: expected non-empty /z and /t", o->ekm);
  if (ax->nzd == 0 || ax->ntd == 0) return EKM_FAIL(err, EKM_EINPUT, "%s: expected non-empty /%s and /t", o->dem, axis);
  if (!increasing(ax->ze, ax->nze)) return EKM_FAIL(err, EKM_EINPUT, "%s: dataset z: expected increasing values", o->ekm);
  if (!increasing(ax->te, ax->nte)) return EKM_FAIL(err, EKM_EINPUT, "%s: dataset t: expected increasing values", o->ekm);
  for (size_t i = 0; i < ax->nzd; i++) ax->zd[i] += o->shift;
  return EKM_OK;
}

/* A --fields name must be a field of the schema (common/schema.h). */
static ekm_status check_field_name(const char *name, ekm_error *err)
{
  if (ekm_field_lookup(name)) return EKM_OK;
  char known[512] = "";
  size_t used = 0;
  for (size_t i = 0; i < ekm_field_count() && used < sizeof known; i++) {
    const char *n = ekm_field_at(i)->name;
    const size_t len = strlen(n);
    if (len > 3 && !strcmp(n + len - 3, "_se")) continue; /* standard errors come with their field */
    used += (size_t)snprintf(known + used, sizeof known - used, "%s%s", used ? " " : "", n);
  }
  return EKM_FAIL(err, EKM_EINPUT, "--fields: unknown field '%s' (the fields are: %s)", name, known);
}

/* Dataset name of file f must carry the schema's units attribute. */
static ekm_status check_units(ekm_h5_file *f, const char *path, const char *name, ekm_error *err)
{
  const char *want = ekm_field_units(name);
  if (!want) return EKM_OK;
  char got[64];
  ekm_status rc = ekm_h5_attr_get_string(f, name, "units", got, sizeof got, err);
  if (rc) return rc;
  if (strcmp(got, want))
    return EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: units '%s', expected '%s' (the field schema)", path, name, got,
                    want);
  return EKM_OK;
}

ekm_status cg_score(const cg_score_opts *o, cg_score_field *res, size_t *nres, ekm_error *err)
{
  cg_score_field loc[MAXF];
  if (!res) res = loc;
  *nres = 0;
  if (!o->dem || !o->ekm) return EKM_FAIL(err, EKM_EUSAGE, "score: expected --dem CG.h5 and --ekm RUN.h5");
  /* field list */
  char names[MAXF][32];
  size_t nf = 0;
  if (o->fields) {
    const char *p = o->fields;
    while (*p) {
      const char *q = strchr(p, ',');
      size_t len = q ? (size_t)(q - p) : strlen(p);
      if (len == 0 || len >= 32 || nf == MAXF)
        return EKM_FAIL(err, EKM_EUSAGE, "--fields: expected a comma-separated list of field names, got '%s'", o->fields);
      memcpy(names[nf], p, len);
      names[nf][len] = '\0';
      ekm_status st = check_field_name(names[nf++], err);
      if (st) return st;
      p += len + (q ? 1 : 0);
    }
  }
  /* the JSON must not replace an input */
  const char *inputs[2] = {o->dem, o->ekm};
  if (o->json) {
    ekm_status st = ekm_atomic_refuse_input(o->json, inputs, 2, err);
    if (st) return st;
  }
  ekm_h5_file *dem = NULL, *ekm = NULL;
  ekm_status rc = ekm_h5_open(&dem, o->dem, err);
  if (!rc) rc = ekm_h5_open(&ekm, o->ekm, err);
  axes ax;
  memset(&ax, 0, sizeof ax);
  if (!rc) rc = read_axes(dem, ekm, o, &ax, err);
  if (!rc && !o->fields)
    for (size_t i = 0; i < sizeof default_fields / sizeof *default_fields; i++)
      if (ekm_h5_exists(dem, default_fields[i]) && ekm_h5_exists(ekm, default_fields[i]))
        strcpy(names[nf++], default_fields[i]);
  if (!rc && nf == 0) rc = EKM_FAIL(err, EKM_EINPUT, "%s, %s: no field in common", o->dem, o->ekm);
  /* time mapping: EKM index and fraction per DEM time */
  int last = o->ekm_last;
  size_t *ti = NULL;
  double *ta = NULL;
  int *tin = NULL;
  if (!rc) {
    ti = malloc(ax.ntd * sizeof *ti);
    ta = malloc(ax.ntd * sizeof *ta);
    tin = malloc(ax.ntd * sizeof *tin);
    if (!ti || !ta || !tin) rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
  }
  if (!rc) {
    size_t nin = 0;
    for (size_t j = 0; j < ax.ntd; j++) {
      tin[j] = locate(ax.te, ax.nte, ax.td[j], &ti[j], &ta[j]);
      nin += (size_t)tin[j];
    }
    if (!last && nin == 0) {
      last = 1;
      if (o->log)
        fprintf(o->log, "note: no DEM time (%.6g..%.6g s) inside the EKM output times (%.6g..%.6g s): "
                "comparing with the EKM's last output (t = %.6g s)\n",
                ax.td[0], ax.td[ax.ntd - 1], ax.te[0], ax.te[ax.nte - 1], ax.te[ax.nte - 1]);
    }
    if (last)
      for (size_t j = 0; j < ax.ntd; j++) { tin[j] = 1; ti[j] = ax.nte - 1; ta[j] = 0.0; }
  }
  for (size_t f = 0; f < nf && !rc; f++) {
    double *fd = NULL, *sd = NULL, *fe = NULL, *fse = NULL;
    size_t nt1, n1, nt2 = 0, n2 = 0, nt3, n3, nt4, n4;
    char sename[48];
    snprintf(sename, sizeof sename, "%s_se", names[f]);
    if (!ekm_h5_exists(dem, names[f])) rc = EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", o->dem, names[f]);
    else if (!ekm_h5_exists(ekm, names[f])) rc = EKM_FAIL(err, EKM_EINPUT, "%s: expected a dataset %s", o->ekm, names[f]);
    if (!rc) rc = check_units(dem, o->dem, names[f], err);
    if (!rc) rc = check_units(ekm, o->ekm, names[f], err);
    if (!rc) rc = read_array(dem, names[f], &fd, &nt1, &n1, err);
    if (!rc && (nt1 != ax.ntd || n1 != ax.nzd))
      rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->dem, names[f], ax.ntd, ax.nzd);
    if (!rc && ekm_h5_exists(dem, sename)) {
      rc = read_array(dem, sename, &sd, &nt2, &n2, err);
      if (!rc && (nt2 != ax.ntd || n2 != ax.nzd))
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->dem, sename, ax.ntd, ax.nzd);
    }
    if (!rc) rc = read_array(ekm, names[f], &fe, &nt3, &n3, err);
    if (!rc && (nt3 != ax.nte || n3 != ax.nze))
      rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->ekm, names[f], ax.nte, ax.nze);
    /* a second coarse-grained DEM run in place of the EKM (engine against
     * engine) carries its own standard error: the two add in quadrature */
    if (!rc && ekm_h5_exists(ekm, sename)) {
      rc = read_array(ekm, sename, &fse, &nt4, &n4, err);
      if (!rc && (nt4 != ax.nte || n4 != ax.nze))
        rc = EKM_FAIL(err, EKM_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->ekm, sename, ax.nte, ax.nze);
    }
    /* the points both cover, in DEM order (time, then coordinate): the
     * model interpolated onto them, the DEM value and its standard error */
    double *pm = NULL, *pdem = NULL, *ps = NULL;
    size_t ncand = ax.ntd * ax.nzd;
    if (!rc && (!(pm = malloc(ncand * sizeof *pm)) || !(pdem = malloc(ncand * sizeof *pdem)) ||
                !(ps = malloc(ncand * sizeof *ps))))
      rc = EKM_FAIL(err, EKM_ENOMEM, "out of memory");
    if (!rc) {
      size_t np = 0;
      for (size_t j = 0; j < ax.ntd; j++) {
        if (!tin[j]) continue;
        size_t i0 = ti[j], i1 = i0 + 1 < ax.nte ? i0 + 1 : i0;
        double at = ta[j];
        for (size_t k = 0; k < ax.nzd; k++) {
          size_t zi;
          double az;
          if (!locate(ax.ze, ax.nze, ax.zd[k], &zi, &az)) continue;
          size_t z1 = zi + 1 < ax.nze ? zi + 1 : zi;
          const double *r0 = fe + i0 * ax.nze, *r1 = fe + i1 * ax.nze;
          double e0 = r0[zi] + az * (r0[z1] - r0[zi]);
          double e1 = r1[zi] + az * (r1[z1] - r1[zi]);
          double e = e0 + at * (e1 - e0), d = fd[j * ax.nzd + k];
          double s = sd ? sd[j * ax.nzd + k] : NAN;
          if (fse) {
            const double *q0 = fse + i0 * ax.nze, *q1 = fse + i1 * ax.nze;
            double s0 = q0[zi] + az * (q0[z1] - q0[zi]);
            double s1 = q1[zi] + az * (q1[z1] - q1[zi]);
            double s2 = s0 + at * (s1 - s0);
            s = sqrt(s * s + s2 * s2);
          }
          pm[np] = e;
          pdem[np] = d;
          ps[np] = s;
          np++;
        }
      }
      cg_metric m = cg_metric_compute(pm, pdem, ps, np, CG_SCORE_SE_FLOOR);
      cg_score_field *r = &res[*nres];
      snprintf(r->name, sizeof r->name, "%s", names[f]);
      r->points = m.points;
      r->points_se = m.points_se;
      r->rel_l2 = m.rel_l2;
      r->noise = m.noise;
      r->se_both = fse != NULL;
      (*nres)++;
    }
    free(fd);
    free(sd);
    free(fe);
    free(fse);
    free(pm);
    free(pdem);
    free(ps);
  }
  if (!rc && o->table) {
    fprintf(o->table, "| field | points | rel. L2 error | noise-normalised error |\n|---|---:|---:|---:|\n");
    for (size_t i = 0; i < *nres; i++)
      fprintf(o->table, "| %s | %zu | %.4g | %.4g |\n", res[i].name, res[i].points, res[i].rel_l2, res[i].noise);
  }
  if (!rc && o->json) rc = write_json(o, res, *nres, last ? "ekm last output" : "interpolated", err);
  free(ti);
  free(ta);
  free(tin);
  free(ax.zd); free(ax.td); free(ax.ze); free(ax.te);
  ekm_h5_close(dem);
  ekm_h5_close(ekm);
  return rc;
}
