/* common/schema: the table agrees with the units docs/output-format.md
 * documents for ekm's datasets, has no duplicates or empty entries, gives
 * every field's standard error its field's units, and build/generated/
 * fields.json is exactly the table. */
#include <jansson.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "schema.h"
#include "testutil.h"

static void test_table_well_formed(void **state)
{
    (void)state;
    assert_true(ekm_field_count() > 20);
    for (size_t i = 0; i < ekm_field_count(); i++) {
        const ekm_field *f = ekm_field_at(i);
        assert_non_null(f);
        assert_true(f->name[0] && f->units[0] && f->description[0]);
        assert_ptr_equal(ekm_field_lookup(f->name), f); /* no duplicates */
        const size_t len = strlen(f->name);
        if (len > 3 && strcmp(f->name + len - 3, "_se") == 0) {
            char base[64];
            snprintf(base, sizeof base, "%.*s", (int)(len - 3), f->name);
            assert_non_null(ekm_field_lookup(base));
            assert_string_equal(ekm_field_units(base), f->units);
        }
    }
    assert_null(ekm_field_at(ekm_field_count()));
    assert_null(ekm_field_lookup("nope"));
    assert_null(ekm_field_units("nope"));
    assert_string_equal(ekm_field_units("T"), "m^2/s^2");
    assert_string_equal(ekm_field_units("rho"), "kg/m^3");
    assert_non_null(ekm_field_description("phi"));
}

/* Rows "| `/phi` | [nt][nz] float64 | `1` | ..." of the output format. */
static void test_matches_output_format_doc(void **state)
{
    (void)state;
    char *doc = tu_read_file(EKM_SOURCE_DIR "/docs/output-format.md");
    assert_non_null(doc);
    int rows = 0;
    for (char *line = strtok(doc, "\n"); line; line = strtok(NULL, "\n")) {
        char name[64], units[128];
        if (sscanf(line, "| `/%63[^`]` | %*[^|]| `%127[^`]` |", name, units) != 2)
            continue;
        const char *u = ekm_field_units(name);
        if (!u)
            fail_msg("docs/output-format.md lists /%s, the schema does not", name);
        assert_string_equal(u, units);
        rows++;
    }
    free(doc);
    assert_int_equal(rows, 11); /* z t phi vx vz T P sxz szz regime gap */
}

static void test_generated_json_is_the_table(void **state)
{
    (void)state;
    json_error_t jerr;
    json_t *root = json_load_file(EKM_FIELDS_JSON, 0, &jerr);
    if (!root)
        fail_msg("%s: %s (line %d)", EKM_FIELDS_JSON, jerr.text, jerr.line);
    json_t *fields = json_object_get(root, "fields");
    assert_true(json_is_object(fields));
    assert_int_equal(json_object_size(fields), ekm_field_count());
    size_t i = 0;
    const char *key;
    json_t *value;
    json_object_foreach(fields, key, value)
    {
        const ekm_field *f = ekm_field_at(i++);
        assert_string_equal(key, f->name); /* in the table's order */
        assert_string_equal(json_string_value(json_object_get(value, "units")), f->units);
        assert_string_equal(json_string_value(json_object_get(value, "description")), f->description);
    }
    json_decref(root);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_well_formed),
        cmocka_unit_test(test_matches_output_format_doc),
        cmocka_unit_test(test_generated_json_is_the_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
