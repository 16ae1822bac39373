/* utf8.h: UTF-8 (RFC 3629) sequences, for the scenario reader (values
 * must be UTF-8 text) and the XDMF writer (XML must be). */
#ifndef EKM_UTF8_H
#define EKM_UTF8_H

#include <stddef.h>

/* Length (1-4) of the valid UTF-8 sequence at s, its code point in *cp;
 * 0 when s starts no valid sequence (an overlong form, a surrogate, a code
 * point above U+10FFFF, a byte that cannot start or continue one) or at
 * its terminating NUL. */
size_t ekm_utf8_sequence(const unsigned char *s, unsigned int *cp);

/* 1 when the NUL-terminated string is UTF-8 text, else 0. */
int ekm_utf8_valid(const char *s);

#endif
