/* cgrun.c: the `ekmcompare cg` pipeline (see cgrun.h). */
#include "ekm_version.h"
#include "cgrun.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dump.h"
#include "h5io.h"
#include "kernel.h"
#include "stats.h"

#define BLOCKS_MAX 64   /* block store size (cg_blocks bmax) */
#define PI 3.14159265358979323846

/* Selected dump columns. */
enum {
  C_POS = 0,        /* 3 x flavour (plain, u, s, su) + dim: x y z xu ... */
  C_VX = 12, C_VY, C_VZ, C_MASS, C_RADIUS, C_DIAMETER, C_STRESS, C_ID = C_STRESS + 6, C_TYPE, C_NCOL
};
static const char *const base_cols[C_STRESS] = {
  "x", "y", "z", "xu", "yu", "zu", "xs", "ys", "zs", "xsu", "ysu", "zsu",
  "vx", "vy", "vz", "mass", "radius", "diameter"};

cg_run_opts cg_run_opts_default(void)
{
  cg_run_opts o;
  memset(&o, 0, sizeof o);
  o.axis = 2;
  o.kernel = "gauss";
  o.tmode = CG_T_PARTICLE;
  return o;
}

/* ---------- snapshot source: files -> selected snapshots -> particles ---------- */

typedef struct {
  const cg_run_opts *o;
  const char *cols[C_NCOL];  /* the columns asked of the reader (compact) */
  size_t ncols;
  int col[C_NCOL];           /* C_* -> index in cols, or -1 if not asked */
  size_t ifile;           /* next file to open */
  cg_dump *d;
  cg_snapshot snap;
  int have_last;
  int64_t last_step;      /* last accepted step (skip repeats) */
  size_t nread;           /* snapshots read */
  size_t nrepeat;         /* repeated steps skipped */
  size_t cap;             /* particle capacity */
  double *s, *v, *m, *vol, *rad, *S;
  cg_particles pt;
  double t;               /* time of the current snapshot [s] */
  double lo, hi;          /* box along the axis [m] */
  int periodic;           /* box periodic along the axis */
  double dsum;            /* sum of diameters so far [m] */
  double dcount;          /* particles in dsum */
  size_t ipair;           /* next pair file to open */
  cg_dump *pd;            /* pair dump being read */
  cg_snapshot psnap;      /* pair snapshot */
  int have_pair;          /* psnap read but not used yet */
  int skip_pairs;         /* 1: do not read the pair dumps (steady pass) */
  size_t ccap;            /* contact capacity */
  double *cs, *cb, *cf;   /* contacts: partner coordinate, branch, force */
  double *ids;            /* id-mode: (id, index) pairs sorted by id */
  size_t idcap;
} source;

static void source_close(source *src)
{
  cg_dump_close(src->d);
  src->d = NULL;
  cg_snapshot_free(&src->snap);
  cg_dump_close(src->pd);
  src->pd = NULL;
  cg_snapshot_free(&src->psnap);
  free(src->cs); free(src->cb); free(src->cf); free(src->ids);
  src->cs = src->cb = src->cf = src->ids = NULL;
  src->ccap = src->idcap = 0;
  free(src->s); free(src->v); free(src->m); free(src->vol); free(src->rad); free(src->S);
  src->s = src->v = src->m = src->vol = src->rad = src->S = NULL;
  src->cap = 0;
}

static void source_init(source *src, const cg_run_opts *o)
{
  memset(src, 0, sizeof *src);
  src->o = o;
  /* only the position columns the axis needs are parsed: the axis
   * coordinate, and for scaled ones the later dimensions (triclinic) */
  int idmode = o->npaircols == 5;
  const char *want[C_NCOL];
  for (size_t j = 0; j < C_STRESS; j++) {
    int f = (int)j / 3, c = (int)j % 3;
    int need = j >= C_VX || c == o->axis || (f >= 2 && c > o->axis) || (idmode && f == 0);
    want[j] = need ? base_cols[j] : NULL;
  }
  for (size_t j = 0; j < 6; j++) want[C_STRESS + j] = j < o->nstress ? o->stress[j] : NULL;
  want[C_ID] = idmode ? "id" : NULL;
  want[C_TYPE] = o->ntypes ? "type" : NULL;
  /* only the needed columns are asked for: fewer conversions, and a
   * compact snapshot row */
  src->ncols = 0;
  for (size_t j = 0; j < C_NCOL; j++) {
    src->col[j] = want[j] ? (int)src->ncols : -1;
    if (want[j]) src->cols[src->ncols++] = want[j];
  }
}

static int source_grow(source *src, size_t n, cg_error *err)
{
  if (n <= src->cap) return CG_OK;
  size_t c = src->cap ? src->cap : 1024;
  while (c < n) c *= 2;
  double *p[6] = {
    realloc(src->s, c * sizeof(double)), NULL, NULL, NULL, NULL, NULL};
  if (p[0]) src->s = p[0];
  p[1] = realloc(src->v, 3 * c * sizeof(double));
  if (p[1]) src->v = p[1];
  p[2] = realloc(src->m, c * sizeof(double));
  if (p[2]) src->m = p[2];
  p[3] = realloc(src->vol, c * sizeof(double));
  if (p[3]) src->vol = p[3];
  p[4] = realloc(src->rad, c * sizeof(double));
  if (p[4]) src->rad = p[4];
  p[5] = realloc(src->S, 6 * c * sizeof(double));
  if (p[5]) src->S = p[5];
  for (int i = 0; i < 6; i++)
    if (!p[i]) return CG_ERROR(err, CG_ESYS, "out of memory (%zu atoms)", n);
  src->cap = c;
  return CG_OK;
}

static int missing(const cg_snapshot *s, const char *what, cg_error *err)
{
  return CG_ERROR(err, CG_EINPUT, "%s: ITEM: ATOMS has no column %s", s->where, what);
}

/* Snapshot columns -> particle arrays. */
#define PR(c) (src->col[c] >= 0 && pr[src->col[c]])
#define AT(row, c) ((row)[src->col[c]])

static int source_convert(source *src, cg_error *err)
{
  const cg_run_opts *o = src->o;
  const cg_snapshot *sn = &src->snap;
  const int *pr = sn->present;
  int ax = o->axis;
  static const char axname[3] = {'x', 'y', 'z'};
  int flav = -1;
  for (int f = 0; f < 4; f++)
    if (PR(C_POS + 3 * f + ax)) { flav = f; break; }
  if (flav < 0) {
    char what[64];
    snprintf(what, sizeof what, "'%c' (nor %cu, %cs, %csu)", axname[ax], axname[ax], axname[ax], axname[ax]);
    return missing(sn, what, err);
  }
  int scaled = flav >= 2;
  if (scaled && sn->triclinic && ax < 2)
    for (int c = ax; c < 3; c++)
      if (!PR(C_POS + 3 * flav + c))
        return missing(sn, c == 1 ? "'ys' (scaled triclinic coordinates need all three)"
                                  : "'zs' (scaled triclinic coordinates need all three)", err);
  for (int c = 0; c < 3; c++)
    if (!PR(C_VX + c)) return missing(sn, c == 0 ? "'vx'" : c == 1 ? "'vy'" : "'vz'", err);
  if (o->npaircols == 5) {
    if (!PR(C_ID)) return missing(sn, "'id' (pair dumps with atom ids)", err);
    for (int c = 0; c < 3; c++)
      if (!PR(C_POS + c)) return missing(sn, c == 0 ? "'x' (pair dumps with atom ids)" : c == 1 ? "'y' (pair dumps with atom ids)" : "'z' (pair dumps with atom ids)", err);
  }
  int has_mass = PR(C_MASS), has_rad = PR(C_RADIUS), has_diam = PR(C_DIAMETER);
  if (!has_mass && !(has_rad || has_diam))
    return missing(sn, "'mass', 'radius' or 'diameter'", err);
  if (!has_mass && !(o->rho_p > 0))
    return CG_ERROR(err, CG_EUSAGE,
                    "%s: ITEM: ATOMS has no column 'mass': give --rho-p (material density, kg/m^3)",
                    sn->where);
  if (!has_rad && !has_diam && !(o->rho_p > 0))
    return CG_ERROR(err, CG_EUSAGE,
                    "%s: ITEM: ATOMS has no column 'radius' or 'diameter' (needed for phi): "
                    "give --rho-p (material density, kg/m^3)", sn->where);
  for (size_t j = 0; j < o->nstress; j++)
    if (!PR(C_STRESS + j)) {
      char what[96];
      snprintf(what, sizeof what, "'%s' (--stress)", o->stress[j]);
      return missing(sn, what, err);
    }
  if (o->ntypes && !PR(C_TYPE)) return missing(sn, "'type' (--types)", err);
  size_t n = (size_t)sn->natoms;
  int rc = source_grow(src, n, err);
  if (rc) return rc;
  double L[3];
  for (int c = 0; c < 3; c++) L[c] = sn->hi[c] - sn->lo[c];
  src->lo = sn->lo[ax];
  src->hi = sn->hi[ax];
  src->periodic = sn->periodic[ax];
  const size_t w = sn->nsel;
  for (size_t i = 0; i < n; i++) {
    const double *row = sn->data + i * w;
    double s;
    if (!scaled) {
      s = AT(row, C_POS + 3 * flav + ax);
    } else {
      double q[3];
      for (int c = 0; c < 3; c++) q[c] = PR(C_POS + 3 * flav + c) ? AT(row, C_POS + 3 * flav + c) : 0.0;
      if (ax == 2) s = sn->lo[2] + q[2] * L[2];
      else if (ax == 1) s = sn->lo[1] + q[1] * L[1] + (sn->triclinic ? q[2] * sn->tilt[2] : 0.0);
      else s = sn->lo[0] + q[0] * L[0] + (sn->triclinic ? q[1] * sn->tilt[0] + q[2] * sn->tilt[1] : 0.0);
    }
    if (src->periodic) {
      s = src->lo + fmod(s - src->lo, L[ax]);
      if (s < src->lo) s += L[ax];
      if (s >= src->hi) s = src->lo;
    }
    src->s[i] = s;
    for (int c = 0; c < 3; c++) src->v[3 * i + c] = AT(row, C_VX + c);
    double r = has_rad ? AT(row, C_RADIUS) : has_diam ? 0.5 * AT(row, C_DIAMETER) : -1.0;
    double m = has_mass ? AT(row, C_MASS) : 0.0;
    if (r >= 0.0) {
      if (!(r > 0.0))
        return CG_ERROR(err, CG_EINPUT, "%s: atom %zu: expected a positive radius, got %g",
                        sn->where, i + 1, r);
      src->vol[i] = 4.0 / 3.0 * PI * r * r * r;
      if (!has_mass) m = o->rho_p * src->vol[i];
    } else {
      if (!(m > 0.0))
        return CG_ERROR(err, CG_EINPUT, "%s: atom %zu: expected a positive mass, got %g",
                        sn->where, i + 1, m);
      src->vol[i] = m / o->rho_p;
      r = cbrt(src->vol[i] * 3.0 / (4.0 * PI));
    }
    if (!(m > 0.0))
      return CG_ERROR(err, CG_EINPUT, "%s: atom %zu: expected a positive mass, got %g",
                      sn->where, i + 1, m);
    /* an atom of a type not kept (--types: e.g. frozen wall grains)
     * stays in the arrays, so that pair dumps still find it by index, but
     * with zero mass, volume and stress it adds nothing to any field */
    int keep = 1;
    if (o->ntypes) {
      double ty = AT(row, C_TYPE);
      keep = 0;
      for (size_t k = 0; k < o->ntypes; k++)
        if (ty == (double)o->types[k]) keep = 1;
    }
    src->m[i] = keep ? m : 0.0;
    src->rad[i] = r;
    if (!keep) src->vol[i] = 0.0;
    if (keep) {
      src->dsum += 2.0 * r;
      src->dcount += 1.0;
    }
    if (o->nstress)
      for (int c = 0; c < 6; c++) src->S[6 * i + c] = keep ? AT(row, C_STRESS + c) : 0.0;
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
  return CG_OK;
}

/* ---------- contacts from pair dumps ---------- */

static int cmp_id(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* Index of the atom with this id (binary search in src->ids), or -1. */
static long find_id(const source *src, double id)
{
  size_t lo = 0, hi = src->pt.n;
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    double v = src->ids[2 * mid];
    if (v == id) return (long)src->ids[2 * mid + 1];
    if (v < id) lo = mid + 1; else hi = mid;
  }
  return -1;
}

/* Minimum image of a branch vector in the (possibly triclinic) box: a
 * contact is never longer than half the box (LIGGGHTS writes the owned,
 * wrapped position of a partner across a periodic boundary). */
static void min_image(const cg_snapshot *sn, double b[3])
{
  double L[3];
  for (int d = 0; d < 3; d++) L[d] = sn->hi[d] - sn->lo[d];
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
  if (sn->periodic[0]) b[0] -= L[0] * nearbyint(b[0] / L[0]);
}

/* The pair snapshot with the atom snapshot's step, as contacts. */
static int source_pairs(source *src, cg_error *err)
{
  const cg_run_opts *o = src->o;
  const cg_snapshot *sn = &src->snap;
  int rc;
  for (;;) {
    if (!src->have_pair) {
      if (!src->pd) {
        if (src->ipair >= o->npairs)
          return CG_ERROR(err, CG_EINPUT, "%s: no pair-dump snapshot for step %lld (the pair dumps end before)",
                          sn->where, (long long)sn->step);
        if ((rc = cg_dump_open(&src->pd, o->pairs[src->ipair++], o->paircols, o->npaircols, err)))
          return rc;
      }
      rc = cg_dump_next(src->pd, &src->psnap, err);
      if (rc == CG_EOF) {
        if (cg_dump_truncated(src->pd) && o->log)
          fprintf(o->log, "warning: %s\n", cg_dump_warning(src->pd));
        cg_dump_close(src->pd);
        src->pd = NULL;
        continue;
      }
      if (rc) return rc;
      src->have_pair = 1;
    }
    if (src->psnap.step < sn->step) { src->have_pair = 0; continue; }
    if (src->psnap.step > sn->step)
      return CG_ERROR(err, CG_EINPUT, "%s: no pair-dump snapshot for step %lld (the next one is step %lld)",
                      sn->where, (long long)sn->step, (long long)src->psnap.step);
    break;
  }
  src->have_pair = 0;
  const cg_snapshot *ps = &src->psnap;
  for (size_t j = 0; j < o->npaircols; j++)
    if (!ps->present[j])
      return CG_ERROR(err, CG_EINPUT, "%s: ITEM: ENTRIES has no column '%s' (--pair-columns)", ps->where,
                      o->paircols[j]);
  size_t nc = (size_t)ps->natoms, w = ps->nsel;
  if (nc > src->ccap) {
    double *a = realloc(src->cs, nc * sizeof *a);
    if (a) src->cs = a;
    double *b = realloc(src->cb, 3 * nc * sizeof *b);
    if (b) src->cb = b;
    double *f = realloc(src->cf, 3 * nc * sizeof *f);
    if (f) src->cf = f;
    if (!a || !b || !f) return CG_ERROR(err, CG_ESYS, "out of memory (%zu contacts)", nc);
    src->ccap = nc;
  }
  int ax = o->axis;
  if (o->npaircols == 9) {
    for (size_t c = 0; c < nc; c++) {
      const double *row = ps->data + c * w;
      for (int d = 0; d < 3; d++) {
        src->cb[3 * c + d] = row[d] - row[3 + d];
        src->cf[3 * c + d] = row[6 + d];
      }
      min_image(sn, src->cb + 3 * c);
      src->cs[c] = row[3 + ax];
    }
  } else {
    size_t n = src->pt.n;
    if (n > src->idcap) {
      double *p = realloc(src->ids, 2 * n * sizeof *p);
      if (!p) return CG_ERROR(err, CG_ESYS, "out of memory");
      src->ids = p;
      src->idcap = n;
    }
    const double *ad = sn->data;
    size_t aw = sn->nsel;
    for (size_t i = 0; i < n; i++) {
      src->ids[2 * i] = AT(ad + i * aw, C_ID);
      src->ids[2 * i + 1] = (double)i;
    }
    qsort(src->ids, n, 2 * sizeof(double), cmp_id);
    for (size_t c = 0; c < nc; c++) {
      const double *row = ps->data + c * w;
      long i = find_id(src, row[0]), j = find_id(src, row[1]);
      if (i < 0 || j < 0)
        return CG_ERROR(err, CG_EINPUT, "%s: entry %zu: no atom with id %.0f in %s", ps->where, c + 1,
                        i < 0 ? row[0] : row[1], sn->where);
      for (int d = 0; d < 3; d++) {
        src->cb[3 * c + d] = AT(ad + (size_t)i * aw, C_POS + d) - AT(ad + (size_t)j * aw, C_POS + d);
        src->cf[3 * c + d] = row[2 + d];
      }
      min_image(sn, src->cb + 3 * c);
      src->cs[c] = src->s[j];
    }
  }
  src->pt.nc = nc;
  src->pt.cs = src->cs;
  src->pt.cb = src->cb;
  src->pt.cf = src->cf;
  return CG_OK;
}

/* Next selected snapshot, converted; CG_EOF after the last file. */
static int source_next(source *src, cg_error *err)
{
  const cg_run_opts *o = src->o;
  for (;;) {
    if (!src->d) {
      if (src->ifile >= o->ninputs) return CG_EOF;
      int rc = cg_dump_open(&src->d, o->inputs[src->ifile++], src->cols, src->ncols, err);
      if (rc) return rc;
    }
    int rc = cg_dump_next(src->d, &src->snap, err);
    if (rc == CG_EOF) {
      if (cg_dump_truncated(src->d) && o->log)
        fprintf(o->log, "warning: %s\n", cg_dump_warning(src->d));
      cg_dump_close(src->d);
      src->d = NULL;
      continue;
    }
    if (rc) return rc;
    src->nread++;
    const cg_snapshot *sn = &src->snap;
    if (src->have_last && sn->step <= src->last_step) {
      src->nrepeat++;
      continue;
    }
    if (sn->has_time) src->t = sn->time;
    else if (o->dt > 0) src->t = (double)sn->step * o->dt;
    else
      return CG_ERROR(err, CG_EUSAGE,
                      "%s: the dump has no ITEM: TIME: give --dt (the engine's time step, s)",
                      sn->where);
    src->have_last = 1;
    src->last_step = sn->step;
    if (o->have_steps && (sn->step < o->step_a || sn->step > o->step_b)) continue;
    if (o->have_from && src->t < o->from) continue;
    if (o->have_to && src->t > o->to) continue;
    int crc = source_convert(src, err);
    if (crc || !o->npairs || src->skip_pairs) return crc;
    return source_pairs(src, err);
  }
}

/* ---------- steady start ---------- */

static int push(double **a, size_t *n, size_t *cap, double v, cg_error *err)
{
  if (*n == *cap) {
    size_t c = *cap ? 2 * *cap : 256;
    double *p = realloc(*a, c * sizeof *p);
    if (!p) return CG_ERROR(err, CG_ESYS, "out of memory");
    *a = p;
    *cap = c;
  }
  (*a)[(*n)++] = v;
  return CG_OK;
}

/* First pass: the time at which the steady window starts. */
static int find_steady(const cg_run_opts *o, double *t_start, cg_error *err)
{
  source src;
  source_init(&src, o);
  src.skip_pairs = 1;
  double *ke = NULL, *com = NULL, *ts = NULL;
  size_t nke = 0, ncom = 0, nts = 0, cke = 0, ccom = 0, cts = 0;
  int rc, periodic = 0;
  while ((rc = source_next(&src, err)) == CG_OK) {
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
  source_close(&src);
  if (rc == CG_EOF) {
    rc = CG_OK;
    if (nts == 0) {
      rc = CG_ERROR(err, CG_EINPUT, "%s: no snapshots selected", o->inputs[0]);
    } else {
      size_t k = cg_stats_mser(ke, nke);
      if (!periodic) {
        size_t k2 = cg_stats_mser(com, ncom);
        if (k2 > k) k = k2;
      }
      *t_start = ts[k];
      if (o->log) {
        if (nts < 10)
          fprintf(o->log, "note: --steady: only %zu snapshots, using all of them\n", nts);
        else
          fprintf(o->log, "note: --steady: steady window starts at t = %.9g s (snapshot %zu of %zu, MSER-5)\n",
                  ts[k], k + 1, nts);
        if (nts >= 10 && k >= (nts / 5 / 2) * 5)
          fprintf(o->log, "warning: --steady: the start is the latest MSER-5 allows (half the selection): "
                  "the run may not be steady yet, or is too short to tell; check with --every or give --from\n");
      }
    }
  }
  free(ke);
  free(com);
  free(ts);
  return rc;
}

/* ---------- windows and results ---------- */

typedef struct {
  size_t n;                 /* bins */
  size_t nt, cap;           /* windows stored, capacity */
  double *t;                /* window mid-times [s] */
  double *nsnap;            /* snapshots per window */
  double *f[CG_NFIELD];     /* nt x n fields */
  double *se[CG_NFIELD];    /* nt x n standard errors */
} results;

static void results_free(results *r)
{
  free(r->t);
  free(r->nsnap);
  for (int f = 0; f < CG_NFIELD; f++) { free(r->f[f]); free(r->se[f]); }
}

static int results_grow(results *r, cg_error *err)
{
  if (r->nt < r->cap) return CG_OK;
  size_t c = r->cap ? 2 * r->cap : 8;
  double *p = realloc(r->t, c * sizeof *p);
  if (!p) return CG_ERROR(err, CG_ESYS, "out of memory");
  r->t = p;
  if (!(p = realloc(r->nsnap, c * sizeof *p))) return CG_ERROR(err, CG_ESYS, "out of memory");
  r->nsnap = p;
  for (int f = 0; f < CG_NFIELD; f++) {
    if (!(p = realloc(r->f[f], c * r->n * sizeof *p))) return CG_ERROR(err, CG_ESYS, "out of memory");
    r->f[f] = p;
    if (!(p = realloc(r->se[f], c * r->n * sizeof *p))) return CG_ERROR(err, CG_ESYS, "out of memory");
    r->se[f] = p;
  }
  r->cap = c;
  return CG_OK;
}

typedef struct {
  const cg_grid *g;
  cg_blocks *b;
  double *mean;    /* CG_NPRIM x n */
  double *fld;     /* CG_NFIELD x n */
  double *bf;      /* BLOCKS_MAX x CG_NFIELD x n */
  double *series;  /* BLOCKS_MAX */
  double *work;    /* BLOCKS_MAX */
} finisher;

/* Close a window: mean fields and their standard errors, appended to r. */
static int finish_window(finisher *fz, results *r, double t_mid, double d, double rho_p,
                         cg_error *err)
{
  int rc = results_grow(r, err);
  if (rc) return rc;
  size_t n = fz->g->n, nf = CG_NFIELD * n, nb = fz->b->nblocks;
  cg_blocks_mean(fz->b, fz->mean);
  cg_profile_derive(fz->mean, fz->g, d, rho_p, fz->fld);
  for (size_t j = 0; j < nb; j++) {
    cg_blocks_block_mean(fz->b, j, fz->mean);
    cg_profile_derive(fz->mean, fz->g, d, rho_p, fz->bf + j * nf);
  }
  for (int f = 0; f < CG_NFIELD; f++)
    for (size_t k = 0; k < n; k++) {
      size_t idx = (size_t)f * n + k;
      r->f[f][r->nt * n + k] = fz->fld[idx];
      for (size_t j = 0; j < nb; j++) fz->series[j] = fz->bf[j * nf + idx];
      r->se[f][r->nt * n + k] = nb >= 2 ? cg_stats_se(fz->series, nb, fz->work) : NAN;
    }
  r->t[r->nt] = t_mid;
  r->nsnap[r->nt] = (double)fz->b->nsnap;
  r->nt++;
  cg_blocks_reset(fz->b);
  return CG_OK;
}

/* ---------- output ---------- */

static const char *const axis_names[3] = {"x", "y", "z"};

typedef struct {
  char inputs[4096];
  char pairs[4096];
  char window[256];
  char stress[256];
  double width, d, area, t_start;
  size_t nread, nused, nout;
  int steady;
  const char *wall;
} run_info;

static int write_h5(const cg_run_opts *o, const cg_grid *g, const results *r,
                    const cg_kernel *k, const run_info *info, cg_error *err)
{
  cg_h5w *w;
  int rc = cg_h5w_create(&w, o->out, err);
  if (rc) return rc;
  size_t n = g->n;
  double *zc = malloc(n * sizeof *zc);
  char name[64];
  if (!zc) { cg_h5w_abort(w); return CG_ERROR(err, CG_ESYS, "out of memory"); }
  for (size_t i = 0; i < n; i++) zc[i] = g->lo + ((double)i + 0.5) * g->dz;
  rc = cg_h5w_dataset(w, axis_names[o->axis], zc, 0, n, "m", err);
  free(zc);
  if (!rc) rc = cg_h5w_dataset(w, "t", r->t, 0, r->nt, "s", err);
  if (!rc) rc = cg_h5w_dataset(w, "nsnapshots", r->nsnap, 0, r->nt, "1", err);
  int nfield = (o->nstress || o->npairs) ? CG_NFIELD : CG_F_MU;
  for (int f = 0; f < nfield && !rc; f++) {
    rc = cg_h5w_dataset(w, cg_field_name(f), r->f[f], r->nt, n, cg_field_units(f), err);
    snprintf(name, sizeof name, "%s_se", cg_field_name(f));
    if (!rc) rc = cg_h5w_dataset(w, name, r->se[f], r->nt, n, cg_field_units(f), err);
  }
  if (!rc) rc = cg_h5w_attr_str(w, "inputs", info->inputs, err);
  if (!rc && o->npairs) rc = cg_h5w_attr_str(w, "pair_inputs", info->pairs, err);
  if (!rc) rc = cg_h5w_attr_str(w, "axis", axis_names[o->axis], err);
  if (!rc) rc = cg_h5w_attr_str(w, "kernel", cg_kernel_name(k), err);
  if (!rc) rc = cg_h5w_attr_str(w, "kernel_evaluation",
                                o->exact || !strcmp(o->kernel, "bins") ? "exact, per particle"
                                : "sub-grid dz/16, cloud-in-cell", err);
  if (!rc) rc = cg_h5w_attr_double(w, "width", info->width, err);
  if (!rc) rc = cg_h5w_attr_double(w, "dz", g->dz, err);
  if (!rc) rc = cg_h5w_attr_double(w, "lo", g->lo, err);
  if (!rc) rc = cg_h5w_attr_double(w, "hi", g->hi, err);
  if (!rc) rc = cg_h5w_attr_str(w, "boundary", info->wall, err);
  if (!rc) rc = cg_h5w_attr_str(w, "window", info->window, err);
  if (!rc) rc = cg_h5w_attr_str(w, "temperature",
                                o->tmode == CG_T_PARTICLE ? "particle" : "consistent", err);
  if (!rc) rc = cg_h5w_attr_str(w, "stress", info->stress, err);
  if (!rc) {
    char types[16 * CG_MAXTYPES + 8] = "all";
    size_t len = 0;
    for (size_t k = 0; k < o->ntypes; k++)
      len += (size_t)snprintf(types + len, sizeof types - len, "%s%d", k ? "," : "", o->types[k]);
    rc = cg_h5w_attr_str(w, "atom_types", types, err);
  }
  if (!rc) rc = cg_h5w_attr_double(w, "mean_diameter", info->d, err);
  if (!rc) rc = cg_h5w_attr_double(w, "lateral_area", info->area, err);
  if (!rc) rc = cg_h5w_attr_double(w, "rho_p", o->rho_p, err);
  if (!rc) rc = cg_h5w_attr_double(w, "snapshots_read", (double)info->nread, err);
  if (!rc) rc = cg_h5w_attr_double(w, "snapshots_used", (double)info->nused, err);
  if (!rc) rc = cg_h5w_attr_double(w, "particles_outside_grid", (double)info->nout, err);
  if (!rc && info->steady) rc = cg_h5w_attr_double(w, "steady_start", info->t_start, err);
  if (!rc) rc = cg_h5w_attr_str(w, "code_version", EKMBENCH_VERSION, err);
  if (rc) { cg_h5w_abort(w); return rc; }
  return cg_h5w_commit(w, err);
}

static int write_csv(const cg_run_opts *o, const cg_grid *g, const results *r, cg_error *err)
{
  size_t len = strlen(o->csv) + 32;
  char *tmp = malloc(len);
  if (!tmp) return CG_ERROR(err, CG_ESYS, "out of memory");
  snprintf(tmp, len, "%s.tmp.%ld", o->csv, (long)getpid());
  FILE *fp = fopen(tmp, "w");
  if (!fp) {
    free(tmp);
    return CG_ERROR(err, CG_ESYS, "%s: cannot create the output file", o->csv);
  }
  int nfield = (o->nstress || o->npairs) ? CG_NFIELD : CG_F_MU;
  fprintf(fp, "t,%s", axis_names[o->axis]);
  for (int f = 0; f < nfield; f++) fprintf(fp, ",%s,%s_se", cg_field_name(f), cg_field_name(f));
  fputc('\n', fp);
  size_t n = g->n;
  for (size_t it = 0; it < r->nt; it++)
    for (size_t k = 0; k < n; k++) {
      fprintf(fp, "%.9g,%.9g", r->t[it], g->lo + ((double)k + 0.5) * g->dz);
      for (int f = 0; f < nfield; f++)
        fprintf(fp, ",%.9g,%.9g", r->f[f][it * n + k], r->se[f][it * n + k]);
      fputc('\n', fp);
    }
  int bad = ferror(fp);
  bad |= fclose(fp) != 0;
  if (bad || rename(tmp, o->csv) != 0) {
    unlink(tmp);
    free(tmp);
    return CG_ERROR(err, CG_ESYS, "%s: cannot write the output file", o->csv);
  }
  free(tmp);
  return CG_OK;
}

/* ---------- the run ---------- */

static int make_grid(const cg_run_opts *o, const source *src, double width, cg_grid *g,
                     cg_error *err)
{
  g->lo = o->have_range ? o->range_lo : src->lo;
  g->hi = o->have_range ? o->range_hi : src->hi;
  if (!(g->hi > g->lo))
    return CG_ERROR(err, CG_EUSAGE, "--range: expected lo < hi, got %g:%g", g->lo, g->hi);
  g->axis = o->axis;
  g->periodic = src->periodic && !o->have_range;
  g->reflect = !src->periodic && !o->have_range;
  double L = g->hi - g->lo;
  if (o->bins > 0) g->n = o->bins;
  else {
    double dz = o->dz > 0 ? o->dz : 0.5 * width;
    if (!(dz > 0))
      return CG_ERROR(err, CG_EUSAGE, "%s: no particles to size the grid: give --bins or --dz",
                      src->snap.where);
    double nb = ceil(L / dz - 1e-9);
    if (nb < 1) nb = 1;
    if (nb > 1e7) return CG_ERROR(err, CG_EUSAGE, "--dz: expected at most 1e7 bins, got %.3g", nb);
    g->n = (size_t)nb;
  }
  g->dz = L / (double)g->n;
  return CG_OK;
}

int cg_run(const cg_run_opts *o, cg_error *err)
{
  if (o->ninputs == 0) return CG_ERROR(err, CG_EUSAGE, "cg: expected at least one dump file");
  if (!o->out && !o->csv) return CG_ERROR(err, CG_EUSAGE, "cg: expected -o OUT.h5 and/or --csv OUT.csv");
  run_info info;
  memset(&info, 0, sizeof info);
  size_t used = 0;
  for (size_t i = 0; i < o->ninputs && used + 2 < sizeof info.inputs; i++)
    used += (size_t)snprintf(info.inputs + used, sizeof info.inputs - used, "%s%s",
                             i ? "\n" : "", o->inputs[i]);
  used = 0;
  for (size_t i = 0; i < o->npairs && used + 2 < sizeof info.pairs; i++)
    used += (size_t)snprintf(info.pairs + used, sizeof info.pairs - used, "%s%s", i ? "\n" : "", o->pairs[i]);
  if (o->nstress && o->npairs)
    return CG_ERROR(err, CG_EUSAGE, "cg: expected --stress or --pairs, not both (the contact stress would count twice)");
  if (o->npairs && o->npaircols != 9 && o->npaircols != 5)
    return CG_ERROR(err, CG_EUSAGE, "--pairs: expected --pair-columns with 9 (x1,y1,z1,x2,y2,z2,fx,fy,fz) "
                    "or 5 (id1,id2,fx,fy,fz) names");
  if (o->nstress)
    snprintf(info.stress, sizeof info.stress, "kinetic + per-atom %s %s %s %s %s %s",
             o->stress[0], o->stress[1], o->stress[2], o->stress[3], o->stress[4], o->stress[5]);
  else if (o->npairs)
    snprintf(info.stress, sizeof info.stress, "kinetic + contacts from pair dumps (branch line integral), %s",
             o->npaircols == 9 ? "positions" : "atom ids");
  else
    snprintf(info.stress, sizeof info.stress, "kinetic only");
  int rc = CG_OK;
  double t_start = -INFINITY;
  if (o->steady && (rc = find_steady(o, &t_start, err))) return rc;
  info.steady = o->steady;
  info.t_start = t_start;

  source src;
  source_init(&src, o);
  cg_kernel *k = NULL;
  cg_profile *prof = NULL;
  cg_grid g;
  memset(&g, 0, sizeof g);
  finisher fz;
  memset(&fz, 0, sizeof fz);
  double *prim = NULL;
  results r;
  memset(&r, 0, sizeof r);
  long cur_w = -1;
  double t0 = 0, tw0 = 0, tw1 = 0, tsel0 = 0, tsel1 = 0;
  size_t count = 0, nout = 0;
  while ((rc = source_next(&src, err)) == CG_OK) {
    if (src.t < t_start) continue;
    if (!prof) {
      double width = o->width > 0 ? o->width : (src.dcount > 0 ? src.dsum / src.dcount : 0.0);
      if (!(width > 0) && strcmp(o->kernel, "bins")) {
        rc = CG_ERROR(err, CG_EUSAGE, "%s: the first snapshot has no atoms: give --width", src.snap.where);
        break;
      }
      info.width = width;
      if ((rc = make_grid(o, &src, width, &g, err))) break;
      if ((rc = cg_kernel_alloc(&k, o->kernel, width, err))) break;
      if ((rc = cg_profile_alloc(&prof, k, &g, o->tmode, o->exact, err))) break;
      if ((rc = cg_blocks_alloc(&fz.b, CG_NPRIM * g.n, BLOCKS_MAX, err))) break;
      fz.g = &g;
      fz.mean = malloc(CG_NPRIM * g.n * sizeof(double));
      fz.fld = malloc(CG_NFIELD * g.n * sizeof(double));
      fz.bf = malloc(BLOCKS_MAX * CG_NFIELD * g.n * sizeof(double));
      fz.series = malloc(BLOCKS_MAX * sizeof(double));
      fz.work = malloc(BLOCKS_MAX * sizeof(double));
      prim = malloc(CG_NPRIM * g.n * sizeof(double));
      r.n = g.n;
      if (!fz.mean || !fz.fld || !fz.bf || !fz.series || !fz.work || !prim) {
        rc = CG_ERROR(err, CG_ESYS, "out of memory");
        break;
      }
      info.area = src.pt.area;
      info.wall = g.periodic ? "periodic" : g.reflect ? "walls: kernel reflected" : "open (--range)";
      t0 = src.t;
      tsel0 = src.t;
    }
    long wi = o->every ? (long)(count / o->every)
              : o->window > 0 ? (long)floor((src.t - t0) / o->window) : 0;
    if (wi != cur_w && cur_w >= 0) {
      double d = src.dcount > 0 ? src.dsum / src.dcount : info.width;
      if ((rc = finish_window(&fz, &r, 0.5 * (tw0 + tw1), d, o->rho_p, err))) break;
    }
    if (wi != cur_w) { cur_w = wi; tw0 = src.t; }
    tw1 = src.t;
    tsel1 = src.t;
    if ((rc = cg_profile_snapshot(prof, &src.pt, prim, err))) break;
    if (!g.periodic)
      for (size_t i = 0; i < src.pt.n; i++) nout += (src.pt.s[i] < g.lo || src.pt.s[i] > g.hi);
    cg_blocks_add(fz.b, prim);
    count++;
  }
  if (rc == CG_EOF) {
    rc = CG_OK;
    if (count == 0)
      rc = CG_ERROR(err, CG_EINPUT, "%s: no snapshots selected (%zu read)", o->inputs[0], src.nread);
  }
  info.d = src.dcount > 0 ? src.dsum / src.dcount : info.width;
  if (!rc) rc = finish_window(&fz, &r, 0.5 * (tw0 + tw1), info.d, o->rho_p, err);
  info.nread = src.nread;
  info.nused = count;
  if (!rc) {
    if (o->every)
      snprintf(info.window, sizeof info.window, "t = %.9g .. %.9g s, %zu snapshots, one profile per %zu snapshots",
               tsel0, tsel1, count, o->every);
    else if (o->window > 0)
      snprintf(info.window, sizeof info.window, "t = %.9g .. %.9g s, %zu snapshots, one profile per %.9g s",
               tsel0, tsel1, count, o->window);
    else
      snprintf(info.window, sizeof info.window, "t = %.9g .. %.9g s, %zu snapshots", tsel0, tsel1, count);
    info.nout = nout;
    if (nout && o->log)
      fprintf(o->log, "note: %zu particle-snapshots outside the grid [%.6g, %.6g] m (a shrink-wrapped box, or "
              "--range): only their kernel tails inside are counted\n", nout, g.lo, g.hi);
    if (src.nrepeat && o->log)
      fprintf(o->log, "note: skipped %zu snapshots whose step was already read\n", src.nrepeat);
    int wrote_h5 = 0;
    if (o->out && !(rc = write_h5(o, &g, &r, k, &info, err))) wrote_h5 = 1;
    if (!rc && o->csv) rc = write_csv(o, &g, &r, err);
    if (rc && wrote_h5) unlink(o->out); /* no partial results if the CSV failed */
    if (!rc && o->log)
      fprintf(o->log, "ekmcompare cg: %zu of %zu snapshots, %zu profile(s) x %zu bins (%s, width %.4g m, "
              "dz %.4g m) -> %s%s%s\n", count, src.nread, r.nt, g.n, k ? cg_kernel_name(k) : "?",
              info.width, g.dz, o->out ? o->out : "", o->out && o->csv ? ", " : "",
              o->csv ? o->csv : "");
  }
  source_close(&src);
  cg_kernel_free(k);
  cg_profile_free(prof);
  cg_blocks_free(fz.b);
  free(fz.mean); free(fz.fld); free(fz.bf); free(fz.series); free(fz.work);
  free(prim);
  results_free(&r);
  return rc;
}
