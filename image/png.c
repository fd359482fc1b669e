/* 8-bit PNG output through libpng, so that writing the tonemapped PNG of a
 * render needs neither OpenImageIO nor its libraries (image/oiio_loader.c
 * loads those only for other formats).  The pixels arrive tonemapped and
 * sRGB-encoded; the file says so with an sRGB chunk.  libpng reports errors
 * by longjmp: its messages are kept for ours, nothing goes to stderr. */
#include <errno.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#include "image_internal.h"

typedef struct png_err_ctx {
    jmp_buf jb;
    char msg[256];
} png_err_ctx;

static void on_error(png_structp png, png_const_charp msg)
{
    int e = errno; /* libpng's "Write Error" follows a failed fwrite: keep its reason */
    png_err_ctx *ctx = png_get_error_ptr(png);
    if (e && strstr(msg, "Write Error"))
        snprintf(ctx->msg, sizeof ctx->msg, "write error: %s", strerror(e));
    else
        snprintf(ctx->msg, sizeof ctx->msg, "%s", msg);
    longjmp(ctx->jb, 1);
}

static void on_warning(png_structp png, png_const_charp msg)
{
    (void)png, (void)msg;
}

int lf_png_write(const char *file, const char *name, int width, int height, int channels,
                 const unsigned char *pixels, lf_error *err)
{
    static const int types[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                PNG_COLOR_TYPE_RGB_ALPHA};
    if (channels < 1 || channels > 4)
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot write '%s': PNG holds 1 to 4 channels, not %d", name,
                            channels);
    FILE *f = fopen(file, "wb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': cannot create %s: %s", name, file, strerror(errno));
    /* volatile: read after longjmp */
    png_err_ctx ctx;
    ctx.msg[0] = 0;
    png_structp volatile png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning);
    png_infop volatile info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_structp p = png;
        png_infop i = info;
        png_destroy_write_struct(p ? &p : NULL, i ? &i : NULL);
        fclose(f);
        return lf_error_set(err, LF_ERR_NOMEM, "cannot write '%s': out of memory", name);
    }
    if (setjmp(ctx.jb)) {
        png_structp p = png;
        png_infop i = info;
        png_destroy_write_struct(&p, &i);
        fclose(f);
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, ctx.msg[0] ? ctx.msg : "libpng error");
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, types[channels - 1], PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    size_t stride = (size_t)width * (size_t)channels;
    for (int y = 0; y < height; y++)
        png_write_row(png, pixels + (size_t)y * stride);
    png_write_end(png, info);
    png_structp p = png;
    png_infop i = info;
    png_destroy_write_struct(&p, &i);
    /* a failed flush or close is a failed write */
    errno = 0;
    if (fflush(f) != 0 || ferror(f)) {
        int e = errno;
        fclose(f);
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': write error: %s", name,
                            e ? strerror(e) : "stream error");
    }
    if (fclose(f) != 0)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': write error: %s", name, strerror(errno));
    return LF_OK;
}
