/* utf8.c: UTF-8 sequences (see utf8.h). */
#include "utf8.h"

size_t ekm_utf8_sequence(const unsigned char *s, unsigned int *cp)
{
    size_t len;
    unsigned int c;
    if (s[0] == 0)
        return 0;
    if (s[0] < 0x80) {
        *cp = s[0];
        return 1;
    }
    if ((s[0] & 0xE0) == 0xC0) {
        len = 2;
        c = s[0] & 0x1F;
    } else if ((s[0] & 0xF0) == 0xE0) {
        len = 3;
        c = s[0] & 0x0F;
    } else if ((s[0] & 0xF8) == 0xF0) {
        len = 4;
        c = s[0] & 0x07;
    } else {
        return 0;
    }
    for (size_t i = 1; i < len; i++) { /* a NUL ends it here too */
        if ((s[i] & 0xC0) != 0x80)
            return 0;
        c = (c << 6) | (s[i] & 0x3F);
    }
    static const unsigned int min_cp[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (c < min_cp[len] || (c >= 0xD800 && c <= 0xDFFF) || c > 0x10FFFF)
        return 0; /* overlong, a surrogate, beyond Unicode */
    *cp = c;
    return len;
}

int ekm_utf8_valid(const char *s)
{
    const unsigned char *t = (const unsigned char *)s;
    unsigned int cp;
    while (*t) {
        const size_t len = ekm_utf8_sequence(t, &cp);
        if (len == 0)
            return 0;
        t += len;
    }
    return 1;
}
