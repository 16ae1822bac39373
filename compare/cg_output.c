/* cg_output.c: HDF5 and CSV outputs of `ekmcompare cg` (see cg_output.h). */
#include "ekm_version.h"
#include "cg_output.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5io.h"

static const char *const axis_names[3] = {"x", "y", "z"};

int cg_output_h5(const cg_run_opts *o, const cg_grid *g, const cg_window_results *r,
                 const cg_kernel *k, const cg_run_info *info, cg_error *err)
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

int cg_output_csv(const cg_run_opts *o, const cg_grid *g, const cg_window_results *r, cg_error *err)
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
