/* resolve.c: the keys of the other tools' sections, their lookup rule and
 * defaults, and the sweep points (resolve.h, docs/resolved-scenario.md). */
#include "resolve.h"

#include "closure.h"

#include "number.h"
#include "tool_keys.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --- resolving --------------------------------------------------------------------- */

static ekm_status add_key(ekm_resolved *r, const char *name, const char *value, const char *from,
                          const char *as, ekm_error *err)
{
    ekm_resolve_key *k = realloc(r->keys, (r->n_keys + 1) * sizeof *k);
    if (!k)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory resolving the scenario");
    r->keys = k;
    k += r->n_keys++;
    snprintf(k->name, sizeof k->name, "%s", name);
    snprintf(k->value, sizeof k->value, "%s", value);
    snprintf(k->from, sizeof k->from, "%s", from);
    snprintf(k->as, sizeof k->as, "%s", as ? as : "");
    return EKM_OK;
}

static void entry_from(const ekm_scenario *s, const ekm_entry *e, char *buf, size_t size)
{
    if (e->origin == EKM_FROM_SET)
        snprintf(buf, size, "--set");
    else
        snprintf(buf, size, "%s:%d", e->origin == EKM_FROM_MATERIAL ? s->material_source : s->source,
                 e->line);
}

/* The entry of tool key section.base by the lookup rule: a --set of the
 * plain key, then <engine>.<size>.k, <size>.k, <engine>.k, k (a variant
 * only when its engine and size were given). */
static const ekm_entry *pick(const ekm_scenario *s, const char *section, const char *base, const char *engine,
                             const char *size)
{
    char name[4][64];
    snprintf(name[0], sizeof name[0], "%s.%s.%s.%s", section, engine, size, base);
    snprintf(name[1], sizeof name[1], "%s.%s.%s", section, size, base);
    snprintf(name[2], sizeof name[2], "%s.%s.%s", section, engine, base);
    snprintf(name[3], sizeof name[3], "%s.%s", section, base);
    const ekm_entry *plain = ekm_scenario_entry_find(s->tool_entries, s->n_tool_entries, name[3]);
    if (plain && plain->origin == EKM_FROM_SET)
        return plain;
    const int allowed[4] = {*engine && *size, *size != '\0', *engine != '\0', 1};
    for (int i = 0; i < 4; i++) {
        const ekm_entry *e =
            allowed[i] ? ekm_scenario_entry_find(s->tool_entries, s->n_tool_entries, name[i]) : NULL;
        if (e)
            return e;
    }
    return NULL;
}

static int section_given(const ekm_scenario *s, const char *section)
{
    const size_t n = strlen(section);
    for (size_t i = 0; i < s->n_tool_entries; i++)
        if (strncmp(s->tool_entries[i].name, section, n) == 0 && s->tool_entries[i].name[n] == '.')
            return 1;
    return 0;
}

/* The family of a sweep, for the one-sweep-only rule, and its name. */
static int sweep_family(ekm_sweep_kind k)
{
    return k == EKM_SWEEP_THETA ? 1 : k == EKM_SWEEP_SOURCE ? 3 : k == EKM_SWEEP_NONE ? 0 : 2;
}

static const char *sweep_family_name(ekm_sweep_kind k)
{
    return k == EKM_SWEEP_THETA ? "inclined-flow" : k == EKM_SWEEP_SOURCE ? "sand-pile" : "simple-shear";
}

/* Which sweep the scenario's [dem] keys (any variant) make it: an inclined
 * flow (t_settle t_flow angles: over the angles), a simple shear at fixed
 * volume (strain rates phis: over phis x rates), a simple shear at fixed
 * pressure (strain rates pressures: over pressures x rates), a sand pile
 * (pile_mass pour_rate pour_speed pour_height source_widths: over the
 * source widths), or none. */
static ekm_status sweep_of(const ekm_scenario *s, ekm_sweep_kind *kind, ekm_error *err)
{
    *kind = EKM_SWEEP_NONE;
    const char *first = NULL, *list = NULL; /* the first sweep key; the phis or pressures key */
    for (size_t i = 0; i < s->n_tool_entries; i++) {
        const ekm_entry *e = &s->tool_entries[i];
        const char *base;
        if (strncmp(e->name, "dem.", 4) != 0 || !ekm_tool_keys_split(e->name + 4, &base))
            continue;
        const ekm_tool_key *tk = ekm_tool_keys_find("dem", base);
        if (!tk || tk->sweep == EKM_SWEEP_NONE)
            continue;
        char from[600];
        entry_from(s, e, from, sizeof from);
        if (*kind != EKM_SWEEP_NONE && sweep_family(tk->sweep) != sweep_family(*kind)) {
            const int pile = tk->sweep == EKM_SWEEP_SOURCE || *kind == EKM_SWEEP_SOURCE;
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [dem] %s: a key of the %s sweep, but [dem] %s is one of the %s sweep: "
                            "expected the keys of one sweep only (inclined flow: t_settle t_flow angles; "
                            "simple shear: strain rates, and phis or pressures%s)",
                            from, e->name + 4, sweep_family_name(tk->sweep), first, sweep_family_name(*kind),
                            pile ? "; sand pile: pile_mass pour_rate pour_speed pour_height source_widths"
                                 : "");
        }
        if ((tk->sweep == EKM_SWEEP_PHI_RATE && *kind == EKM_SWEEP_P_RATE) ||
            (tk->sweep == EKM_SWEEP_P_RATE && *kind == EKM_SWEEP_PHI_RATE))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [dem] %s: a list of the %s sweep, but [dem] %s is one of the %s sweep: "
                            "expected phis (shear at fixed volume) or pressures (shear at fixed pressure), "
                            "not both",
                            from, e->name + 4,
                            tk->sweep == EKM_SWEEP_P_RATE ? "pressure x rate" : "phi x rate", list,
                            *kind == EKM_SWEEP_P_RATE ? "pressure x rate" : "phi x rate");
        if (!first)
            first = e->name + 4;
        if (tk->sweep == EKM_SWEEP_PHI_RATE || tk->sweep == EKM_SWEEP_P_RATE) {
            *kind = tk->sweep;
            list = e->name + 4;
        } else if (*kind == EKM_SWEEP_NONE) {
            *kind = tk->sweep;
        }
    }
    if (*kind == EKM_SWEEP_SHEAR)
        *kind = EKM_SWEEP_PHI_RATE;
    return EKM_OK;
}

/* [dem] settle_max, the latest end of the sand pile's settling (default
 * t_end: none), cannot end the run before t_end: an error naming where
 * settle_max was given (docs/scenario-format.md). */
static ekm_status check_settle_max(const ekm_resolved *r, ekm_error *err)
{
    const ekm_resolve_key *sm = ekm_resolve_find(r, "dem.settle_max"), *te = ekm_resolve_find(r, "dem.t_end");
    if (!sm || !te)
        return EKM_OK;
    const double x = strtod(sm->value, NULL), t = strtod(te->value, NULL);
    if (x >= t)
        return EKM_OK;
    const int te_given = strcmp(te->from, "default") != 0;
    return EKM_FAIL(err, EKM_EINPUT, "%s: [dem] %s: expected a time >= [dem] t_end = %s s (%s%s), got '%s'",
                    sm->from, sm->as[0] ? sm->as : "settle_max", te->value,
                    te_given ? "" : "the default: ", te_given ? te->from : "[run] t_end", sm->value);
}

static ekm_status resolve_tool_section(const ekm_scenario *s, ekm_resolved *r, const char *section,
                                       ekm_sweep_kind sweep, ekm_error *err)
{
    for (size_t i = 0; i < ekm_tool_keys_count(); i++) {
        const ekm_tool_key *tk = ekm_tool_keys_at(i);
        if (strcmp(tk->section, section) != 0)
            continue;
        char name[64], from[600], value[EKM_VALUE_MAX];
        snprintf(name, sizeof name, "%s.%s", section, tk->key);
        const ekm_entry *e = pick(s, section, tk->key, r->engine, r->size);
        ekm_status st = EKM_OK;
        if (e) {
            entry_from(s, e, from, sizeof from);
            const char *written = e->name + strlen(section) + 1;
            st = add_key(r, name, e->value, from, strcmp(written, tk->key) != 0 ? written : NULL, err);
        } else {
            /* defaults: documented, or derived from another key */
            const ekm_resolve_key *src = NULL;
            value[0] = '\0';
            if (tk->dflt)
                snprintf(value, sizeof value, "%s", tk->dflt);
            else if (strcmp(name, "dem.restitution_input") == 0)
                src = ekm_resolve_find(r, "dem.restitution");
            else if (strcmp(name, "dem.t_end") == 0)
                src = ekm_resolve_find(r, "run.t_end");
            else if (strcmp(name, "dem.settle_max") == 0)
                src = ekm_resolve_find(r, "dem.t_end");
            else if (strcmp(name, "dem.pressure") == 0)
                src = ekm_resolve_find(r, "top.pressure");
            else if (strcmp(name, "dem.angles") == 0 && sweep == EKM_SWEEP_THETA)
                src = ekm_resolve_find(r, "gravity.angle");
            else if (strcmp(name, "dem.phis") == 0 && sweep == EKM_SWEEP_PHI_RATE)
                src = ekm_resolve_find(r, "initial.phi");
            else if (strcmp(name, "dem.rates") == 0 &&
                     (sweep == EKM_SWEEP_PHI_RATE || sweep == EKM_SWEEP_P_RATE))
                /* the imposed rate of a rate-held top wall, else the walls'
                 * (as scripts/dem/run.sh computed it: awk printf "%.10g") */
                snprintf(value, sizeof value, "%.10g",
                         !isnan(s->top.shear_rate) ? s->top.shear_rate
                                                   : (s->top.velocity - s->bottom.velocity) / s->length);
            if (src)
                snprintf(value, sizeof value, "%s", src->value);
            if (value[0])
                st = add_key(r, name, value, "default", NULL, err);
        }
        if (st != EKM_OK)
            return st;
    }
    if (strcmp(section, "dem") == 0)
        return check_settle_max(r, err);
    return EKM_OK;
}

/* The blank-separated items of a list, each at most 63 characters. */
typedef struct {
    size_t n;
    char item[EKM_VALUE_MAX / 2][64];
} item_list;

static ekm_status split_list(const ekm_resolve_key *k, item_list *out, ekm_error *err)
{
    out->n = 0;
    for (const char *p = k->value + strspn(k->value, EKM_NUMBER_BLANKS); *p;
         p += strspn(p, EKM_NUMBER_BLANKS)) {
        const size_t len = strcspn(p, EKM_NUMBER_BLANKS);
        const char *key = k->as[0] ? k->as : k->name + 4;
        if (len >= sizeof out->item[0])
            return EKM_FAIL(err, EKM_EINPUT, "%s: [dem] %s: list item longer than %zu characters", k->from,
                            key, sizeof out->item[0] - 1);
        for (size_t j = 0; j < out->n; j++)
            if (strlen(out->item[j]) == len && strncmp(out->item[j], p, len) == 0)
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s: [dem] %s: value '%s' given twice (each point needs its own tag)",
                                k->from, key, out->item[j]);
        snprintf(out->item[out->n++], sizeof out->item[0], "%.*s", (int)len, p);
        p += len;
    }
    return EKM_OK;
}

/* Where the value of a sweep list came from, for a message blaming it: its
 * FILE:LINE or --set; a derived default (dem.phis: [initial] phi, dem.rates:
 * the walls' rate) names the key it was derived from, and says so in why. */
static void blame_of(const ekm_scenario *s, const ekm_resolved *r, const ekm_resolve_key *k, char *from,
                     size_t from_size, char *why, size_t why_size)
{
    snprintf(from, from_size, "%s", k->from);
    why[0] = '\0';
    if (strcmp(k->from, "default") != 0)
        return;
    const char *source = NULL;
    if (strcmp(k->name, "dem.phis") == 0) {
        source = "initial.phi";
        snprintf(why, why_size, " (the default: [initial] phi)");
    } else if (strcmp(k->name, "dem.rates") == 0) {
        source = !isnan(s->top.shear_rate) ? "top.shear_rate" : "top.velocity";
        snprintf(why, why_size, "%s",
                 !isnan(s->top.shear_rate)
                     ? " (the default: [top] shear_rate)"
                     : " (the default: ([top] velocity - [bottom] velocity) / [domain] length)");
        if (isnan(s->top.shear_rate) && !ekm_scenario_entry_find(s->entries, s->n_entries, "top.velocity"))
            source = "bottom.velocity";
    }
    const ekm_resolve_key *src = source ? ekm_resolve_find(r, source) : NULL;
    if (src && strcmp(src->from, "--set") == 0)
        snprintf(from, from_size, "--set %s", source);
    else
        snprintf(from, from_size, "%s", src && strcmp(src->from, "default") != 0 ? src->from : s->source);
}

/* Every item of a [dem] sweep list in (lo, hi) (hi <= 0: no upper bound). */
static ekm_status check_sweep_items(const ekm_scenario *s, const ekm_resolved *r, const ekm_resolve_key *k,
                                    const item_list *l, double lo, double hi, const char *expected,
                                    ekm_error *err)
{
    const char *key = k->as[0] ? k->as : k->name + 4;
    for (size_t i = 0; i < l->n; i++) {
        const double x = strtod(l->item[i], NULL);
        if (!(x > lo) || (hi > 0 && !(x < hi))) {
            char from[600], why[96];
            blame_of(s, r, k, from, sizeof from, why, sizeof why);
            return EKM_FAIL(err, EKM_EINPUT, "%s: [dem] %s: expected %s, got '%s'%s", from, key, expected,
                            l->item[i], why);
        }
    }
    return EKM_OK;
}

static ekm_resolve_point *add_point(ekm_resolved *r, ekm_error *err)
{
    ekm_resolve_point *p = realloc(r->points, (r->n_points + 1) * sizeof *p);
    if (!p) {
        EKM_FAIL(err, EKM_ENOMEM, "out of memory resolving the scenario");
        return NULL;
    }
    r->points = p;
    p += r->n_points++;
    memset(p, 0, sizeof *p);
    return p;
}

/* One point per item of a one-variable sweep: tag PREFIX<item> (none for a
 * single item), the variable VAR = item and, with KEY, the EKM set
 * KEY=item. */
static ekm_status add_list_points(ekm_resolved *r, const item_list *items, const char *prefix,
                                  const char *var, const char *key, ekm_error *err)
{
    for (size_t i = 0; i < items->n; i++) {
        ekm_resolve_point *p = add_point(r, err);
        if (!p)
            return EKM_ENOMEM;
        if (items->n > 1)
            snprintf(p->tag, sizeof p->tag, "%s%s", prefix, items->item[i]);
        p->n_vars = 1;
        snprintf(p->var_name[0], sizeof p->var_name[0], "%s", var);
        snprintf(p->var_value[0], sizeof p->var_value[0], "%s", items->item[i]);
        if (key) {
            p->n_sets = 1;
            snprintf(p->set[0], sizeof p->set[0], "%s=%s", key, items->item[i]);
        }
    }
    return EKM_OK;
}

/* The dump_every of a shear point with [dem] dump_strain: one frame every
 * dump_strain of shear, int(dump_strain / (rate dt) + 0.5) steps, at least
 * 1 (the arithmetic of the awk line run.sh had). */
static ekm_status dump_every_of(const ekm_resolve_key *dump_strain, const ekm_resolve_key *dt,
                                const ekm_resolve_key *rates, const char *rate, char *out, size_t size,
                                ekm_error *err)
{
    const char *key = dump_strain->as[0] ? dump_strain->as : "dump_strain";
    if (!dt)
        return EKM_FAIL(err, EKM_EINPUT, "%s: [dem] %s: needs [dem] dt (dump_every = %s / (rate dt))",
                        dump_strain->from, key, key);
    const double strain = strtod(dump_strain->value, NULL), r = strtod(rate, NULL),
                 step = strtod(dt->value, NULL);
    if (!(strain > 0) || !(r > 0) || !(step > 0))
        return EKM_FAIL(
            err, EKM_EINPUT,
            "%s: [dem] %s: expected dump_strain, dt and every rate > 0 (got dump_strain %s, dt %s, "
            "rate %s of [dem] %s)",
            dump_strain->from, key, dump_strain->value, dt->value, rate, rates->as[0] ? rates->as : "rates");
    const double n = strain / (r * step) + 0.5;
    if (!(n < 2147483647.0))
        return EKM_FAIL(err, EKM_EINPUT,
                        "%s: [dem] %s: dump_every %s / (%s %s) exceeds the largest step count",
                        dump_strain->from, key, dump_strain->value, rate, dt->value);
    const long every = (long)n;
    snprintf(out, size, "%ld", every < 1 ? 1L : every);
    return EKM_OK;
}

/* The EKM's source and floor of a sand-pile point of width W [d] from the
 * DEM's keys (docs/scenario-format.md "The sweep"), each set made when its
 * keys are resolved (a size's keys: --size):
 *   top.inlet_width = W d                        [m]
 *   top.phi = q / (rho_p pour_speed W d), q = k pour_rate / (ly d)
 *             (the mass flux per unit depth [kg/(m s)]; k = 2 for a sieve,
 *             W >= plate_width, which pours 2 pile_mass at 2 pour_rate as
 *             the decks do, else 1)
 *   top.w = -pour_speed                          [m/s]
 *   top.t_stop = pile_mass / pour_rate           [s]
 *   bottom.plate_width = plate_width d           [m]
 *   run.t_end = [dem] t_end                      [s]
 * (d = [dem] diameter). With a size given (r->size) every key is needed:
 * a missing one is an error naming it. */
static ekm_status pile_sets(const ekm_scenario *s, const ekm_resolved *r, const char *width,
                            ekm_resolve_point *p, ekm_error *err)
{
    static const char *const need[] = {"dem.diameter",  "dem.ly",          "dem.pour_rate", "dem.pour_speed",
                                       "dem.pile_mass", "dem.plate_width", "dem.t_end"};
    const ekm_resolve_key *k[sizeof need / sizeof need[0]];
    for (size_t i = 0; i < sizeof need / sizeof need[0]; i++) {
        k[i] = ekm_resolve_find(r, need[i]);
        if (!k[i] && r->size[0])
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: [dem] %s: missing for size %s (the sand-pile point's ekm_set, the EKM's "
                            "source and plate, is made from it)",
                            s->source, need[i] + 4, r->size);
    }
    const ekm_resolve_key *d = k[0], *ly = k[1], *rate = k[2], *speed = k[3], *mass = k[4], *plate = k[5],
                          *t_end = k[6];
    const double W = strtod(width, NULL);
    p->n_sets = 0;
    if (!d)
        return EKM_OK;
    const double dm = strtod(d->value, NULL);
    snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.inlet_width=%.10g", W * dm);
    if (rate && ly && speed && plate) {
        const int sieve = W >= strtod(plate->value, NULL) - 1e-9;
        const double q = (1 + sieve) * strtod(rate->value, NULL) / (strtod(ly->value, NULL) * dm);
        const double v = strtod(speed->value, NULL);
        snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.phi=%.10g",
                 q / (s->material.rho_p * v * W * dm));
        snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.w=%.10g", -v);
    }
    if (mass && rate)
        snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.t_stop=%.10g",
                 strtod(mass->value, NULL) / strtod(rate->value, NULL));
    if (plate)
        snprintf(p->set[p->n_sets++], sizeof p->set[0], "bottom.plate_width=%.10g",
                 strtod(plate->value, NULL) * dm);
    if (t_end)
        snprintf(p->set[p->n_sets++], sizeof p->set[0], "run.t_end=%.10g", strtod(t_end->value, NULL));
    return EKM_OK;
}

static ekm_status build_points(const ekm_scenario *s, ekm_resolved *r, ekm_sweep_kind sweep, ekm_error *err)
{
    const ekm_resolve_key *angles = ekm_resolve_find(r, "dem.angles");
    const ekm_resolve_key *phis = ekm_resolve_find(r, "dem.phis"), *rates = ekm_resolve_find(r, "dem.rates");
    const ekm_resolve_key *pressures = ekm_resolve_find(r, "dem.pressures");
    const ekm_resolve_key *dump_strain = ekm_resolve_find(r, "dem.dump_strain"),
                          *dt = ekm_resolve_find(r, "dem.dt");
    item_list *a = calloc(2, sizeof *a);
    if (!a)
        return EKM_FAIL(err, EKM_ENOMEM, "out of memory resolving the scenario");
    ekm_status st = EKM_OK;
    if (sweep == EKM_SWEEP_THETA && angles) {
        st = split_list(angles, &a[0], err);
        if (st == EKM_OK)
            st = add_list_points(r, &a[0], "theta", "theta", "gravity.angle", err);
    } else if ((sweep == EKM_SWEEP_PHI_RATE && phis && rates) ||
               (sweep == EKM_SWEEP_P_RATE && pressures && rates)) {
        const int by_p = sweep == EKM_SWEEP_P_RATE;
        st = split_list(by_p ? pressures : phis, &a[0], err);
        char phi_range[64];
        snprintf(phi_range, sizeof phi_range, "volume fractions in (0, phi_cp = %g)", s->material.phi_cp);
        if (st == EKM_OK)
            st = by_p ? check_sweep_items(s, r, pressures, &a[0], 0.0, 0.0, "normal stresses > 0 [Pa]", err)
                      : check_sweep_items(s, r, phis, &a[0], 0.0, s->material.phi_cp, phi_range, err);
        if (st == EKM_OK)
            st = split_list(rates, &a[1], err);
        if (st == EKM_OK)
            st = check_sweep_items(s, r, rates, &a[1], 0.0, 0.0, "shear rates > 0 [1/s]", err);
        const size_t n = a[0].n * a[1].n;
        for (size_t i = 0; i < a[0].n && st == EKM_OK; i++)
            for (size_t j = 0; j < a[1].n && st == EKM_OK; j++) {
                ekm_resolve_point *p = add_point(r, err);
                if (!p) {
                    st = EKM_ENOMEM;
                    break;
                }
                if (n > 1)
                    snprintf(p->tag, sizeof p->tag, "%s%s-rate%s", by_p ? "p" : "phi", a[0].item[i],
                             a[1].item[j]);
                p->n_vars = 2;
                snprintf(p->var_name[0], sizeof p->var_name[0], "%s", by_p ? "pressure" : "phi");
                snprintf(p->var_value[0], sizeof p->var_value[0], "%s", a[0].item[i]);
                snprintf(p->var_name[1], sizeof p->var_name[1], "rate");
                snprintf(p->var_value[1], sizeof p->var_value[1], "%s", a[1].item[j]);
                if (dump_strain) {
                    st = dump_every_of(dump_strain, dt, rates, a[1].item[j], p->var_value[2],
                                       sizeof p->var_value[2], err);
                    snprintf(p->var_name[2], sizeof p->var_name[2], "dump_every");
                    p->n_vars = 3;
                }
                /* the walls at -+ R L/2 (r * L / 2 printed "%.10g": the digits
                 * the DEM campaign has always used); a pressure point holds
                 * the top wall at P and its speed at [bottom] velocity + R gap
                 * (bc.h), the bottom at -R L/2 of the initial gap */
                const double v = strtod(a[1].item[j], NULL) * s->length / 2;
                p->n_sets = 0;
                if (by_p) {
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.pressure=%s", a[0].item[i]);
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.shear_rate=%s", a[1].item[j]);
                } else {
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "initial.phi=%s", a[0].item[i]);
                    snprintf(p->set[p->n_sets++], sizeof p->set[0], "top.velocity=%.10g", v);
                }
                snprintf(p->set[p->n_sets++], sizeof p->set[0], "bottom.velocity=%.10g", -v);
            }
    } else if (sweep == EKM_SWEEP_SOURCE) {
        const ekm_resolve_key *widths = ekm_resolve_find(r, "dem.source_widths");
        if (!widths)
            st = EKM_FAIL(err, EKM_EINPUT,
                          "%s: [dem] source_widths: missing for this engine and size (a sand pile needs "
                          "the widths of its sources [d])",
                          s->source);
        if (st == EKM_OK)
            st = split_list(widths, &a[0], err);
        if (st == EKM_OK)
            st = check_sweep_items(s, r, widths, &a[0], 0.0, 0.0, "source widths > 0 [d]", err);
        const size_t first = r->n_points;
        if (st == EKM_OK)
            st = add_list_points(r, &a[0], "source", "source_width", NULL, err);
        for (size_t i = 0; st == EKM_OK && i < a[0].n; i++)
            st = pile_sets(s, r, a[0].item[i], &r->points[first + i], err);
    } else if (sweep == EKM_SWEEP_P_RATE) {
        st = EKM_FAIL(err, EKM_EINPUT,
                      "%s: [dem] pressures: missing for this engine and size (only other variants are given; "
                      "a pressure x rate sweep needs its list of normal stresses)",
                      s->source);
    } else if (!add_point(r, err)) {
        st = EKM_ENOMEM;
    }
    free(a);
    return st;
}

ekm_status ekm_resolve(const ekm_scenario *s, const char *engine, const char *size, ekm_resolved *r,
                       ekm_error *err)
{
    memset(r, 0, sizeof *r);
    if (engine && !ekm_tool_keys_is_engine(engine))
        return EKM_FAIL(err, EKM_EINPUT, "--engine %s: unknown engine (expected liggghts or lammps)", engine);
    if (size && !ekm_tool_keys_is_size(size))
        return EKM_FAIL(err, EKM_EINPUT, "--size %s: unknown size (expected smoke or ref)", size);
    snprintf(r->engine, sizeof r->engine, "%s", engine ? engine : "");
    snprintf(r->size, sizeof r->size, "%s", size ? size : "");
    ekm_status st = EKM_OK;
    /* ekm's sections: the value given, else the default of the loaded scenario */
    for (size_t i = 0; i < ekm_scenario_key_count() && st == EKM_OK; i++) {
        const char *section, *key;
        ekm_scenario_key_name(i, &section, &key);
        char name[64], from[600], value[EKM_VALUE_MAX];
        snprintf(name, sizeof name, "%s.%s", section, key);
        if (strcmp(section, "material") == 0 && !ekm_closure_reads_ekm_key(s->closure, key))
            continue; /* a key the scenario's closure does not read */
        const ekm_entry *e = ekm_scenario_entry_find(s->entries, s->n_entries, name);
        if (e) {
            entry_from(s, e, from, sizeof from);
            st = add_key(r, name, e->value, from, NULL, err);
        } else if (ekm_scenario_key_default(s, i, value, sizeof value)) {
            st = add_key(r, name, value, "default", NULL, err);
        }
    }
    /* the closure's own [material] keys (closure.h), each given */
    for (size_t k = 0; k < s->closure->nparams && st == EKM_OK; k++) {
        char name[64], from[600];
        snprintf(name, sizeof name, "material.%s", s->closure->params[k].key);
        const ekm_entry *e = ekm_scenario_entry_find(s->entries, s->n_entries, name);
        if (e) {
            entry_from(s, e, from, sizeof from);
            st = add_key(r, name, e->value, from, NULL, err);
        }
    }
    ekm_sweep_kind sweep = EKM_SWEEP_NONE;
    if (st == EKM_OK)
        st = sweep_of(s, &sweep, err);
    if (st == EKM_OK && section_given(s, "dem"))
        st = resolve_tool_section(s, r, "dem", sweep, err);
    if (st == EKM_OK && section_given(s, "compare"))
        st = resolve_tool_section(s, r, "compare", EKM_SWEEP_NONE, err);
    if (st == EKM_OK && section_given(s, "campaign"))
        st = resolve_tool_section(s, r, "campaign", EKM_SWEEP_NONE, err);
    if (st == EKM_OK)
        st = build_points(s, r, section_given(s, "dem") ? sweep : EKM_SWEEP_NONE, err);
    return st;
}

ekm_status ekm_resolve_keep_point(ekm_resolved *r, const char *tag, ekm_error *err)
{
    for (size_t i = 0; i < r->n_points; i++)
        if (strcmp(r->points[i].tag, tag) == 0) {
            r->points[0] = r->points[i];
            r->n_points = 1;
            return EKM_OK;
        }
    char tags[800] = "";
    size_t used = 0;
    for (size_t i = 0; i < r->n_points && used < sizeof tags; i++) {
        int n = snprintf(tags + used, sizeof tags - used, "%s%s", i ? " " : "",
                         r->points[i].tag[0] ? r->points[i].tag : "\"\"");
        if (n < 0)
            break;
        used += (size_t)n;
    }
    return EKM_FAIL(err, EKM_EINPUT, "--point %s: unknown point (the points are: %s)", tag, tags);
}

const ekm_resolve_key *ekm_resolve_find(const ekm_resolved *r, const char *name)
{
    for (size_t i = 0; i < r->n_keys; i++)
        if (strcmp(r->keys[i].name, name) == 0)
            return &r->keys[i];
    return NULL;
}

void ekm_resolve_free(ekm_resolved *r)
{
    if (!r)
        return;
    free(r->keys);
    free(r->points);
    r->keys = NULL;
    r->points = NULL;
    r->n_keys = r->n_points = 0;
}
