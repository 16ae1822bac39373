/* score.c: the EKM against coarse-grained DEM (see score.h). */
#include "ekm_version.h"
#include "score.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5io.h"
#include "metric.h"

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

static int write_json(const cg_score_opts *o, const cg_score_field *res, size_t nres,
                      const char *mode, cg_error *err)
{
  size_t len = strlen(o->json) + 32;
  char *tmp = malloc(len);
  if (!tmp) return CG_ERROR(err, CG_ESYS, "out of memory");
  snprintf(tmp, len, "%s.tmp.%ld", o->json, (long)getpid());
  FILE *fp = fopen(tmp, "w");
  if (!fp) {
    free(tmp);
    return CG_ERROR(err, CG_ESYS, "%s: cannot create the output file", o->json);
  }
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
  int bad = ferror(fp);
  bad |= fclose(fp) != 0;
  if (bad || rename(tmp, o->json) != 0) {
    unlink(tmp);
    free(tmp);
    return CG_ERROR(err, CG_ESYS, "%s: cannot write the output file", o->json);
  }
  free(tmp);
  return CG_OK;
}

typedef struct {
  double *zd, *td, *ze, *te;  /* DEM and EKM coordinates and times */
  size_t nzd, ntd, nze, nte;
} axes;

static int read_axes(cg_h5r *dem, cg_h5r *ekm, const cg_score_opts *o, axes *ax, cg_error *err)
{
  char axis[8] = "z";
  size_t nt;
  if (cg_h5r_attr_str(dem, "axis", axis, sizeof axis)) {
    if (!cg_h5r_has(dem, "z") && cg_h5r_has(dem, "x")) strcpy(axis, "x");
    else if (!cg_h5r_has(dem, "z") && cg_h5r_has(dem, "y")) strcpy(axis, "y");
  }
  int rc = cg_h5r_read(dem, axis, &ax->zd, &nt, &ax->nzd, err);
  if (!rc && nt) rc = CG_ERROR(err, CG_EINPUT, "%s: dataset %s: expected 1 dimension", o->dem, axis);
  if (!rc) rc = cg_h5r_read(dem, "t", &ax->td, &nt, &ax->ntd, err);
  if (!rc && nt) rc = CG_ERROR(err, CG_EINPUT, "%s: dataset t: expected 1 dimension", o->dem);
  if (!rc) rc = cg_h5r_read(ekm, "z", &ax->ze, &nt, &ax->nze, err);
  if (!rc && nt) rc = CG_ERROR(err, CG_EINPUT, "%s: dataset z: expected 1 dimension", o->ekm);
  if (!rc) rc = cg_h5r_read(ekm, "t", &ax->te, &nt, &ax->nte, err);
  if (!rc && nt) rc = CG_ERROR(err, CG_EINPUT, "%s: dataset t: expected 1 dimension", o->ekm);
  if (rc) return rc;
  if (ax->nze == 0 || ax->nte == 0) return CG_ERROR(err, CG_EINPUT, "%s: expected non-empty /z and /t", o->ekm);
  if (ax->nzd == 0 || ax->ntd == 0) return CG_ERROR(err, CG_EINPUT, "%s: expected non-empty /%s and /t", o->dem, axis);
  if (!increasing(ax->ze, ax->nze)) return CG_ERROR(err, CG_EINPUT, "%s: dataset z: expected increasing values", o->ekm);
  if (!increasing(ax->te, ax->nte)) return CG_ERROR(err, CG_EINPUT, "%s: dataset t: expected increasing values", o->ekm);
  for (size_t i = 0; i < ax->nzd; i++) ax->zd[i] += o->shift;
  return CG_OK;
}

int cg_score(const cg_score_opts *o, cg_score_field *res, size_t *nres, cg_error *err)
{
  cg_score_field loc[MAXF];
  if (!res) res = loc;
  *nres = 0;
  if (!o->dem || !o->ekm) return CG_ERROR(err, CG_EUSAGE, "score: expected --dem CG.h5 and --ekm RUN.h5");
  /* field list */
  char names[MAXF][32];
  size_t nf = 0;
  if (o->fields) {
    const char *p = o->fields;
    while (*p) {
      const char *q = strchr(p, ',');
      size_t len = q ? (size_t)(q - p) : strlen(p);
      if (len == 0 || len >= 32 || nf == MAXF)
        return CG_ERROR(err, CG_EUSAGE, "--fields: expected a comma-separated list of field names, got '%s'", o->fields);
      memcpy(names[nf], p, len);
      names[nf++][len] = '\0';
      p += len + (q ? 1 : 0);
    }
  }
  cg_h5r *dem = NULL, *ekm = NULL;
  int rc = cg_h5r_open(&dem, o->dem, err);
  if (!rc) rc = cg_h5r_open(&ekm, o->ekm, err);
  axes ax;
  memset(&ax, 0, sizeof ax);
  if (!rc) rc = read_axes(dem, ekm, o, &ax, err);
  if (!rc && !o->fields)
    for (size_t i = 0; i < sizeof default_fields / sizeof *default_fields; i++)
      if (cg_h5r_has(dem, default_fields[i]) && cg_h5r_has(ekm, default_fields[i]))
        strcpy(names[nf++], default_fields[i]);
  if (!rc && nf == 0) rc = CG_ERROR(err, CG_EINPUT, "%s, %s: no field in common", o->dem, o->ekm);
  /* time mapping: EKM index and fraction per DEM time */
  int last = o->ekm_last;
  size_t *ti = NULL;
  double *ta = NULL;
  int *tin = NULL;
  if (!rc) {
    ti = malloc(ax.ntd * sizeof *ti);
    ta = malloc(ax.ntd * sizeof *ta);
    tin = malloc(ax.ntd * sizeof *tin);
    if (!ti || !ta || !tin) rc = CG_ERROR(err, CG_ESYS, "out of memory");
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
    if (!cg_h5r_has(dem, names[f])) rc = CG_ERROR(err, CG_EINPUT, "%s: expected a dataset %s", o->dem, names[f]);
    else if (!cg_h5r_has(ekm, names[f])) rc = CG_ERROR(err, CG_EINPUT, "%s: expected a dataset %s", o->ekm, names[f]);
    if (!rc) rc = cg_h5r_read(dem, names[f], &fd, &nt1, &n1, err);
    if (!rc && (nt1 != ax.ntd || n1 != ax.nzd))
      rc = CG_ERROR(err, CG_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->dem, names[f], ax.ntd, ax.nzd);
    if (!rc && cg_h5r_has(dem, sename)) {
      rc = cg_h5r_read(dem, sename, &sd, &nt2, &n2, err);
      if (!rc && (nt2 != ax.ntd || n2 != ax.nzd))
        rc = CG_ERROR(err, CG_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->dem, sename, ax.ntd, ax.nzd);
    }
    if (!rc) rc = cg_h5r_read(ekm, names[f], &fe, &nt3, &n3, err);
    if (!rc && (nt3 != ax.nte || n3 != ax.nze))
      rc = CG_ERROR(err, CG_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->ekm, names[f], ax.nte, ax.nze);
    /* a second coarse-grained DEM run in place of the EKM (engine against
     * engine) carries its own standard error: the two add in quadrature */
    if (!rc && cg_h5r_has(ekm, sename)) {
      rc = cg_h5r_read(ekm, sename, &fse, &nt4, &n4, err);
      if (!rc && (nt4 != ax.nte || n4 != ax.nze))
        rc = CG_ERROR(err, CG_EINPUT, "%s: dataset %s: expected shape [%zu][%zu]", o->ekm, sename, ax.nte, ax.nze);
    }
    /* the points both cover, in DEM order (time, then coordinate): the
     * model interpolated onto them, the DEM value and its standard error */
    double *pm = NULL, *pdem = NULL, *ps = NULL;
    size_t ncand = ax.ntd * ax.nzd;
    if (!rc && (!(pm = malloc(ncand * sizeof *pm)) || !(pdem = malloc(ncand * sizeof *pdem)) ||
                !(ps = malloc(ncand * sizeof *ps))))
      rc = CG_ERROR(err, CG_ESYS, "out of memory");
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
  cg_h5r_close(dem);
  cg_h5r_close(ekm);
  return rc;
}
