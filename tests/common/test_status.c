/* common/status: the exit-code table is docs/exit-codes.md's, row by row;
 * the error record's messages, input and source locations; the printer. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "status.h"
#include "testutil.h"

static const ekm_status ALL[] = {EKM_EOF,      EKM_OK,        EKM_EINPUT, EKM_ENOMEM,     EKM_EIO,
                                 EKM_ENUMERIC, EKM_EINTERNAL, EKM_EUSAGE, EKM_ENOTSTEADY, EKM_EUNAVAILABLE};
enum { N_ALL = sizeof ALL / sizeof ALL[0] };

/* Every `EKM_X` in a row "| N | `EKM_X`, `EKM_Y` | ..." of the doc must map
 * to N; every status except EKM_EOF must appear in exactly one row. */
static void test_exit_codes_match_the_doc(void **state)
{
    (void)state;
    char *doc = tu_read_file(EKM_SOURCE_DIR "/docs/exit-codes.md");
    assert_non_null(doc);
    int seen[N_ALL] = {0};
    int rows = 0;
    for (char *line = strtok(doc, "\n"); line; line = strtok(NULL, "\n")) {
        int code;
        int used = 0;
        if (sscanf(line, "| %d |%n", &code, &used) != 1 || used == 0)
            continue;
        char *cell_end = strchr(line + used, '|');
        assert_non_null(cell_end);
        *cell_end = '\0';
        for (char *p = strstr(line + used, "`EKM_"); p; p = strstr(p + 1, "`EKM_")) {
            char sym[32];
            assert_int_equal(sscanf(p + 1, "%31[A-Z_]", sym), 1);
            int found = 0;
            for (int i = 0; i < N_ALL; i++)
                if (strcmp(ekm_status_symbol(ALL[i]), sym) == 0) {
                    assert_int_equal(ekm_status_exit_code(ALL[i]), code);
                    seen[i]++;
                    found = 1;
                }
            if (!found)
                fail_msg("docs/exit-codes.md names %s, which status.h does not have", sym);
            rows++;
        }
    }
    free(doc);
    assert_int_equal(rows, N_ALL - 1);
    for (int i = 0; i < N_ALL; i++)
        assert_int_equal(seen[i], ALL[i] == EKM_EOF ? 0 : 1);
    /* end of data is not a failure */
    assert_int_equal(ekm_status_exit_code(EKM_EOF), 0);
    /* the values themselves (the contract the shell scripts copy) */
    assert_int_equal(ekm_status_exit_code(EKM_EUSAGE), 1);
    assert_int_equal(ekm_status_exit_code(EKM_EINPUT), 2);
    assert_int_equal(ekm_status_exit_code(EKM_EIO), 3);
    assert_int_equal(ekm_status_exit_code(EKM_ENUMERIC), 4);
    assert_int_equal(ekm_status_exit_code(EKM_EINTERNAL), 5);
    assert_int_equal(ekm_status_exit_code(EKM_ENOMEM), 5);
    assert_int_equal(ekm_status_exit_code(EKM_ENOTSTEADY), 6);
    assert_int_equal(ekm_status_exit_code(EKM_EUNAVAILABLE), 7);
}

static void test_fail_records_source(void **state)
{
    (void)state;
    ekm_error err;
    memset(&err, 0x5a, sizeof err);
    const int line = __LINE__ + 1;
    ekm_status st = EKM_FAIL(&err, EKM_EIO, "%s: cannot write", "out.h5");
    assert_int_equal(st, EKM_EIO);
    assert_int_equal(err.code, EKM_EIO);
    assert_string_equal(err.message, "out.h5: cannot write");
    assert_string_equal(err.input_file, "");
    assert_int_equal(err.input_line, 0);
    assert_string_equal(err.src_file, __FILE__);
    assert_int_equal(err.src_line, line);
    /* a NULL record is allowed */
    assert_int_equal(EKM_FAIL(NULL, EKM_EINPUT, "x"), EKM_EINPUT);
}

static void test_fail_at_records_input(void **state)
{
    (void)state;
    ekm_error err = {0};
    /* one line, so that __LINE__ + 1 is the line of the call */
    /* clang-format off */
    const int line = __LINE__ + 1;
    ekm_status st = EKM_FAIL_AT(&err, EKM_EINPUT, "chute.ini", 14, "[material] eps0: expected a number, got '%s'", "5x0");
    /* clang-format on */
    assert_int_equal(st, EKM_EINPUT);
    assert_string_equal(err.message, "chute.ini:14: [material] eps0: expected a number, got '5x0'");
    assert_string_equal(err.input_file, "chute.ini");
    assert_int_equal(err.input_line, 14);
    assert_int_equal(err.src_line, line);
    EKM_FAIL_AT(&err, EKM_EINPUT, "run.h5", 0, "expected a dataset %s", "phi");
    assert_string_equal(err.message, "run.h5: expected a dataset phi");
    assert_int_equal(err.input_line, 0);
    EKM_FAIL_AT(&err, EKM_EINPUT, NULL, 3, "no file");
    assert_string_equal(err.message, "no file");
    assert_string_equal(err.input_file, "");
    assert_int_equal(err.input_line, 0);
    ekm_error_clear(&err);
    assert_int_equal(err.code, EKM_OK);
    assert_string_equal(err.message, "");
}

static void print_it(void *arg)
{
    ekm_error_print("ekm", arg);
}

static void test_print_one_line_and_debug(void **state)
{
    (void)state;
    ekm_error err = {0};
    const int line = __LINE__ + 1;
    EKM_FAIL_AT(&err, EKM_EINPUT, "a.ini", 3, "[run] t_end: expected a number");
    unsetenv("EKM_DEBUG");
    char *text = tu_capture_stderr(print_it, &err);
    assert_non_null(text);
    assert_string_equal(text, "ekm: a.ini:3: [run] t_end: expected a number\n");
    free(text);
    setenv("EKM_DEBUG", "1", 1);
    text = tu_capture_stderr(print_it, &err);
    unsetenv("EKM_DEBUG");
    char expected[1024];
    snprintf(expected, sizeof expected,
             "ekm: a.ini:3: [run] t_end: expected a number\nekm: raised at %s:%d\n", __FILE__, line);
    assert_string_equal(text, expected);
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exit_codes_match_the_doc),
        cmocka_unit_test(test_fail_records_source),
        cmocka_unit_test(test_fail_at_records_input),
        cmocka_unit_test(test_print_one_line_and_debug),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
