/* schema.h: the one table of the fields ekmbench writes and reads: name,
 * SI units (the `units` attribute of the HDF5 dataset) and a one-line
 * description.  ekm (continuum/h5out.c), ekmcompare's coarse-graining and
 * scoring take units from here; non-C readers (figures, tests) read the
 * same table from build/generated/fields.json (common/fields_json.c).
 * Standard errors "F_se" have their own entries, with F's units.
 */
#ifndef EKM_SCHEMA_H
#define EKM_SCHEMA_H

#include <stddef.h>

typedef struct {
    const char *name;        /* dataset name, e.g. "phi" */
    const char *units;       /* SI units string, e.g. "m/s", "1" dimensionless */
    const char *description; /* one line, what the values are */
} ekm_field;

/* The entry for name; NULL when the table has none. */
const ekm_field *ekm_field_lookup(const char *name);

/* Units / description of name; NULL when the table has none. */
const char *ekm_field_units(const char *name);
const char *ekm_field_description(const char *name);

/* The whole table, in order: ekm_field_at(i) for i < ekm_field_count(). */
size_t ekm_field_count(void);
const ekm_field *ekm_field_at(size_t i);

#endif
