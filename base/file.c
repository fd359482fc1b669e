/* file.c - file reads with transparent gunzip, whole or as a stream (see lf_file.h). */
#include "lf_file.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <zlib.h>

int lf_is_gzip(const void *buf, size_t len)
{
    const unsigned char *b = buf;
    return len >= 2 && b[0] == 0x1f && b[1] == 0x8b;
}

static int too_big(lf_error *err, const char *name, size_t max_bytes, int gz)
{
    return lf_error_set(err, LF_ERR_IO, "%s: %s larger than the limit of %zu bytes; refusing to read it", name,
                        gz ? "decompressed data is" : "file is", max_bytes);
}

/* ------------------------------------------------------------------------ */
/* Streams: the content a chunk at a time                                   */

enum { STREAM_IN_BYTES = 1 << 16 };

struct lf_file_stream {
    char *name;                   /* for messages */
    FILE *f;                      /* NULL: an in-memory source */
    const unsigned char *mem;     /* in-memory source (lf_gunzip) */
    size_t mem_len, mem_pos;
    size_t size_hint;             /* the file's size, when it is a regular file */
    unsigned char *in;            /* compressed (or plain) bytes read ahead */
    int gz;                       /* content is gzip */
    int src_end;                  /* the source has no more bytes */
    int member_end;               /* a gzip member ended: another, padding or the end follows */
    int done;                     /* everything delivered (or failed) */
    z_stream zs;
    int zs_ready;
};

/* Refills s->zs.next_in/avail_in from the source.  0, or an error. */
static int stream_fill(lf_file_stream *s, lf_error *err)
{
    if (s->zs.avail_in || s->src_end)
        return LF_OK;
    if (!s->f) { /* in memory: the next 1 GiB at most (zlib counts in uInt) */
        size_t k = s->mem_len - s->mem_pos > (1u << 30) ? (1u << 30) : s->mem_len - s->mem_pos;
        s->zs.next_in = (Bytef *)(uintptr_t)(s->mem + s->mem_pos);
        s->zs.avail_in = (uInt)k;
        s->mem_pos += k;
        s->src_end = k == 0;
        return LF_OK;
    }
    size_t n = fread(s->in, 1, STREAM_IN_BYTES, s->f);
    if (n == 0) {
        if (ferror(s->f))
            return lf_error_set(err, LF_ERR_IO, "%s: read error: %s", s->name, strerror(errno ? errno : EIO));
        s->src_end = 1;
    }
    s->zs.next_in = s->in;
    s->zs.avail_in = (uInt)n;
    return LF_OK;
}

static int stream_fail(lf_file_stream *s, int rc)
{
    s->done = 1;
    return rc;
}

/* After a member's end: another member (as `cat a.gz b.gz` makes), zero
 * padding (ignored, as gunzip does) or the end.  0 with s->done set at the
 * end; 0 with the stream reset for a next member; or an error. */
static int stream_next_member(lf_file_stream *s, lf_error *err)
{
    for (;;) {
        while (s->zs.avail_in && *s->zs.next_in == 0)
            s->zs.next_in++, s->zs.avail_in--;
        if (s->zs.avail_in)
            break;
        int rc = stream_fill(s, err);
        if (rc)
            return rc;
        if (s->src_end && !s->zs.avail_in) {
            s->done = 1;
            return LF_OK;
        }
    }
    if (*s->zs.next_in != 0x1f || (s->zs.avail_in > 1 && s->zs.next_in[1] != 0x8b))
        return lf_error_set(err, LF_ERR_PARSE, "%s: corrupt gzip data: trailing garbage after the compressed stream",
                            s->name);
    inflateReset(&s->zs);
    s->member_end = 0;
    return LF_OK;
}

/* Inflates into buf[0, n) (n at most 1 GiB: zlib counts in uInt). */
static int stream_inflate(lf_file_stream *s, char *buf, size_t n, size_t *got, lf_error *err)
{
    *got = 0;
    while (*got < n && !s->done) {
        int rc = s->member_end ? stream_next_member(s, err) : stream_fill(s, err);
        if (rc)
            return rc;
        if (s->done || s->member_end)
            continue;
        s->zs.next_out = (Bytef *)(buf + *got);
        s->zs.avail_out = (uInt)(n - *got);
        int z = inflate(&s->zs, Z_NO_FLUSH);
        *got = n - s->zs.avail_out;
        if (z == Z_STREAM_END) {
            s->member_end = 1;
        } else if (z == Z_MEM_ERROR) {
            return lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory decompressing", s->name);
        } else if (z != Z_OK && z != Z_BUF_ERROR) {
            return lf_error_set(err, LF_ERR_PARSE, "%s: corrupt gzip data (zlib: %s)", s->name,
                                s->zs.msg ? s->zs.msg : "data error");
        } else if (s->src_end && !s->zs.avail_in && s->zs.avail_out) {
            /* all input consumed, output space left, yet no stream end */
            return lf_error_set(err, LF_ERR_PARSE,
                                "%s: corrupt gzip data: truncated (unexpected end of the compressed stream)", s->name);
        }
    }
    return LF_OK;
}

int lf_file_stream_read(lf_file_stream *s, char *buf, size_t n, size_t *got, lf_error *err)
{
    *got = 0;
    if (n > (1u << 30))
        n = 1u << 30;
    if (s->done || n == 0)
        return LF_OK;
    if (s->gz) {
        int rc = stream_inflate(s, buf, n, got, err);
        return rc ? stream_fail(s, rc) : LF_OK;
    }
    /* plain: the bytes read ahead for the magic first, then the file */
    while (*got < n) {
        int rc = stream_fill(s, err);
        if (rc)
            return stream_fail(s, rc);
        if (!s->zs.avail_in) {
            s->done = 1;
            break;
        }
        size_t k = n - *got < s->zs.avail_in ? n - *got : s->zs.avail_in;
        memcpy(buf + *got, s->zs.next_in, k);
        s->zs.next_in += k, s->zs.avail_in -= (uInt)k, *got += k;
    }
    return LF_OK;
}

void lf_file_stream_close(lf_file_stream *s)
{
    if (!s)
        return;
    if (s->zs_ready)
        inflateEnd(&s->zs);
    if (s->f)
        fclose(s->f);
    free(s->in);
    free(s->name);
    free(s);
}

/* Starts a stream over a source already set in s (file or memory): reads
 * ahead to see the gzip magic and prepares zlib if it is there. */
static int stream_start(lf_file_stream *s, lf_error *err)
{
    int rc = stream_fill(s, err);
    if (rc)
        return rc;
    s->gz = lf_is_gzip(s->zs.next_in, s->zs.avail_in);
    if (s->gz) {
        if (inflateInit2(&s->zs, 16 + MAX_WBITS) != Z_OK)
            return lf_error_set(err, LF_ERR_NOMEM, "%s: cannot initialise zlib", s->name);
        s->zs_ready = 1;
    }
    return LF_OK;
}

int lf_file_stream_open(const char *path, lf_file_stream **out, lf_error *err)
{
    *out = NULL;
    lf_file_stream *s = calloc(1, sizeof *s);
    if (!s || !(s->name = strdup(path)) || !(s->in = malloc(STREAM_IN_BYTES))) {
        lf_file_stream_close(s);
        return lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory reading the file", path);
    }
    if (!(s->f = fopen(path, "rb"))) {
        int e = errno;
        lf_file_stream_close(s);
        return lf_error_set(err, LF_ERR_IO, "%s: cannot open: %s", path, strerror(e));
    }
    /* Directories and devices (/dev/zero would never end) are refused;
     * regular files and pipes are read. */
    struct stat st;
    if (fstat(fileno(s->f), &st) == 0 && (S_ISDIR(st.st_mode) || S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode))) {
        lf_file_stream_close(s);
        return lf_error_set(err, LF_ERR_IO, "%s: cannot open: %s", path,
                            S_ISDIR(st.st_mode) ? "is a directory" : "is a device, not a file");
    }
    if (S_ISREG(st.st_mode))
        s->size_hint = (size_t)st.st_size;
    int rc = stream_start(s, err);
    if (rc) {
        lf_file_stream_close(s);
        return rc;
    }
    *out = s;
    return LF_OK;
}

int lf_file_stream_was_gzip(const lf_file_stream *s) { return s->gz; }

/* ------------------------------------------------------------------------ */
/* Whole reads                                                              */

/* Reads the rest of the stream into a malloc'ed, NUL-terminated buffer,
 * refusing more than max_bytes.  cap: the first buffer size. */
static int stream_read_all(lf_file_stream *s, size_t max_bytes, size_t cap, char **data, size_t *len,
                           lf_error *err)
{
    if (cap > max_bytes + 1)
        cap = max_bytes + 1;
    size_t n = 0;
    char *buf = malloc(cap + 1);
    int rc = LF_OK;
    for (;;) {
        if (!buf) {
            rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory reading the file", s->name);
            break;
        }
        if (n == cap) {
            if (cap > max_bytes) {
                rc = too_big(err, s->name, max_bytes, s->gz);
                break;
            }
            size_t ncap = cap * 2 > max_bytes + 1 ? max_bytes + 1 : cap * 2;
            char *nb = realloc(buf, ncap + 1);
            if (!nb) {
                free(buf);
                buf = NULL;
                continue;
            }
            buf = nb;
            cap = ncap;
        }
        size_t got;
        if ((rc = lf_file_stream_read(s, buf + n, cap - n, &got, err)))
            break;
        n += got;
        if (n > max_bytes) {
            rc = too_big(err, s->name, max_bytes, s->gz);
            break;
        }
        if (got == 0)
            break;
    }
    if (rc) {
        free(buf);
        return rc;
    }
    buf[n] = '\0';
    *data = buf;
    *len = n;
    return LF_OK;
}

int lf_gunzip(const unsigned char *in, size_t in_len, const char *name, size_t max_bytes, char **data, size_t *len,
              lf_error *err)
{
    *data = NULL;
    *len = 0;
    if (!lf_is_gzip(in, in_len))
        return lf_error_set(err, LF_ERR_PARSE, "%s: not gzip data", name);
    lf_file_stream *s = calloc(1, sizeof *s);
    if (!s || !(s->name = strdup(name))) {
        lf_file_stream_close(s);
        return lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory", name);
    }
    s->mem = in;
    s->mem_len = in_len;
    int rc = stream_start(s, err);
    if (!rc)
        rc = stream_read_all(s, max_bytes, in_len * 4 + 1024, data, len, err);
    lf_file_stream_close(s);
    return rc;
}

int lf_file_read(const char *path, size_t max_bytes, char **data, size_t *len, int *was_gzip, lf_error *err)
{
    *data = NULL;
    *len = 0;
    if (was_gzip)
        *was_gzip = 0;
    lf_file_stream *s;
    int rc = lf_file_stream_open(path, &s, err);
    if (rc)
        return rc;
    /* a plain file fits its size exactly; a compressed one starts at 4x */
    size_t hint = s->size_hint < ((size_t)1 << 40) ? s->size_hint : 0;
    rc = stream_read_all(s, max_bytes, s->gz ? hint * 4 + 1024 : hint ? hint + 1 : 1 << 16, data, len, err);
    if (!rc && was_gzip)
        *was_gzip = s->gz;
    lf_file_stream_close(s);
    return rc;
}

int lf_file_read_head(const char *path, size_t max_bytes, char **data, size_t *len, int *was_gzip, lf_error *err)
{
    *data = NULL, *len = 0;
    lf_file_stream *s;
    int rc = lf_file_stream_open(path, &s, err);
    if (rc)
        return rc;
    char *buf = malloc(max_bytes + 1);
    size_t n = 0, got = 1;
    if (!buf)
        rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory reading the file", path);
    while (!rc && n < max_bytes && got)
        if (!(rc = lf_file_stream_read(s, buf + n, max_bytes - n, &got, err)))
            n += got;
    if (was_gzip)
        *was_gzip = s->gz;
    lf_file_stream_close(s);
    if (rc) {
        free(buf);
        return rc;
    }
    buf[n] = '\0';
    *data = buf, *len = n;
    return LF_OK;
}

int lf_path_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && !strcasecmp(path + n - e, ext);
}
