/* file.c - whole-file reads with transparent gunzip (see lf_file.h). */
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

int lf_gunzip(const unsigned char *in, size_t in_len, const char *name, size_t max_bytes, char **data, size_t *len,
              lf_error *err)
{
    *data = NULL;
    *len = 0;
    if (!lf_is_gzip(in, in_len))
        return lf_error_set(err, LF_ERR_PARSE, "%s: not gzip data", name);
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK)
        return lf_error_set(err, LF_ERR_NOMEM, "%s: cannot initialise zlib", name);
    size_t cap = in_len * 4 + 1024, n = 0;
    if (cap > max_bytes + 1)
        cap = max_bytes + 1;
    char *out = malloc(cap + 1);
    if (!out) {
        inflateEnd(&zs);
        return lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory", name);
    }
    size_t in_pos = 0;
    int rc = LF_OK;
    for (;;) {
        /* zlib counts in uInt: feed and drain in chunks of at most 1 GiB. */
        size_t in_chunk = in_len - in_pos > (1u << 30) ? (1u << 30) : in_len - in_pos;
        if (n == cap) {
            if (cap > max_bytes) {
                rc = too_big(err, name, max_bytes, 1);
                break;
            }
            size_t ncap = cap * 2 > max_bytes + 1 ? max_bytes + 1 : cap * 2;
            char *nb = realloc(out, ncap + 1);
            if (!nb) {
                rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory decompressing", name);
                break;
            }
            out = nb;
            cap = ncap;
        }
        size_t out_chunk = cap - n > (1u << 30) ? (1u << 30) : cap - n;
        zs.next_in = (Bytef *)(uintptr_t)(in + in_pos);
        zs.avail_in = (uInt)in_chunk;
        zs.next_out = (Bytef *)(out + n);
        zs.avail_out = (uInt)out_chunk;
        int z = inflate(&zs, Z_NO_FLUSH);
        in_pos += in_chunk - zs.avail_in;
        n += out_chunk - zs.avail_out;
        if (n > max_bytes) {
            rc = too_big(err, name, max_bytes, 1);
            break;
        }
        if (z == Z_STREAM_END) {
            /* Another gzip member may follow (as `cat a.gz b.gz` makes);
             * trailing zero padding is ignored as gunzip does. */
            size_t k = in_pos;
            while (k < in_len && in[k] == 0)
                k++;
            if (k >= in_len)
                break;
            if (!lf_is_gzip(in + in_pos, in_len - in_pos)) {
                rc = lf_error_set(err, LF_ERR_PARSE, "%s: corrupt gzip data: trailing garbage after the compressed stream",
                                  name);
                break;
            }
            inflateReset(&zs);
            continue;
        }
        if (z == Z_BUF_ERROR && zs.avail_out != 0) {
            rc = lf_error_set(err, LF_ERR_PARSE, "%s: corrupt gzip data: truncated (unexpected end of the compressed stream)",
                              name);
            break;
        }
        if (z == Z_MEM_ERROR) {
            rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory decompressing", name);
            break;
        }
        if (z != Z_OK && z != Z_BUF_ERROR) {
            rc = lf_error_set(err, LF_ERR_PARSE, "%s: corrupt gzip data (zlib: %s)", name,
                              zs.msg ? zs.msg : "data error");
            break;
        }
        if (z == Z_OK && in_pos >= in_len && zs.avail_out != 0) {
            /* all input consumed, output space left, yet no stream end */
            rc = lf_error_set(err, LF_ERR_PARSE, "%s: corrupt gzip data: truncated (unexpected end of the compressed stream)",
                              name);
            break;
        }
    }
    inflateEnd(&zs);
    if (rc) {
        free(out);
        return rc;
    }
    out[n] = '\0';
    *data = out;
    *len = n;
    return LF_OK;
}

int lf_file_read(const char *path, size_t max_bytes, char **data, size_t *len, int *was_gzip, lf_error *err)
{
    *data = NULL;
    *len = 0;
    if (was_gzip)
        *was_gzip = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    /* Directories and devices (/dev/zero would fill memory up to the limit)
     * are refused; regular files and pipes are read. */
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && (S_ISDIR(st.st_mode) || S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode))) {
        fclose(f);
        return lf_error_set(err, LF_ERR_IO, "%s: cannot open: %s", path,
                            S_ISDIR(st.st_mode) ? "is a directory" : "is a device, not a file");
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    int rc = LF_OK;
    for (;;) {
        if (!buf) {
            rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory reading the file", path);
            break;
        }
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap)
            break;
        /* A compressed file may be at most as large as the decompressed
         * limit allows too. */
        if (cap > max_bytes) {
            rc = too_big(err, path, max_bytes, 0);
            break;
        }
        size_t ncap = cap * 2;
        char *nb = realloc(buf, ncap + 1);
        if (!nb) {
            free(buf);
            buf = NULL;
            continue;
        }
        buf = nb;
        cap = ncap;
    }
    if (!rc && ferror(f))
        rc = lf_error_set(err, LF_ERR_IO, "%s: read error: %s", path, strerror(errno ? errno : EIO));
    fclose(f);
    if (rc) {
        free(buf);
        return rc;
    }
    if (lf_is_gzip(buf, n)) {
        char *out;
        size_t out_len;
        rc = lf_gunzip((const unsigned char *)buf, n, path, max_bytes, &out, &out_len, err);
        free(buf);
        if (rc)
            return rc;
        if (was_gzip)
            *was_gzip = 1;
        *data = out;
        *len = out_len;
        return LF_OK;
    }
    if (n > max_bytes) {
        free(buf);
        return too_big(err, path, max_bytes, 0);
    }
    buf[n] = '\0';
    *data = buf;
    *len = n;
    return LF_OK;
}

int lf_file_read_head(const char *path, size_t max_bytes, char **data, size_t *len, int *was_gzip, lf_error *err)
{
    *data = NULL, *len = 0;
    if (max_bytes > (size_t)INT32_MAX)
        max_bytes = (size_t)INT32_MAX; /* gzread counts in unsigned int */
    gzFile g = gzopen(path, "rb");
    if (!g)
        return lf_error_set(err, LF_ERR_IO, "%s: cannot open: %s", path, strerror(errno ? errno : ENOMEM));
    char *buf = malloc(max_bytes + 1);
    int n = buf ? gzread(g, buf, (unsigned)max_bytes) : -1;
    int errnum = 0;
    const char *zmsg = n < 0 ? gzerror(g, &errnum) : NULL;
    if (was_gzip)
        *was_gzip = !gzdirect(g);
    int rc = !buf ? lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory reading the file", path)
             : n < 0 ? lf_error_set(err, LF_ERR_PARSE, "%s: corrupt gzip data (zlib: %s)", path,
                                     errnum == Z_ERRNO ? strerror(errno) : zmsg)
                     : LF_OK;
    gzclose(g);
    if (rc) {
        free(buf);
        return rc;
    }
    buf[n] = '\0';
    *data = buf, *len = (size_t)n;
    return LF_OK;
}

int lf_path_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && !strcasecmp(path + n - e, ext);
}
