/* test_progress.c: the progress line of long runs (common/progress.h) in a
 * file, as a batch's log gets it: one full line when due, nothing in
 * between, none without a stream; and the JSON helpers (common/json_out.h):
 * NaN and infinity as null, a failed set reported. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_out.h"
#include "progress.h"

static void read_all(FILE *fp, char *buf, size_t size)
{
    rewind(fp);
    size_t n = fread(buf, 1, size - 1, fp);
    buf[n] = '\0';
}

static void test_log_lines(void **state)
{
    (void)state;
    FILE *fp = tmpfile();
    assert_non_null(fp);
    ekm_progress p;
    ekm_progress_start(&p, fp);
    assert_int_equal(p.tty, 0);
    assert_true(p.every_s == 60.0);
    /* not due yet: nothing */
    ekm_progress_update(&p, 0.5, 2.0, 1e-4, 10, 0);
    char buf[512];
    read_all(fp, buf, sizeof buf);
    assert_string_equal(buf, "");
    /* forced: one whole line with the fraction, the step and the ETA */
    ekm_progress_update(&p, 0.5, 2.0, 1e-4, 10, 1);
    ekm_progress_end(&p);
    read_all(fp, buf, sizeof buf);
    assert_non_null(strstr(buf, "t =        0.5 s / 2 s  ( 25.0%)"));
    assert_non_null(strstr(buf, "dt =    0.0001 s"));
    assert_non_null(strstr(buf, "steps        10"));
    assert_non_null(strstr(buf, "ETA"));
    assert_null(strchr(buf, '\r'));
    assert_int_equal(buf[strlen(buf) - 1], '\n');
    assert_true(strchr(buf, '\n') == buf + strlen(buf) - 1); /* one line */
    /* a step not given (2D): not shown; a second whole line */
    ekm_progress_update(&p, 1.0, 2.0, 0.0, 20, 1);
    read_all(fp, buf, sizeof buf);
    const char *second = strchr(buf, '\n') + 1;
    assert_non_null(strstr(second, "( 50.0%)"));
    assert_null(strstr(second, "dt ="));
    assert_int_equal(buf[strlen(buf) - 1], '\n');
    fclose(fp);
    /* on a terminal: the line rewritten (\r, no newline) four times a
     * second, and ended by ekm_progress_end */
    fp = tmpfile();
    assert_non_null(fp);
    ekm_progress_start(&p, fp);
    p.tty = 1;
    p.every_s = 0.25;
    ekm_progress_update(&p, 0.5, 2.0, 1e-4, 10, 1);
    read_all(fp, buf, sizeof buf);
    assert_int_equal(buf[0], '\r');
    assert_null(strchr(buf, '\n'));
    ekm_progress_update(&p, 0.6, 2.0, 1e-4, 11, 0); /* not due */
    ekm_progress_end(&p);
    read_all(fp, buf, sizeof buf);
    assert_null(strstr(buf, "( 30.0%)"));
    assert_true(strchr(buf, '\n') == buf + strlen(buf) - 1);
    ekm_progress_end(&p); /* once only */
    read_all(fp, buf, sizeof buf);
    assert_true(strchr(buf, '\n') == buf + strlen(buf) - 1);
    fclose(fp);
    /* no stream: nothing, no crash */
    ekm_progress_start(&p, NULL);
    ekm_progress_update(&p, 1.0, 2.0, 0.1, 1, 1);
    ekm_progress_end(&p);
}

static void test_json_helpers(void **state)
{
    (void)state;
    json_t *v = ekm_json_number(NAN);
    assert_true(json_is_null(v));
    json_decref(v);
    v = ekm_json_number(INFINITY);
    assert_true(json_is_null(v));
    json_decref(v);
    v = ekm_json_number(0.25);
    assert_true(json_is_real(v) && json_real_value(v) == 0.25);
    json_decref(v);
    int bad = 0;
    json_t *obj = json_object();
    assert_int_equal(ekm_json_set(obj, "a", json_integer(1), &bad), 0);
    assert_int_equal(bad, 0);
    assert_int_equal(ekm_json_set(obj, "b", NULL, &bad), -1); /* a failed allocation */
    assert_int_equal(bad, 1);
    /* 9 digits, exponent without leading zeros, null for NaN */
    ekm_json_set(obj, "x", ekm_json_number(1.234567891234e-5), &bad);
    ekm_json_set(obj, "n", ekm_json_number(NAN), &bad);
    char *text = json_dumps(obj, JSON_PRESERVE_ORDER | JSON_COMPACT | JSON_REAL_PRECISION(9));
    assert_string_equal(text, "{\"a\":1,\"x\":1.23456789e-5,\"n\":null}");
    free(text);
    json_decref(obj);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_log_lines),
        cmocka_unit_test(test_json_helpers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
