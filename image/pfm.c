/* Portable Float Map (PFM): the format of disparity maps in light-field
 * benchmarks (docs/lightfield-format.md, "PFM").
 *
 *   "PF\n" (3 channels) or "Pf\n" (1 channel)
 *   "<width> <height>\n"
 *   "<scale>\n"      negative: little-endian floats, positive: big-endian;
 *                    |scale| is informational only
 *   width * height * channels 32-bit floats, rows stored BOTTOM-UP.
 *
 * The header tokens may be separated by any white space (one character of
 * white space after the scale, as in PNM).  Reading flips rows so row 0 is
 * the top, as every lf_image; writing is little-endian (scale -1).
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_internal.h"

static int host_little_endian(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void swap4(unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++, p += 4) {
        unsigned char t = p[0];
        p[0] = p[3], p[3] = t;
        t = p[1], p[1] = p[2], p[2] = t;
    }
}

/* Next header token (at most n-1 characters); returns 0 or -1 at EOF/overlong. */
static int token(FILE *f, char *buf, size_t n)
{
    int c;
    while ((c = fgetc(f)) != EOF && (c == ' ' || c == '\t' || c == '\n' || c == '\r'))
        ;
    size_t k = 0;
    while (c != EOF && c != ' ' && c != '\t' && c != '\n' && c != '\r') {
        if (k + 1 >= n)
            return -1;
        buf[k++] = (char)c;
        c = fgetc(f);
    }
    buf[k] = '\0';
    /* c is the single white-space character that ends the token (or EOF) */
    return k ? 0 : -1;
}

int lf_pfm_read(const char *file, const char *name, lf_image *img, lf_error *err)
{
    memset(img, 0, sizeof *img);
    FILE *f = fopen(file, "rb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot open '%s': %s", name, strerror(errno));
    char magic[8], ws[32], hs[32], ss[64];
    int rc = LF_OK;
    if (token(f, magic, sizeof magic) || (strcmp(magic, "PF") && strcmp(magic, "Pf"))) {
        rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': not a PFM file (expected \"PF\" or \"Pf\")", name);
        goto done;
    }
    if (token(f, ws, sizeof ws) || token(f, hs, sizeof hs) || token(f, ss, sizeof ss)) {
        rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': PFM header ends early (expected width, height, scale)",
                          name);
        goto done;
    }
    char *e1, *e2, *e3;
    errno = 0;
    long w = strtol(ws, &e1, 10), h = strtol(hs, &e2, 10);
    double scale = strtod(ss, &e3);
    if (*e1 || *e2 || *e3 || errno || w < 1 || h < 1 || !isfinite(scale) || scale == 0) {
        rc = lf_error_set(err, LF_ERR_PARSE,
                          "cannot read '%s': bad PFM header \"%s %s %s\" (expected width >= 1, height >= 1 and a "
                          "non-zero scale)",
                          name, ws, hs, ss);
        goto done;
    }
    int channels = magic[1] == 'F' ? 3 : 1;
    if ((rc = lf_image_check_size(w, h, channels, name, LF_ERR_PARSE, err)))
        goto done;
    if ((rc = lf_image_alloc(img, (int)w, (int)h, channels, err)))
        goto done;
    size_t row = (size_t)w * channels;
    for (long y = h - 1; y >= 0; y--) { /* bottom-up */
        float *dst = img->data + (size_t)y * row;
        if (fread(dst, sizeof(float), row, f) != row) {
            rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': PFM data ends early (%ld x %ld x %d floats expected)",
                              name, w, h, channels);
            goto done;
        }
        if ((scale < 0) != host_little_endian())
            swap4((unsigned char *)dst, row);
    }
done:
    fclose(f);
    if (rc)
        lf_image_free(img);
    return rc;
}

int lf_pfm_write(const char *file, const char *name, const lf_image *img, lf_error *err)
{
    if (img->channels != 1 && img->channels != 3)
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot write '%s': PFM holds 1 or 3 channels, the image has %d",
                            name, img->channels);
    FILE *f = fopen(file, "wb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, strerror(errno));
    errno = 0;
    int ok = fprintf(f, "%s\n%d %d\n-1.0\n", img->channels == 3 ? "PF" : "Pf", img->width, img->height) > 0;
    size_t row = (size_t)img->width * img->channels;
    float *buf = malloc(row * sizeof *buf);
    ok = ok && buf;
    for (int y = img->height - 1; ok && y >= 0; y--) {
        memcpy(buf, img->data + (size_t)y * row, row * sizeof *buf);
        if (!host_little_endian())
            swap4((unsigned char *)buf, row);
        ok = fwrite(buf, sizeof *buf, row, f) == row;
    }
    int e = ok ? 0 : (buf ? errno : ENOMEM);
    free(buf);
    if (fclose(f) && ok)
        ok = 0, e = errno;
    return ok ? LF_OK
              : lf_error_set(err, LF_ERR_IO, "cannot write '%s': write failed: %s", name,
                             e ? strerror(e) : "stream error");
}
