/* ekm_fields_json OUT.json: the field table of schema.h as JSON, for the
 * readers that are not C (figures, tests):
 *   {"fields": {"phi": {"units": "1", "description": "..."}, ...}}
 * in the table's order.  Run at build time (common/CMakeLists.txt). */
#include <jansson.h>
#include <stdio.h>

#include "atomic.h"
#include "json_out.h"
#include "schema.h"

int main(int argc, char **argv)
{
    ekm_error err = {0};
    if (argc != 2) {
        fprintf(stderr, "usage: ekm_fields_json OUT.json\n");
        return ekm_status_exit_code(EKM_EUSAGE);
    }
    ekm_status st = ekm_atomic_install_signal_cleanup(&err);
    json_t *root = json_object(), *fields = json_object();
    if (st == EKM_OK && (!root || !fields || json_object_set_new(root, "fields", fields) != 0))
        st = EKM_FAIL(&err, EKM_ENOMEM, "out of memory");
    for (size_t i = 0; i < ekm_field_count() && st == EKM_OK; i++) {
        const ekm_field *f = ekm_field_at(i);
        json_t *entry = json_pack("{s:s, s:s}", "units", f->units, "description", f->description);
        if (!entry || json_object_set_new(fields, f->name, entry) != 0)
            st = EKM_FAIL(&err, EKM_ENOMEM, "out of memory");
    }
    if (st == EKM_OK)
        st = ekm_json_write(argv[1], root, JSON_INDENT(2) | JSON_PRESERVE_ORDER, &err);
    json_decref(root);
    if (st != EKM_OK)
        ekm_error_print("ekm_fields_json", &err);
    return ekm_status_exit_code(st);
}
