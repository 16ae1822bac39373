/* json_out.c: JSON documents written with jansson (json_out.h). */
#include "json_out.h"

#include <math.h>

#include "atomic.h"

json_t *ekm_json_number(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

int ekm_json_set(json_t *obj, const char *key, json_t *value, int *bad)
{
    /* json_object_set_new takes value also when it fails (and a NULL obj) */
    if (!value || json_object_set_new(obj, key, value) != 0) {
        *bad = 1;
        return -1;
    }
    return 0;
}

ekm_status ekm_json_dump(const json_t *root, FILE *fp, size_t flags, const char *path, ekm_error *err)
{
    if (json_dumpf(root, fp, flags) != 0 || fputc('\n', fp) == EOF)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the JSON", path);
    return EKM_OK;
}

ekm_status ekm_json_write(const char *path, const json_t *root, size_t flags, ekm_error *err)
{
    if (!root)
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory building the JSON", path);
    ekm_atomic out;
    ekm_status st = ekm_atomic_open(&out, path, err);
    if (st != EKM_OK)
        return st;
    st = ekm_json_dump(root, out.fp, flags, path, err);
    if (st != EKM_OK) {
        ekm_atomic_abort(&out);
        return st;
    }
    return ekm_atomic_commit(&out, err);
}
