/* dump.c: streaming reader for LAMMPS/LIGGGHTS dumps (see dump.h).
 *
 * Text and gzip go through one zlib gzFile (zlib reads uncompressed files
 * transparently), into a line buffer that is refilled in 1 MiB blocks; atom
 * lines are tokenised in place and only the selected columns are converted
 * (cg_parse_double: exact fast path for <= 15 significant digits, which
 * covers the engines' %g and LIGGGHTS's 6 digits; strtod otherwise). The
 * column count of every atom line is checked.
 *
 * LAMMPS binary dump layout (dump_custom.cpp write_header_binary, format
 * revision 2, native byte order):
 *   int64 -len, char magic[len] ("DUMPCUSTOM"), int32 endian (=1),
 *   int32 revision, int64 step, int64 natoms, int32 triclinic,
 *   int32 boundary[3][2] (0 = periodic), double xlo xhi ylo yhi zlo zhi
 *   (bounding box), [double xy xz yz if triclinic], int32 size_one,
 *   int32 ulen + units, char has_time + [double time],
 *   int32 clen + column names (blank separated), int32 nchunk,
 *   nchunk x (int32 n, double[n]).
 */
#include "dump.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <zlib.h>

#define TEXT_BLOCK  (1u << 20)  /* bytes read per refill */
#define TEXT_MAXBUF (64u << 20) /* longest line accepted [bytes] */
#define BIN_BUF     (1u << 16)  /* doubles read at a time */

struct cg_dump {
    char *path; /* input name, for messages */
    gzFile gz;
    int binary;                          /* 1: LAMMPS binary dump */
    size_t nsel;                         /* selected columns */
    char *sel[CG_DUMP_MAXCOL];           /* their names */
    cg_dump_check check[CG_DUMP_MAXCOL]; /* what their values must be */
    char *buf;                           /* text buffer (cap + 1 bytes) */
    size_t cap, pos, end;                /* buffer size, read position, fill */
    int eof;                             /* no more bytes from gz */
    int gz_short;                        /* compressed stream ended early */
    long long gz_short_at;               /* at this compressed byte offset */
    int last_no_newline;                 /* last line returned had no '\n' */
    long long lineno;                    /* line number of the last line */
    unsigned long long offset;           /* binary: bytes consumed */
    int *colmap;                         /* file column -> selection index or -1 */
    size_t ncols, colmap_cap;            /* columns in the current header */
    double *chunk;                       /* binary read buffer (BIN_BUF doubles) */
    int truncated;                       /* last snapshot incomplete (skipped) */
    char truncation[800];                /* where and how the last snapshot was cut short */
    char warning[900];                   /* the same, and what was done */
};

/* ---------- numbers ---------- */

static const double pow10_tab[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                     1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static const double pow10_neg[23] = {1e0,   1e-1,  1e-2,  1e-3,  1e-4,  1e-5,  1e-6,  1e-7,
                                     1e-8,  1e-9,  1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15,
                                     1e-16, 1e-17, 1e-18, 1e-19, 1e-20, 1e-21, 1e-22};

static int is_end(char c)
{
    return c == ' ' || c == '\t' || c == '\0' || c == '\r' || c == '\n';
}

/* Eight ASCII digits at once (little-endian SWAR, as in fast_float):
 * is8digits tests, parse8 converts. The line buffer keeps 16 bytes of
 * slack after its end, so reading 8 bytes from any position is safe. */
static int is8digits(uint64_t v)
{
    return ((v & 0xF0F0F0F0F0F0F0F0ULL) | (((v + 0x0606060606060606ULL) & 0xF0F0F0F0F0F0F0F0ULL) >> 4)) ==
           0x3333333333333333ULL;
}

static uint64_t parse8(uint64_t v)
{
    const uint64_t mask = 0x000000FF000000FFULL;
    const uint64_t mul1 = 100 + (1000000ULL << 32), mul2 = 1 + (10000ULL << 32);
    v -= 0x3030303030303030ULL;
    v = (v * 10) + (v >> 8);
    return (((v & mask) * mul1) + (((v >> 16) & mask) * mul2)) >> 32;
}

static int little_endian(void)
{
    const uint16_t one = 1;
    unsigned char c;
    memcpy(&c, &one, 1);
    return c == 1;
}

/* The reader's parser: needs 8 readable bytes after the token's end. */
static int parse_number(const char **pp, double *out)
{
    const char *p = *pp, *start = *pp;
    int neg = 0;
    if (*p == '-') {
        neg = 1;
        p++;
    } else if (*p == '+')
        p++;
    char c0 = (char)(*p | 32);
    if (c0 == 'n' || c0 == 'i') {
        const char *q = p;
        while (!is_end(*q))
            q++;
        size_t n = (size_t)(q - p);
        if ((n == 3 && (!strncasecmp(p, "nan", 3) || !strncasecmp(p, "inf", 3))) ||
            (n == 8 && !strncasecmp(p, "infinity", 8)) || (n > 3 && !strncasecmp(p, "nan(", 4)))
            return 2;
        return 1;
    }
    uint64_t m = 0;
    int nd = 0, e10 = 0, any = 0, inexact = 0;
    while (*p >= '0' && *p <= '9') {
        any = 1;
        if (nd < 19) {
            m = m * 10 + (uint64_t)(*p - '0');
            if (m)
                nd++;
        } else {
            e10++;
            inexact = 1;
        }
        p++;
    }
    if (*p == '.') {
        p++;
        if (little_endian()) {
            uint64_t v8;
            memcpy(&v8, p, 8);
            while (nd + 8 <= 19 && is8digits(v8)) {
                m = m * 100000000ULL + parse8(v8);
                nd = m ? nd + 8 : 0; /* counts leading zeros once m != 0: safe */
                e10 -= 8;
                any = 1;
                p += 8;
                memcpy(&v8, p, 8);
            }
        }
        while (*p >= '0' && *p <= '9') {
            any = 1;
            if (nd < 19) {
                m = m * 10 + (uint64_t)(*p - '0');
                if (m)
                    nd++;
                e10--;
            } else
                inexact = 1;
            p++;
        }
    }
    if (!any)
        return 1;
    if (*p == 'e' || *p == 'E') {
        p++;
        int eneg = 0, ex = 0, edig = 0;
        if (*p == '-') {
            eneg = 1;
            p++;
        } else if (*p == '+')
            p++;
        while (*p >= '0' && *p <= '9') {
            if (ex < 100000)
                ex = ex * 10 + (*p - '0');
            edig = 1;
            p++;
        }
        if (!edig)
            return 1;
        e10 += eneg ? -ex : ex;
    }
    if (!is_end(*p))
        return 1;
    double v;
    if (!inexact && nd <= 15 && e10 >= -22 && e10 <= 22) {
        /* multiplication by the nearest double of 10^e10: within 1 ulp of the
         * correctly rounded value (a division, exact, costs 3x more here) */
        v = (double)m;
        v = e10 < 0 ? v * pow10_neg[-e10] : v * pow10_tab[e10];
        if (neg)
            v = -v;
    } else {
        char tmp[128];
        size_t n = (size_t)(p - start);
        if (n >= sizeof tmp)
            return 1;
        memcpy(tmp, start, n);
        tmp[n] = '\0';
        char *end;
        errno = 0;
        v = strtod(tmp, &end);
        if (end != tmp + n)
            return 1;
        if (!isfinite(v))
            return 2;
    }
    *out = v;
    *pp = p;
    return 0;
}

int cg_parse_double(const char **pp, double *out)
{
    char tmp[160];
    size_t n = strnlen(*pp, 128);
    memset(tmp, 0, sizeof tmp);
    memcpy(tmp, *pp, n);
    const char *p = tmp;
    int rc = parse_number(&p, out);
    if (rc == 0)
        *pp += p - tmp;
    return rc;
}

/* Parse a whole line as one integer (blanks around allowed). */
static int parse_int64(const char *s, int64_t *out)
{
    while (*s == ' ' || *s == '\t')
        s++;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || errno)
        return 1;
    while (*end == ' ' || *end == '\t' || *end == '\r')
        end++;
    if (*end)
        return 1;
    *out = v;
    return 0;
}

/* ---------- open / close ---------- */

static int mark_truncated(cg_dump *d, const char *what)
{
    d->truncated = 1;
    if (d->gz_short)
        snprintf(d->truncation, sizeof d->truncation,
                 "%s: truncated gzip stream at byte %lld (unexpected end of file): snapshot cut short (%s)",
                 d->path, d->gz_short_at, what);
    else if (d->binary)
        snprintf(d->truncation, sizeof d->truncation, "%s:@%llu: truncated snapshot (%s)", d->path, d->offset,
                 what);
    else
        snprintf(d->truncation, sizeof d->truncation, "%s:%lld: truncated snapshot (%s)", d->path, d->lineno,
                 what);
    snprintf(d->warning, sizeof d->warning, "%s: skipped, earlier snapshots kept", d->truncation);
    return EKM_EOF;
}

/* zlib's message without the "path: " it puts in front. */
static const char *zlib_message(cg_dump *d, int *zerr)
{
    const char *msg = gzerror(d->gz, zerr);
    size_t n = strlen(d->path);
    if (!strncmp(msg, d->path, n) && !strncmp(msg + n, ": ", 2))
        msg += n + 2;
    return msg;
}

/* Read up to n more bytes into the buffer end; sets eof. A gzip stream
 * that ends early (a file cut off: zlib's Z_BUF_ERROR) is the end of the
 * data, the snapshot it cuts short skipped with a warning (gz_short); one
 * that is corrupt (Z_DATA_ERROR: a flipped byte, a bad check value) is an
 * error naming the compressed byte offset and zlib's message. */
static ekm_status fill(cg_dump *d, size_t want, ekm_error *err)
{
    if (d->eof)
        return EKM_OK;
    if (want > d->cap - d->end)
        want = d->cap - d->end;
    int n = gzread(d->gz, d->buf + d->end, (unsigned)want);
    int zerr = Z_OK;
    const char *msg = zlib_message(d, &zerr);
    if (zerr == Z_DATA_ERROR)
        return EKM_FAIL(err, EKM_EINPUT, "%s: corrupt gzip stream, detected at byte %lld: %s", d->path,
                        (long long)gzoffset(d->gz), msg);
    if (zerr == Z_BUF_ERROR && n <= 0) {
        /* zlib reports it as soon as it has read the last input byte: the
         * data already decompressed come first */
        d->gz_short = 1;
        d->gz_short_at = (long long)gzoffset(d->gz);
        d->eof = 1;
    } else if (n < 0) {
        return EKM_FAIL(err, zerr == Z_MEM_ERROR ? EKM_ENOMEM : EKM_EIO, "%s: cannot read: %s", d->path,
                        zerr == Z_ERRNO ? strerror(errno) : msg);
    }
    if (n <= 0)
        d->eof = 1;
    else
        d->end += (size_t)n;
    return EKM_OK;
}

ekm_status cg_dump_open(cg_dump **out, const char *path, const char *const *cols, size_t ncols,
                        ekm_error *err)
{
    *out = NULL;
    if (ncols > CG_DUMP_MAXCOL)
        return EKM_FAIL(err, EKM_EUSAGE, "%s: too many columns selected (%zu > %d)", path, ncols,
                        CG_DUMP_MAXCOL);
    cg_dump *d = calloc(1, sizeof *d);
    if (!d)
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", path);
    d->path = strdup(path);
    d->cap = TEXT_BLOCK;
    d->buf = calloc(d->cap + 16, 1); /* 16 bytes of slack: SWAR reads */
    if (!d->path || !d->buf) {
        cg_dump_close(d);
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", path);
    }
    for (size_t j = 0; j < ncols; j++) {
        d->sel[j] = strdup(cols[j]);
        if (!d->sel[j]) {
            cg_dump_close(d);
            return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", path);
        }
        d->nsel = j + 1;
    }
    d->gz = gzopen(path, "rb");
    if (!d->gz) {
        int e = errno;
        cg_dump_close(d);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: %s", path, e ? strerror(e) : "zlib error");
    }
    gzbuffer(d->gz, 1u << 18);
    ekm_status rc = fill(d, 64, err);
    if (rc) {
        cg_dump_close(d);
        return rc;
    }
    /* sniff: text dumps start with "ITEM:" (maybe after blanks); binary
     * dumps with a negative int64 (the magic string length). */
    size_t i = 0;
    while (i < d->end && isspace((unsigned char)d->buf[i]))
        i++;
    if (d->end - i >= 5 && !memcmp(d->buf + i, "ITEM:", 5)) {
        d->binary = 0;
    } else if (d->end >= 8) {
        /* printable start: a broken text file, reported by the text parser */
        int printable = 1;
        for (size_t k = 0; k < 8; k++)
            if (!isprint((unsigned char)d->buf[k]) && !isspace((unsigned char)d->buf[k]))
                printable = 0;
        d->binary = !printable;
    }
    *out = d;
    return EKM_OK;
}

void cg_dump_close(cg_dump *d)
{
    if (!d)
        return;
    if (d->gz)
        gzclose(d->gz);
    for (size_t j = 0; j < d->nsel; j++)
        free(d->sel[j]);
    free(d->path);
    free(d->buf);
    free(d->colmap);
    free(d->chunk);
    free(d);
}

void cg_snapshot_free(cg_snapshot *s)
{
    if (!s)
        return;
    free(s->data);
    s->data = NULL;
    s->cap = 0;
}

int cg_dump_truncated(const cg_dump *d)
{
    return d->truncated;
}
const char *cg_dump_truncation(const cg_dump *d)
{
    return d->truncation;
}

const char *cg_dump_warning(const cg_dump *d)
{
    return d->warning;
}

/* ---------- shared helpers ---------- */

static ekm_status grow_rows(cg_snapshot *s, size_t rows, size_t nsel, const char *path, ekm_error *err)
{
    if (rows <= s->cap)
        return EKM_OK;
    size_t ncap = s->cap ? s->cap : 1024;
    while (ncap < rows)
        ncap *= 2;
    size_t w = nsel ? nsel : 1;
    double *p = realloc(s->data, ncap * w * sizeof *p);
    if (!p)
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory (%zu atoms)", path, rows);
    s->data = p;
    s->cap = ncap;
    return EKM_OK;
}

/* Map the column names of a header to the selection. names: blank-separated. */
static ekm_status set_columns(cg_dump *d, cg_snapshot *s, const char *names, ekm_error *err,
                              const char *where)
{
    d->ncols = 0;
    for (size_t j = 0; j < d->nsel; j++)
        s->present[j] = 0;
    const char *p = names;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r')
            p++;
        if (!*p)
            break;
        const char *q = p;
        while (*q && *q != ' ' && *q != '\t' && *q != '\r')
            q++;
        if (d->ncols == d->colmap_cap) {
            size_t nc = d->colmap_cap ? 2 * d->colmap_cap : 32;
            int *m = realloc(d->colmap, nc * sizeof *m);
            if (!m)
                return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", where);
            d->colmap = m;
            d->colmap_cap = nc;
        }
        int map = -1;
        for (size_t j = 0; j < d->nsel; j++)
            if (strlen(d->sel[j]) == (size_t)(q - p) && !memcmp(d->sel[j], p, (size_t)(q - p))) {
                if (!s->present[j]) {
                    map = (int)j;
                    s->present[j] = 1;
                }
                break;
            }
        d->colmap[d->ncols++] = map;
        p = q;
    }
    if (d->ncols == 0)
        return EKM_FAIL(err, EKM_EINPUT, "%s: ITEM: ATOMS names no columns", where);
    return EKM_OK;
}

void cg_dump_expect(cg_dump *d, size_t j, cg_dump_check c)
{
    if (j < d->nsel)
        d->check[j] = c;
}

/* The box's longest edge [m]. */
static double box_longest(const cg_snapshot *s)
{
    double m = 0.0;
    for (int k = 0; k < 3; k++)
        m = fmax(m, s->hi[k] - s->lo[k]);
    return m;
}

/* A value of column j against its check: NULL if good, else what was
 * expected. */
static const char *check_value(const cg_dump *d, const cg_snapshot *s, size_t j, double v, char *buf,
                               size_t len)
{
    const cg_dump_check c = d->check[j];
    if (c == CG_DUMP_ANY)
        return NULL;
    if (c == CG_DUMP_INTEGER) {
        if (v != floor(v))
            return "expected an integer";
        if (!(fabs(v) <= 9007199254740992.0))
            return "expected an integer of magnitude at most 2^53 (exact in double precision)";
        return NULL;
    }
    if (c == CG_DUMP_VELOCITY)
        return fabs(v) < CG_DUMP_LIGHT_SPEED
                   ? NULL
                   : "expected a velocity component below the speed of light (|v| < 299792458 m/s)";
    if (!(v > 0.0))
        return "expected a positive finite number";
    const double size = c == CG_DUMP_RADIUS ? 2.0 * v : v, edge = box_longest(s);
    if ((c == CG_DUMP_RADIUS || c == CG_DUMP_DIAMETER) && !(size <= edge)) {
        snprintf(buf, len, "expected a particle no larger than the box (longest edge %.6g m)", edge);
        return buf;
    }
    return NULL;
}

/* The box after the tilts are taken off: finite, lo < hi, and an edge
 * that is a finite number (a box of -1e308 .. 1e308 is not). */
static ekm_status box_check(const cg_dump *d, const cg_snapshot *s, ekm_error *err)
{
    static const char axis[3] = {'x', 'y', 'z'};
    for (int k = 0; k < 3; k++) {
        const double L = s->hi[k] - s->lo[k];
        if (!isfinite(s->lo[k]) || !isfinite(s->hi[k]) || !(L > 0.0) || !isfinite(L))
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: ITEM: BOX BOUNDS: %c: expected finite bounds lo < hi with a finite length, "
                            "got %.6g .. %.6g%s",
                            s->box_where[k], axis[k], s->lo[k], s->hi[k],
                            s->triclinic ? " (the box inside the bounding box, tilts taken off)" : "");
    }
    (void)d;
    return EKM_OK;
}

static void box_from_bounds(cg_snapshot *s, double b[3][2])
{
    double xy = s->tilt[0], xz = s->tilt[1], yz = s->tilt[2];
    if (s->triclinic) {
        double mn = fmin(fmin(0.0, xy), fmin(xz, xy + xz));
        double mx = fmax(fmax(0.0, xy), fmax(xz, xy + xz));
        s->lo[0] = b[0][0] - mn;
        s->hi[0] = b[0][1] - mx;
        s->lo[1] = b[1][0] - fmin(0.0, yz);
        s->hi[1] = b[1][1] - fmax(0.0, yz);
    } else {
        s->lo[0] = b[0][0];
        s->hi[0] = b[0][1];
        s->lo[1] = b[1][0];
        s->hi[1] = b[1][1];
    }
    s->lo[2] = b[2][0];
    s->hi[2] = b[2][1];
}

/* ---------- text ---------- */

/* Next line (NUL-terminated, without '\n' or '\r'). 1: line, 0: EOF. */
static int text_line(cg_dump *d, char **line, ekm_status *rc, ekm_error *err)
{
    *rc = EKM_OK;
    for (;;) {
        char *base = d->buf + d->pos;
        char *nl = memchr(base, '\n', d->end - d->pos);
        if (nl) {
            *nl = '\0';
            if (nl > base && nl[-1] == '\r')
                nl[-1] = '\0';
            *line = base;
            d->pos = (size_t)(nl - d->buf) + 1;
            d->lineno++;
            d->last_no_newline = 0;
            return 1;
        }
        if (d->eof) {
            if (d->pos < d->end) {
                memset(d->buf + d->end, 0, 16);
                *line = base;
                d->pos = d->end;
                d->lineno++;
                d->last_no_newline = 1;
                return 1;
            }
            return 0;
        }
        if (d->pos > 0) {
            memmove(d->buf, d->buf + d->pos, d->end - d->pos);
            d->end -= d->pos;
            d->pos = 0;
        }
        if (d->end == d->cap) {
            if (d->cap >= TEXT_MAXBUF) {
                *rc = EKM_FAIL(err, EKM_EINPUT, "%s:%lld: line longer than %u bytes", d->path, d->lineno + 1,
                               TEXT_MAXBUF);
                return 0;
            }
            char *nb = realloc(d->buf, 2 * d->cap + 16);
            if (!nb) {
                *rc = EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", d->path);
                return 0;
            }
            memset(nb + d->cap, 0, d->cap + 16);
            d->buf = nb;
            d->cap *= 2;
        }
        *rc = fill(d, TEXT_BLOCK, err);
        if (*rc)
            return 0;
    }
}

static const char *skip_blank(const char *p)
{
    while (*p == ' ' || *p == '\t')
        p++;
    return p;
}

/* Does item text (after "ITEM:") equal word, up to trailing blanks? */
static int item_is(const char *item, const char *word)
{
    size_t n = strlen(word);
    if (strncmp(item, word, n))
        return 0;
    return *skip_blank(item + n) == '\0';
}

static int item_starts(const char *item, const char *word, const char **rest)
{
    size_t n = strlen(word);
    if (strncmp(item, word, n))
        return 0;
    if (item[n] != '\0' && item[n] != ' ' && item[n] != '\t')
        return 0;
    *rest = item + n;
    return 1;
}

/* A line without its newline is the last of a file cut short: the engines
 * end every line with one, and what is left of it may still parse (a value
 * 0.0123 cut to 0.01), so it is never used. */
#define CUT_LINE "last line cut short"

/* The value line after an ITEM: line; returns 1, or 0 (EOF, a line cut
 * short, or an error in rc). */
static int value_line(cg_dump *d, char **line, ekm_status *rc, ekm_error *err)
{
    if (text_line(d, line, rc, err)) {
        if (!d->last_no_newline)
            return 1;
        *rc = mark_truncated(d, CUT_LINE);
        return 0;
    }
    if (*rc == EKM_OK)
        *rc = mark_truncated(d, "end of file inside the header");
    return 0;
}

static ekm_status parse_box(cg_dump *d, cg_snapshot *s, const char *flags, ekm_error *err)
{
    const char *p = flags;
    int nflag = 0;
    s->triclinic = 0;
    for (int k = 0; k < 3; k++)
        s->periodic[k] = 0, s->tilt[k] = 0.0;
    for (;;) {
        p = skip_blank(p);
        if (!*p)
            break;
        const char *q = p;
        while (*q && *q != ' ' && *q != '\t')
            q++;
        size_t n = (size_t)(q - p);
        if (n == 2 && (!strncmp(p, "xy", 2) || !strncmp(p, "xz", 2) || !strncmp(p, "yz", 2)) && nflag == 0) {
            s->triclinic = 1;
        } else if (n == 2 && nflag < 3 && strchr("pfsm", p[0]) && strchr("pfsm", p[1])) {
            s->periodic[nflag++] = (p[0] == 'p');
        } else {
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s:%lld: ITEM: BOX BOUNDS: expected 'xy xz yz' or boundary flags "
                            "like 'pp ff', got '%.*s'",
                            d->path, d->lineno, (int)n, p);
        }
        p = q;
    }
    double b[3][2];
    for (int k = 0; k < 3; k++) {
        char *line;
        ekm_status rc;
        if (!value_line(d, &line, &rc, err))
            return rc;
        const char *q = line;
        int nv = s->triclinic ? 3 : 2;
        double v[3] = {0, 0, 0};
        for (int j = 0; j < nv; j++) {
            q = skip_blank(q);
            const char *tok = q;
            int pr = parse_number(&q, &v[j]);
            if (pr)
                return EKM_FAIL(err, EKM_EINPUT,
                                "%s:%lld:%d: ITEM: BOX BOUNDS: expected %d %snumbers, got '%.60s'", d->path,
                                d->lineno, (int)(tok - line) + 1, nv, pr == 2 ? "finite " : "", line);
        }
        q = skip_blank(q);
        if (*q)
            return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: ITEM: BOX BOUNDS: expected %d numbers, got '%.60s'",
                            d->path, d->lineno, nv, line);
        if (!(v[1] > v[0]))
            return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: ITEM: BOX BOUNDS: expected lo < hi, got '%.60s'",
                            d->path, d->lineno, line);
        b[k][0] = v[0];
        b[k][1] = v[1];
        s->tilt[k] = v[2];
        snprintf(s->box_where[k], sizeof s->box_where[k], "%s:%lld", d->path, d->lineno);
    }
    box_from_bounds(s, b);
    return box_check(d, s, err);
}

static ekm_status text_atoms(cg_dump *d, cg_snapshot *s, ekm_error *err)
{
    size_t nsel = d->nsel, ncols = d->ncols;
    int64_t n = s->natoms;
    size_t reserve = (size_t)(n < (1 << 16) ? n : (1 << 16)); /* grows as lines come */
    ekm_status rc = grow_rows(s, reserve, nsel, d->path, err);
    if (rc)
        return rc;
    for (int64_t i = 0; i < n; i++) {
        char *line;
        if (!text_line(d, &line, &rc, err)) {
            if (rc)
                return rc;
            char what[96];
            snprintf(what, sizeof what, "end of file after %lld of %lld atoms", (long long)i, (long long)n);
            return mark_truncated(d, what);
        }
        if (d->last_no_newline)
            return mark_truncated(d, CUT_LINE);
        if ((size_t)i >= s->cap && (rc = grow_rows(s, (size_t)i + 1, nsel, d->path, err)))
            return rc;
        double *row = s->data + (size_t)i * nsel;
        const char *p = line;
        if (p[0] == 'I' && !strncmp(p, "ITEM:", 5))
            return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: expected %lld atoms (ITEM: NUMBER OF ATOMS), got %lld",
                            d->path, d->lineno, (long long)n, (long long)i);
        for (size_t c = 0; c < ncols; c++) {
            p = skip_blank(p);
            if (!*p) {
                return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: expected %zu columns, got %zu", d->path, d->lineno,
                                ncols, c);
            }
            int j = d->colmap[c];
            if (j >= 0) {
                const char *tok = p;
                int pr = parse_number(&p, &row[j]);
                if (pr) {
                    const char *q = tok;
                    while (!is_end(*q))
                        q++;
                    if (pr == 2)
                        return EKM_FAIL(err, EKM_EINPUT,
                                        "%s:%lld:%d: column '%s': expected a finite number, got '%.*s'",
                                        d->path, d->lineno, (int)(tok - line) + 1, d->sel[j],
                                        (int)(q - tok > 40 ? 40 : q - tok), tok);
                    return EKM_FAIL(err, EKM_EINPUT, "%s:%lld:%d: column '%s': expected a number, got '%.*s'",
                                    d->path, d->lineno, (int)(tok - line) + 1, d->sel[j],
                                    (int)(q - tok > 40 ? 40 : q - tok), tok);
                }
                char why[128];
                const char *bad = check_value(d, s, (size_t)j, row[j], why, sizeof why);
                if (bad)
                    return EKM_FAIL(err, EKM_EINPUT, "%s:%lld:%d: %s: %s, got %.*s", d->path, d->lineno,
                                    (int)(tok - line) + 1, d->sel[j], bad, (int)(p - tok > 40 ? 40 : p - tok),
                                    tok);
            } else {
                while (*p && *p != ' ' && *p != '\t')
                    p++;
            }
        }
        p = skip_blank(p);
        if (*p)
            return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: expected %zu columns, got more ('%.40s')", d->path,
                            d->lineno, ncols, p);
    }
    return EKM_OK;
}

static ekm_status text_next(cg_dump *d, cg_snapshot *s, ekm_error *err)
{
    int have_step = 0, have_n = 0, have_box = 0, started = 0, rc;
    for (;;) {
        char *line;
        if (!text_line(d, &line, &rc, err)) {
            if (rc)
                return rc;
            if (!started) {
                if (d->gz_short)
                    return mark_truncated(d, "compressed stream ends early");
                return EKM_EOF;
            }
            return mark_truncated(d, "end of file inside the header");
        }
        if (!started && *skip_blank(line) == '\0')
            continue;
        if (d->last_no_newline)
            return mark_truncated(d, CUT_LINE);
        if (!started) {
            s->has_time = 0;
            s->time = 0.0;
            started = 1;
        }
        if (strncmp(line, "ITEM:", 5))
            return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: expected an ITEM: line%s, got '%.40s'", d->path,
                            d->lineno, have_step ? "" : " (more atom lines than ITEM: NUMBER OF ATOMS?)",
                            line);
        const char *item = skip_blank(line + 5), *rest;
        char *v;
        if (item_is(item, "TIMESTEP")) {
            if (!value_line(d, &v, &rc, err))
                return rc;
            if (parse_int64(v, &s->step))
                return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: ITEM: TIMESTEP: expected an integer, got '%.40s'",
                                d->path, d->lineno, v);
            if (!s->has_time)
                snprintf(s->time_where, sizeof s->time_where, "%s:%lld", d->path, d->lineno);
            have_step = 1;
        } else if (item_is(item, "TIME")) {
            if (!value_line(d, &v, &rc, err))
                return rc;
            const char *q = skip_blank(v);
            if (parse_number(&q, &s->time) || *skip_blank(q))
                return EKM_FAIL(err, EKM_EINPUT, "%s:%lld: ITEM: TIME: expected a finite number, got '%.40s'",
                                d->path, d->lineno, v);
            s->has_time = 1;
            snprintf(s->time_where, sizeof s->time_where, "%s:%lld", d->path, d->lineno);
        } else if (item_is(item, "UNITS")) {
            if (!value_line(d, &v, &rc, err))
                return rc;
        } else if (item_is(item, "NUMBER OF ATOMS") || item_is(item, "NUMBER OF ENTRIES")) {
            if (!value_line(d, &v, &rc, err))
                return rc;
            if (parse_int64(v, &s->natoms) || s->natoms < 0)
                return EKM_FAIL(
                    err, EKM_EINPUT,
                    "%s:%lld: ITEM: NUMBER OF ATOMS: expected a non-negative integer, got '%.40s'", d->path,
                    d->lineno, v);
            have_n = 1;
        } else if (item_starts(item, "BOX BOUNDS", &rest)) {
            if ((rc = parse_box(d, s, rest, err)))
                return rc;
            have_box = 1;
        } else if (item_starts(item, "ATOMS", &rest) || item_starts(item, "ENTRIES", &rest)) {
            snprintf(s->where, sizeof s->where, "%s:%lld", d->path, d->lineno);
            const char *miss = !have_step  ? "TIMESTEP"
                               : !have_n   ? "NUMBER OF ATOMS"
                               : !have_box ? "BOX BOUNDS"
                                           : NULL;
            if (miss)
                return EKM_FAIL(err, EKM_EINPUT, "%s: expected ITEM: %s before ITEM: ATOMS", s->where, miss);
            if ((rc = set_columns(d, s, rest, err, s->where)))
                return rc;
            s->nsel = d->nsel;
            return text_atoms(d, s, err);
        } else {
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s:%lld: expected ITEM: TIMESTEP, TIME, UNITS, NUMBER OF ATOMS (ENTRIES), "
                            "BOX BOUNDS or ATOMS (ENTRIES), got '%.40s'",
                            d->path, d->lineno, line);
        }
    }
}

/* ---------- times ---------- */

/* The shortest %g form of v (9 to 17 digits) that reads back as v: two
 * times that differ are never printed alike. */
static void shortest(char *buf, size_t len, double v)
{
    for (int prec = 9; prec <= 17; prec++) {
        snprintf(buf, len, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            return;
    }
}

ekm_status cg_snapshot_time(const cg_snapshot *s, double dt, cg_time_order *ord, double *t, ekm_error *err)
{
    double now;
    if (s->has_time)
        now = s->time;
    else if (dt > 0)
        now = (double)s->step * dt;
    else
        return EKM_FAIL(err, EKM_EUSAGE,
                        "%s: the dump has no ITEM: TIME: give --dt (the engine's time step, s)", s->where);
    if (ord->have && !(now > ord->t)) {
        char prev[32], cur[32];
        shortest(prev, sizeof prev, ord->t);
        shortest(cur, sizeof cur, now);
        if (s->has_time)
            return EKM_FAIL(err, EKM_EINPUT,
                            "%s: ITEM: TIME: expected a time after the previous snapshot's %s s, got %s s",
                            s->time_where, prev, cur);
        return EKM_FAIL(
            err, EKM_EINPUT,
            "%s: ITEM: TIMESTEP %lld x --dt %.9g s: expected a time after the previous snapshot's "
            "%s s, got %s s",
            s->time_where, (long long)s->step, dt, prev, cur);
    }
    ord->have = 1;
    ord->t = now;
    *t = now;
    return EKM_OK;
}

/* ---------- binary ---------- */

/* Read n bytes; returns bytes read (< n only at the end of the data). */
static size_t bin_read(cg_dump *d, void *dst, size_t n, ekm_status *rc, ekm_error *err)
{
    char *out = dst;
    size_t got = 0;
    *rc = EKM_OK;
    while (got < n) {
        if (d->pos == d->end) {
            if (d->eof)
                break;
            d->pos = d->end = 0;
            if ((*rc = fill(d, TEXT_BLOCK, err)))
                break;
            continue;
        }
        size_t k = d->end - d->pos;
        if (k > n - got)
            k = n - got;
        memcpy(out + got, d->buf + d->pos, k);
        d->pos += k;
        got += k;
    }
    d->offset += got;
    return got;
}

#define BREAD(ptr, size, what)                                      \
    do {                                                            \
        if (bin_read(d, (ptr), (size), &rc, err) != (size_t)(size)) \
            return rc ? rc : mark_truncated(d, what);               \
    } while (0)

static ekm_status bin_fail(cg_dump *d, ekm_error *err, const char *what)
{
    return EKM_FAIL(err, EKM_EINPUT, "%s:@%llu: %s", d->path, d->offset, what);
}

static ekm_status bin_next(cg_dump *d, cg_snapshot *s, ekm_error *err)
{
    ekm_status rc;
    int64_t first;
    size_t got = bin_read(d, &first, 8, &rc, err);
    if (rc)
        return rc;
    if (got == 0) {
        if (d->gz_short)
            return mark_truncated(d, "compressed stream ends early");
        return EKM_EOF;
    }
    if (got < 8)
        return mark_truncated(d, "end of file inside the header");
    if (first >= 0)
        return bin_fail(d, err,
                        "expected a LAMMPS binary dump with column names (format revision >= 2, "
                        "LAMMPS since 2020); convert older files with LAMMPS tools/binary2txt");
    if (first < -64)
        return bin_fail(d, err, "expected a text dump (ITEM:) or a LAMMPS binary dump");
    char magic[65];
    size_t mlen = (size_t)(-first);
    BREAD(magic, mlen, "end of file inside the header");
    magic[mlen] = '\0';
    int32_t endian, revision;
    BREAD(&endian, 4, "end of file inside the header");
    if (endian != 1)
        return bin_fail(d, err, "expected native byte order (endian flag 1)");
    BREAD(&revision, 4, "end of file inside the header");
    if (revision < 2)
        return bin_fail(d, err, "expected binary format revision >= 2 (with column names)");
    snprintf(s->time_where, sizeof s->time_where, "%s:@%llu", d->path, d->offset);
    BREAD(&s->step, 8, "end of file inside the header");
    BREAD(&s->natoms, 8, "end of file inside the header");
    if (s->natoms < 0)
        return bin_fail(d, err, "expected a non-negative number of atoms");
    int32_t tri, bnd[6];
    BREAD(&tri, 4, "end of file inside the header");
    if (tri != 0 && tri != 1)
        return bin_fail(d, err, "expected triclinic flag 0 or 1");
    s->triclinic = tri;
    BREAD(bnd, sizeof bnd, "end of file inside the header");
    for (int k = 0; k < 3; k++)
        s->periodic[k] = (bnd[2 * k] == 0);
    double b[3][2], tilt[3] = {0, 0, 0};
    BREAD(b, sizeof b, "end of file inside the header");
    if (tri)
        BREAD(tilt, sizeof tilt, "end of file inside the header");
    for (int k = 0; k < 3; k++) {
        if (!isfinite(b[k][0]) || !isfinite(b[k][1]) || !(b[k][1] > b[k][0]) || !isfinite(tilt[k]))
            return bin_fail(d, err, "expected finite box bounds with lo < hi");
        s->tilt[k] = tilt[k];
    }
    for (int k = 0; k < 3; k++)
        snprintf(s->box_where[k], sizeof s->box_where[k], "%s:@%llu", d->path, d->offset);
    box_from_bounds(s, b);
    if ((rc = box_check(d, s, err)))
        return rc;
    int32_t size_one, len;
    BREAD(&size_one, 4, "end of file inside the header");
    if (size_one < 1 || size_one > 100000)
        return bin_fail(d, err, "expected 1..100000 values per atom");
    BREAD(&len, 4, "end of file inside the header");
    if (len < 0 || len > 4096)
        return bin_fail(d, err, "expected a units string of 0..4096 bytes");
    char skip[4096];
    BREAD(skip, (size_t)len, "end of file inside the header");
    char tflag;
    BREAD(&tflag, 1, "end of file inside the header");
    s->has_time = (tflag != 0);
    if (tflag) {
        BREAD(&s->time, 8, "end of file inside the header");
        if (!isfinite(s->time))
            return bin_fail(d, err, "expected a finite time");
    }
    BREAD(&len, 4, "end of file inside the header");
    if (len < 1 || len > 1000000)
        return bin_fail(d, err, "expected a column-name string of 1..1e6 bytes");
    char *names = malloc((size_t)len + 1);
    if (!names)
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", d->path);
    if (bin_read(d, names, (size_t)len, &rc, err) != (size_t)len) {
        free(names);
        return rc ? rc : mark_truncated(d, "end of file inside the header");
    }
    names[len] = '\0';
    if (memchr(names, '\0', (size_t)len)) {
        free(names);
        return bin_fail(d, err, "expected column names without NUL bytes");
    }
    snprintf(s->where, sizeof s->where, "%s:@%llu", d->path, d->offset);
    rc = set_columns(d, s, names, err, s->where);
    free(names);
    if (rc)
        return rc;
    s->nsel = d->nsel;
    if (d->ncols != (size_t)size_one)
        return bin_fail(d, err, "expected as many column names as values per atom");
    int32_t nchunk;
    BREAD(&nchunk, 4, "end of file inside the header");
    if (nchunk < 0)
        return bin_fail(d, err, "expected a non-negative chunk count");
    if (!d->chunk && !(d->chunk = malloc(BIN_BUF * sizeof(double))))
        return EKM_FAIL(err, EKM_ENOMEM, "%s: out of memory", d->path);
    size_t per = BIN_BUF / (size_t)size_one, nsel = d->nsel;
    if (per == 0)
        return bin_fail(d, err, "expected fewer values per atom");
    int64_t atom = 0;
    for (int32_t c = 0; c < nchunk; c++) {
        int32_t n;
        BREAD(&n, 4, "end of file inside a chunk");
        if (n < 0 || n % size_one)
            return bin_fail(d, err, "expected a chunk length that is a multiple of the values per atom");
        int64_t na = n / size_one;
        if (atom + na > s->natoms)
            return bin_fail(d, err, "expected no more atoms than the header's atom count");
        while (na > 0) {
            size_t k = (size_t)na < per ? (size_t)na : per;
            /* grow with the data actually read, never with a declared size */
            if ((rc = grow_rows(s, (size_t)atom + k, nsel, d->path, err)))
                return rc;
            BREAD(d->chunk, k * (size_t)size_one * sizeof(double), "end of file inside a chunk");
            for (size_t i = 0; i < k; i++) {
                const double *in = d->chunk + i * (size_t)size_one;
                double *row = s->data + (size_t)(atom + (int64_t)i) * nsel;
                for (size_t col = 0; col < d->ncols; col++) {
                    int j = d->colmap[col];
                    if (j < 0)
                        continue;
                    if (!isfinite(in[col])) {
                        char what[160];
                        snprintf(what, sizeof what, "column '%s' of atom %lld: expected a finite number",
                                 d->sel[j], (long long)(atom + (int64_t)i + 1));
                        return bin_fail(d, err, what);
                    }
                    char why[128];
                    const char *bad = check_value(d, s, (size_t)j, in[col], why, sizeof why);
                    if (bad) {
                        char what[320];
                        snprintf(what, sizeof what, "column '%s' of atom %lld: %s, got %.6g", d->sel[j],
                                 (long long)(atom + (int64_t)i + 1), bad, in[col]);
                        return bin_fail(d, err, what);
                    }
                    row[j] = in[col];
                }
            }
            atom += (int64_t)k;
            na -= (int64_t)k;
        }
    }
    if (atom != s->natoms) {
        char what[160];
        snprintf(what, sizeof what, "expected %lld atoms (header), chunks hold %lld", (long long)s->natoms,
                 (long long)atom);
        return bin_fail(d, err, what);
    }
    return EKM_OK;
}

ekm_status cg_dump_next(cg_dump *d, cg_snapshot *s, ekm_error *err)
{
    if (d->truncated)
        return EKM_EOF;
    s->nsel = d->nsel;
    return d->binary ? bin_next(d, s, err) : text_next(d, s, err);
}
