/* safeio.c - reading a student's files as untrusted data.
 *
 * Names are plain file names (no '/', no leading '.'), opened relative to
 * the submission directory with O_NOFOLLOW; a symbolic link is followed only
 * when its real path lies inside the submission's real path.  Only regular
 * files are read (O_NONBLOCK, so a FIFO cannot hang the grader), at most a
 * fixed number of bytes.  Image headers are checked here, before any
 * decoder sees the bytes, so a 100000 x 100000 header costs nothing. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "grade_internal.h"

static int plain_name(const char *name)
{
    if (!name[0] || name[0] == '.' || strlen(name) > 200)
        return 0;
    for (const char *p = name; *p; p++)
        if (*p == '/' || (unsigned char)*p < 32)
            return 0;
    return 1;
}

static int read_fd(int fd, const char *name, size_t max, unsigned char **data, size_t *n, char *why, size_t wn)
{
    struct stat st;
    if (fstat(fd, &st)) {
        snprintf(why, wn, "%s: cannot stat: %s", name, strerror(errno));
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(why, wn, "%s: not a regular file (not read)", name);
        return -1;
    }
    if (st.st_size == 0) {
        snprintf(why, wn, "%s: empty file", name);
        return -1;
    }
    if ((uintmax_t)st.st_size > max) {
        snprintf(why, wn, "%s: %jd bytes, more than the %zu allowed (not read)", name, (intmax_t)st.st_size, max);
        return -1;
    }
    size_t size = (size_t)st.st_size, got = 0;
    unsigned char *buf = malloc(size + 1);
    if (!buf) {
        snprintf(why, wn, "%s: out of memory", name);
        return -1;
    }
    while (got < size) {
        ssize_t r = read(fd, buf + got, size - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    if (got == 0) {
        free(buf);
        snprintf(why, wn, "%s: empty file", name);
        return -1;
    }
    buf[got] = 0;
    *data = buf;
    *n = got;
    return 0;
}

int lf_grade_read_inside(const char *dir, const char *name, size_t max, unsigned char **data, size_t *n,
                         char *why, size_t wn)
{
    *data = NULL;
    *n = 0;
    if (!plain_name(name)) {
        snprintf(why, wn, "%s: not a plain file name", name);
        return -1;
    }
    int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd < 0) {
        snprintf(why, wn, "%s: cannot open the submission folder: %s", dir, strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstatat(dfd, name, &st, AT_SYMLINK_NOFOLLOW)) {
        int e = errno;
        close(dfd);
        if (e == ENOENT)
            return 1;
        snprintf(why, wn, "%s: %s", name, strerror(e));
        return -1;
    }
    int fd = -1;
    if (S_ISLNK(st.st_mode)) {
        char target[PATH_MAX] = "", full[PATH_MAX], real_dir[PATH_MAX], real_file[PATH_MAX];
        ssize_t tl = readlinkat(dfd, name, target, sizeof target - 1);
        target[tl > 0 ? tl : 0] = 0;
        snprintf(full, sizeof full, "%s/%s", dir, name);
        if (!realpath(dir, real_dir) || !realpath(full, real_file)) {
            close(dfd);
            snprintf(why, wn, "%s: symbolic link to %s, which does not resolve (not followed)", name, target);
            return -1;
        }
        size_t dl = strlen(real_dir);
        if (strncmp(real_file, real_dir, dl) || real_file[dl] != '/') {
            close(dfd);
            snprintf(why, wn, "%s: symbolic link to %s, outside the submission (not followed)", name, target);
            return -1;
        }
        fd = open(real_file, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    } else {
        fd = openat(dfd, name, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    }
    close(dfd);
    if (fd < 0) {
        snprintf(why, wn, "%s: cannot open: %s", name, strerror(errno));
        return -1;
    }
    int rc = read_fd(fd, name, max, data, n, why, wn);
    close(fd);
    return rc;
}

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}
static int32_t le32(const unsigned char *p)
{
    return (int32_t)((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24);
}

/* OpenEXR header: magic, version, then (name\0 type\0 int32 size, value)*
 * ending with an empty name; dataWindow is a box2i (xmin ymin xmax ymax). */
static int exr_header(const unsigned char *d, size_t n, int *w, int *h, char *why, size_t wn)
{
    if (n < 8) {
        snprintf(why, wn, "truncated EXR header");
        return -1;
    }
    uint32_t version = (uint32_t)le32(d + 4);
    if (version & 0x1000) {
        snprintf(why, wn, "multi-part EXR files are not accepted");
        return -1;
    }
    size_t p = 8;
    int found = 0;
    for (int guard = 0; guard < 4096; guard++) {
        if (p >= n) {
            snprintf(why, wn, "truncated EXR header");
            return -1;
        }
        if (d[p] == 0)
            break;
        const unsigned char *nm = d + p, *nul = memchr(nm, 0, n - p);
        if (!nul || (size_t)(nul - nm) > 255) {
            snprintf(why, wn, "corrupt EXR header (attribute name)");
            return -1;
        }
        p = (size_t)(nul - d) + 1;
        const unsigned char *ty = d + p, *nul2 = p < n ? memchr(ty, 0, n - p) : NULL;
        if (!nul2 || (size_t)(nul2 - ty) > 255) {
            snprintf(why, wn, "corrupt EXR header (attribute type)");
            return -1;
        }
        p = (size_t)(nul2 - d) + 1;
        if (p + 4 > n) {
            snprintf(why, wn, "truncated EXR header");
            return -1;
        }
        int32_t sz = le32(d + p);
        p += 4;
        if (sz < 0 || (size_t)sz > n - p) {
            snprintf(why, wn, "corrupt or truncated EXR header (attribute size %d)", (int)sz);
            return -1;
        }
        if (!strcmp((const char *)nm, "dataWindow") && !strcmp((const char *)ty, "box2i") && sz == 16) {
            int64_t x0 = le32(d + p), y0 = le32(d + p + 4), x1 = le32(d + p + 8), y1 = le32(d + p + 12);
            int64_t ww = x1 - x0 + 1, hh = y1 - y0 + 1;
            if (ww < 1 || hh < 1 || ww > LF_GRADE_MAX_DIM || hh > LF_GRADE_MAX_DIM ||
                ww * hh > (int64_t)LF_GRADE_MAX_PIXELS) {
                snprintf(why, wn, "EXR header claims %lld x %lld pixels (limit %d per side, %u in all): not decoded",
                         (long long)ww, (long long)hh, LF_GRADE_MAX_DIM, LF_GRADE_MAX_PIXELS);
                return -1;
            }
            *w = (int)ww, *h = (int)hh;
            found = 1;
        }
        p += (size_t)sz;
    }
    if (!found) {
        snprintf(why, wn, "EXR header without a dataWindow");
        return -1;
    }
    return 0;
}

int lf_grade_image_header(const unsigned char *d, size_t n, const char **format, int *w, int *h, char *why,
                          size_t wn)
{
    static const unsigned char png_magic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
    if (n >= 8 && !memcmp(d, png_magic, 8)) {
        *format = "png";
        if (n < 24 || memcmp(d + 12, "IHDR", 4)) {
            snprintf(why, wn, "truncated or corrupt PNG header");
            return -1;
        }
        uint32_t ww = be32(d + 16), hh = be32(d + 20);
        if (ww < 1 || hh < 1 || ww > LF_GRADE_MAX_DIM || hh > LF_GRADE_MAX_DIM ||
            (uint64_t)ww * hh > LF_GRADE_MAX_PIXELS) {
            snprintf(why, wn, "PNG header claims %u x %u pixels (limit %d per side, %u in all): not decoded", ww, hh,
                     LF_GRADE_MAX_DIM, LF_GRADE_MAX_PIXELS);
            return -1;
        }
        *w = (int)ww, *h = (int)hh;
        return 0;
    }
    if (n >= 4 && !memcmp(d, exr_magic, 4)) {
        *format = "exr";
        return exr_header(d, n, w, h, why, wn);
    }
    *format = NULL;
    snprintf(why, wn, "neither a PNG nor an OpenEXR file");
    return -1;
}

int lf_grade_image_decode(const unsigned char *data, size_t n, const char *format, lf_image *img, char *why,
                          size_t wn)
{
    const char *tmp = getenv("TMPDIR");
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/lfgrade-XXXXXX.%s", tmp && tmp[0] ? tmp : "/tmp", format);
    int fd = mkstemps(path, (int)strlen(format) + 1);
    if (fd < 0) {
        snprintf(why, wn, "grader: cannot create a temporary file: %s", strerror(errno));
        return -1;
    }
    size_t put = 0;
    int werr = 0;
    while (put < n) {
        ssize_t r = write(fd, data + put, n - put);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0) {
            werr = r < 0 ? errno : ENOSPC;
            break;
        }
        put += (size_t)r;
    }
    close(fd);
    lf_error err = {0};
    int rc = put == n ? lf_image_read(path, img, NULL, &err) : -1;
    unlink(path);
    if (rc) {
        /* the library's message names our temporary file: keep only the cause */
        const char *m = err.msg;
        const char *p = strstr(m, path);
        if (p)
            m = p + strlen(path);
        while (*m == '\'' || *m == ':' || *m == ' ') /* the quote that closed the path, then ": " */
            m++;
        if (put == n)
            snprintf(why, wn, "cannot decode: %s", m[0] ? m : "unreadable image");
        else
            snprintf(why, wn, "cannot decode: writing the temporary copy failed: %s", strerror(werr));
        memset(img, 0, sizeof *img);
        return -1;
    }
    return 0;
}
