/* test_utf8.c: UTF-8 sequences (common/utf8.h) against RFC 3629's table
 * and its examples of what is not UTF-8. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "utf8.h"

static void test_sequences(void **state)
{
    (void)state;
    unsigned int cp = 0;
    assert_int_equal(ekm_utf8_sequence((const unsigned char *)"A", &cp), 1);
    assert_int_equal(cp, 0x41);
    assert_int_equal(ekm_utf8_sequence((const unsigned char *)"\xC3\xA9", &cp), 2); /* e acute */
    assert_int_equal(cp, 0xE9);
    assert_int_equal(ekm_utf8_sequence((const unsigned char *)"\xE2\x82\xAC", &cp), 3); /* euro */
    assert_int_equal(cp, 0x20AC);
    assert_int_equal(ekm_utf8_sequence((const unsigned char *)"\xF4\x8F\xBF\xBF", &cp), 4); /* U+10FFFF */
    assert_int_equal(cp, 0x10FFFF);
    assert_int_equal(ekm_utf8_sequence((const unsigned char *)"", &cp), 0); /* the NUL */
}

static void test_not_utf8(void **state)
{
    (void)state;
    unsigned int cp;
    const char *bad[] = {
        "\xC0\x80",         /* overlong NUL */
        "\xE0\x80\xAF",     /* overlong '/' */
        "\xED\xA0\x80",     /* surrogate U+D800 */
        "\xF4\x90\x80\x80", /* U+110000 */
        "\xE9",             /* Latin-1 e acute alone */
        "\xC3",             /* a sequence cut by the NUL */
        "\x80",             /* a continuation byte first */
        "\xFF",
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        assert_int_equal(ekm_utf8_sequence((const unsigned char *)bad[i], &cp), 0);
        assert_false(ekm_utf8_valid(bad[i]));
    }
    assert_true(ekm_utf8_valid("phi = 0.6 \xE2\x80\x93 d\xC3\xA9j\xC3\xA0 vu"));
    assert_true(ekm_utf8_valid(""));
    assert_false(ekm_utf8_valid("ok \xC3\xA9 then \xC3"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_sequences), cmocka_unit_test(test_not_utf8)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
