/* exr.c - OpenEXR files through the OpenEXRCore C API.
 *
 * Writing: one scanline part, ZIP compression, FLOAT or HALF channels named
 * Y / R,G,B / R,G,B,A / C0..Cn, every lf_attrs entry as a typed attribute.
 * Reading: scanline or tiled (level 0), FLOAT/HALF/UINT channels converted
 * to float, any data window (its size is the image size), channels mapped
 * by name whatever their order in the file.
 */
#include <OpenEXR/openexr.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image_internal.h"

/* OpenEXRCore reports details through a callback (printing to stderr by
 * default, which a library must not do).  The callback has no user pointer
 * we may use with the built-in file streams, so the latest message is kept
 * per thread; each public call clears it first. */
static _Thread_local char exr_last_msg[512];

static void exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    snprintf(exr_last_msg, sizeof exr_last_msg, "%s", msg ? msg : exr_get_default_error_message(code));
}

static const char *exr_msg(exr_result_t rv)
{
    return exr_last_msg[0] ? exr_last_msg : exr_get_default_error_message(rv);
}

static exr_context_initializer_t exr_init(void)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_on_error;
    /* Header warnings would otherwise reach the callback as noise. */
    init.flags |= EXR_CONTEXT_FLAG_SILENT_HEADER_PARSE;
    return init;
}

int lf_exr_is_exr_magic(const unsigned char *bytes, size_t n)
{
    /* 20000630 decimal, little-endian: the first four bytes of every EXR. */
    return n >= 4 && bytes[0] == 0x76 && bytes[1] == 0x2f && bytes[2] == 0x31 && bytes[3] == 0x01;
}

/* ----------------------------------------------------------------- write */

static void channel_name(int k, int channels, char *buf, size_t size)
{
    static const char *const rgba[] = {"R", "G", "B", "A"};
    if (channels == 1)
        snprintf(buf, size, "Y");
    else if (channels == 3 || channels == 4)
        snprintf(buf, size, "%s", rgba[k]);
    else
        snprintf(buf, size, "C%d", k);
}

static exr_result_t write_attr(exr_context_t ctxt, const lf_attr *at)
{
    switch (at->type) {
    case LF_ATTR_STRING:
        return exr_attr_set_string(ctxt, 0, at->name, at->s ? at->s : "");
    case LF_ATTR_INT:
        return exr_attr_set_int(ctxt, 0, at->name, at->i);
    case LF_ATTR_FLOAT:
        return exr_attr_set_float(ctxt, 0, at->name, (float)at->d);
    case LF_ATTR_DOUBLE:
        return exr_attr_set_double(ctxt, 0, at->name, at->d);
    case LF_ATTR_FLOATS:
        return exr_attr_set_float_vector(ctxt, 0, at->name, at->n, at->v);
    case LF_ATTR_M44D: {
        exr_attr_m44d_t m;
        memcpy(m.m, at->m, sizeof m.m);
        return exr_attr_set_m44d(ctxt, 0, at->name, &m);
    }
    }
    return EXR_ERR_INVALID_ARGUMENT;
}

/* Pixels go through per-chunk planar buffers (one contiguous plane per
 * channel) rather than pointing OpenEXRCore into our interleaved image:
 * the 3.1 library picks specialised routines for interleaved layouts that
 * place channels by file order rather than by the pointers given, and
 * corrupt some 3-channel chunks; the planar path is the general one. */
/* OpenEXRCore 3.1 stores a ZIP chunk compressed when the compressed bytes
 * are exactly as many as the raw ones, but readers take a chunk of raw size
 * as stored raw, and decode garbage (OpenEXR issue #2306, fixed in 3.4).
 * This wrapper around the library's compressor stores such chunks raw. */
typedef struct compress_guard {
    exr_result_t (*compress)(exr_encode_pipeline_t *enc);
} compress_guard;

static exr_result_t compress_guarded(exr_encode_pipeline_t *enc)
{
    const compress_guard *g = enc->encoding_user_data;
    exr_result_t rv = g->compress(enc);
    if (rv == EXR_ERR_SUCCESS && enc->compressed_bytes == enc->packed_bytes && enc->compressed_buffer &&
        enc->compressed_buffer != enc->packed_buffer)
        memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
    return rv;
}

static int write_pixels(exr_context_t ctxt, const lf_image *img, const char *name, lf_error *err)
{
    int32_t lines_per_chunk = 1;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines_per_chunk);
    if (rv || lines_per_chunk < 1)
        return lf_error_set(err, LF_ERR_INTERNAL, "cannot write '%s': %s", name, exr_msg(rv));
    if (lines_per_chunk > img->height)
        lines_per_chunk = img->height;

    const int nc = img->channels, w = img->width;
    const size_t plane = (size_t)w * (size_t)lines_per_chunk;
    float *planes = malloc(plane * (size_t)nc * sizeof(float));
    if (!planes)
        return lf_error_set(err, LF_ERR_NOMEM, "cannot write '%s': out of memory", name);
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    compress_guard guard = {NULL};
    int initialized = 0;
    for (int y = 0; y < img->height && !rv; y += lines_per_chunk) {
        exr_chunk_info_t ci;
        rv = exr_write_scanline_chunk_info(ctxt, 0, y, &ci);
        if (rv)
            break;
        rv = initialized ? exr_encoding_update(ctxt, 0, &ci, &enc) : exr_encoding_initialize(ctxt, 0, &ci, &enc);
        if (rv)
            break;
        for (int line = 0; line < ci.height; line++) {
            const float *src = lf_image_px(img, 0, ci.start_y + line);
            for (int x = 0; x < w; x++)
                for (int k = 0; k < nc; k++)
                    planes[(size_t)k * plane + (size_t)line * (size_t)w + (size_t)x] = src[(size_t)x * (size_t)nc + (size_t)k];
        }
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int k = 0;
            char want[16];
            for (; k < nc - 1; k++) { /* every channel of the part is one we declared */
                channel_name(k, nc, want, sizeof want);
                if (strcmp(want, ch->channel_name) == 0)
                    break;
            }
            ch->encode_from_ptr = (const uint8_t *)(planes + (size_t)k * plane);
            ch->user_pixel_stride = sizeof(float);
            ch->user_line_stride = w * (int32_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = sizeof(float);
        }
        if (!initialized) {
            rv = exr_encoding_choose_default_routines(ctxt, 0, &enc);
            if (rv)
                break;
            initialized = 1;
        }
        if (enc.compress_fn && enc.compress_fn != compress_guarded) {
            guard.compress = enc.compress_fn;
            enc.compress_fn = compress_guarded;
            enc.encoding_user_data = &guard;
        }
        rv = exr_encoding_run(ctxt, 0, &enc);
    }
    if (initialized || enc.channels)
        exr_encoding_destroy(ctxt, &enc);
    free(planes);
    if (rv)
        return lf_error_set(err, rv == EXR_ERR_OUT_OF_MEMORY ? LF_ERR_NOMEM : LF_ERR_IO, "cannot write '%s': %s",
                            name, exr_msg(rv));
    return LF_OK;
}

int lf_exr_write(const char *file, const char *name, const lf_image *img, const lf_attrs *attrs, int half,
                 const char *mono_name, lf_error *err)
{
    exr_last_msg[0] = '\0';
    exr_context_initializer_t init = exr_init();
    exr_context_t ctxt = NULL;
    exr_result_t rv = exr_start_write(&ctxt, file, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv) {
        exr_finish(&ctxt);
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, exr_msg(rv));
    }

    int rc = LF_OK, part = 0;
    rv = exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part);
    if (!rv)
        rv = exr_initialize_required_attr_simple(ctxt, part, img->width, img->height, EXR_COMPRESSION_ZIP);
    for (int k = 0; k < img->channels && !rv; k++) {
        char cname[16];
        channel_name(k, img->channels, cname, sizeof cname);
        if (img->channels == 1 && mono_name)
            snprintf(cname, sizeof cname, "%s", mono_name);
        rv = exr_add_channel(ctxt, part, cname, half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    }
    if (rv)
        rc = lf_error_set(err, LF_ERR_INTERNAL, "cannot write '%s': %s", name, exr_msg(rv));

    /* Names up to 31 bytes fit every EXR reader; longer ones need the
     * long-name flag, which only OpenEXR 2+ readers accept, so it is set
     * only when a name needs it. */
    for (size_t i = 0; !rc && attrs && i < attrs->count; i++) {
        const lf_attr *at = &attrs->items[i];
        size_t len = strlen(at->name);
        if (len == 0 || len > 255) {
            rc = lf_error_set(err, LF_ERR_PARAM, "cannot write '%s': attribute name '%s' must be 1-255 bytes", name,
                              at->name);
            break;
        }
        if (len > 31 && (rv = exr_set_longname_support(ctxt, 1)) != 0)
            rc = lf_error_set(err, LF_ERR_INTERNAL, "cannot write '%s': %s", name, exr_msg(rv));
        else if ((rv = write_attr(ctxt, at)) != 0)
            /* Typically a name OpenEXR reserves with another type, e.g. "compression". */
            rc = lf_error_set(err, LF_ERR_PARAM, "cannot write '%s': attribute '%s': %s", name, at->name,
                              exr_msg(rv));
    }

    if (!rc && (rv = exr_write_header(ctxt)) != 0)
        rc = lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, exr_msg(rv));
    if (!rc)
        rc = write_pixels(ctxt, img, name, err);
    /* exr_finish flushes the chunk offset table: its failure is a failed write. */
    rv = exr_finish(&ctxt);
    if (!rc && rv)
        rc = lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", name, exr_msg(rv));
    return rc;
}

/* ------------------------------------------------------------------ read */

static int read_attrs(exr_const_context_t ctxt, lf_attrs *attrs)
{
    int32_t count = 0;
    if (exr_get_attribute_count(ctxt, 0, &count))
        return LF_OK;
    int rc = LF_OK;
    for (int32_t i = 0; i < count && !rc; i++) {
        const exr_attribute_t *at = NULL;
        if (exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, i, &at) || !at)
            continue;
        switch (at->type) {
        case EXR_ATTR_STRING: {
            /* EXR strings carry a length and need not be NUL-terminated. */
            int32_t len = at->string && at->string->length > 0 ? at->string->length : 0;
            char *s = malloc((size_t)len + 1);
            if (!s)
                return LF_ERR_NOMEM;
            if (len)
                memcpy(s, at->string->str, (size_t)len);
            s[len] = '\0';
            rc = lf_attrs_set_string(attrs, at->name, s, NULL);
            free(s);
            break;
        }
        case EXR_ATTR_INT:
            rc = lf_attrs_set_int(attrs, at->name, at->i, NULL);
            break;
        case EXR_ATTR_FLOAT:
            rc = lf_attrs_set_float(attrs, at->name, at->f, NULL);
            break;
        case EXR_ATTR_DOUBLE:
            rc = lf_attrs_set_double(attrs, at->name, at->d, NULL);
            break;
        case EXR_ATTR_FLOAT_VECTOR:
            if (at->floatvector)
                rc = lf_attrs_set_floats(attrs, at->name, at->floatvector->arr, at->floatvector->length, NULL);
            break;
        case EXR_ATTR_M44D:
            if (at->m44d)
                rc = lf_attrs_set_m44d(attrs, at->name, at->m44d->m, NULL);
            break;
        case EXR_ATTR_M44F:
            /* Other writers store camera matrices as m44f; widening is exact. */
            if (at->m44f) {
                double m[16];
                for (int k = 0; k < 16; k++)
                    m[k] = at->m44f->m[k];
                rc = lf_attrs_set_m44d(attrs, at->name, m, NULL);
            }
            break;
        default: /* types lf_attrs cannot hold are skipped */
            break;
        }
    }
    return rc;
}

/* Chooses which file channels become image channels, in order: R,G,B[,A]
 * when present, else Y[,A], else every channel - C0..Cn by their number
 * (the file sorts them by name, so C10 would come before C2), or in file
 * order.  Returns the number of image channels; map[k] is the chlist index. */
static int map_channels(const exr_attr_chlist_t *chl, int *map)
{
    int r = -1, g = -1, b = -1, a = -1, y = -1;
    int n = chl->num_channels;
    for (int i = 0; i < n; i++) {
        const char *s = chl->entries[i].name.str;
        if (strcmp(s, "R") == 0)
            r = i;
        else if (strcmp(s, "G") == 0)
            g = i;
        else if (strcmp(s, "B") == 0)
            b = i;
        else if (strcmp(s, "A") == 0)
            a = i;
        else if (strcmp(s, "Y") == 0)
            y = i;
    }
    if (r >= 0 && g >= 0 && b >= 0) {
        map[0] = r, map[1] = g, map[2] = b, map[3] = a;
        return a >= 0 ? 4 : 3;
    }
    if (y >= 0) {
        map[0] = y, map[1] = a;
        return a >= 0 ? 2 : 1;
    }
    int numbered = 1;
    for (int i = 0; i < n; i++)
        map[i] = -1;
    for (int i = 0; i < n && numbered; i++) {
        const char *s = chl->entries[i].name.str;
        char *end;
        long k = s[0] == 'C' && s[1] >= '0' && s[1] <= '9' ? strtol(s + 1, &end, 10) : -1;
        if (k < 0 || k >= n || *end != '\0' || map[k] >= 0)
            numbered = 0;
        else
            map[k] = i;
    }
    if (!numbered)
        for (int i = 0; i < n; i++)
            map[i] = i;
    return n;
}

typedef struct exr_reader {
    exr_const_context_t ctxt;
    exr_attr_box2i_t dw;
    lf_image *img;
    const int *out_of_file;   /* file channel index -> image channel, or -1 */
    const int *uint_channel;  /* per image channel: stored as UINT */
    float *planes;            /* one plane per image channel, plane_size floats each */
    size_t plane_size;
    exr_decode_pipeline_t dec;
    int initialized;
} exr_reader;

/* Decodes one chunk into the planes, then interleaves it into the image at
 * (x0, y0), the chunk's first pixel relative to the data window, which the
 * caller computes: OpenEXRCore 3.1 gives tile indices, not pixels, in
 * start_x/start_y of tiled chunks.  (Planar buffers: see write_pixels.) */
static exr_result_t decode_chunk(exr_reader *r, const exr_chunk_info_t *ci, int64_t x0, int64_t y0)
{
    exr_result_t rv = r->initialized ? exr_decoding_update(r->ctxt, 0, ci, &r->dec)
                                     : exr_decoding_initialize(r->ctxt, 0, ci, &r->dec);
    if (rv)
        return rv;
    /* A chunk must lie inside the data window and the planes, or the
     * copies below would overrun; a corrupt file must not steer them. */
    const int cw = ci->width, chh = ci->height;
    if (x0 < 0 || y0 < 0 || cw <= 0 || chh <= 0 || x0 + cw > r->img->width || y0 + chh > r->img->height ||
        (size_t)cw * (size_t)chh > r->plane_size)
        return EXR_ERR_CORRUPT_CHUNK;
    const int nc = r->img->channels;
    for (int c = 0; c < r->dec.channel_count; c++) {
        exr_coding_channel_info_t *ch = &r->dec.channels[c];
        int k = r->out_of_file[c];
        /* A channel we do not keep is decoded into a scratch plane (the one
         * after the kept ones) rather than skipped with a NULL pointer:
         * OpenEXRCore 3.1.5's specialised unpackers dereference every
         * channel's pointer (fuzzing found the crash). */
        ch->decode_to_ptr = (uint8_t *)(r->planes + (size_t)(k < 0 ? nc : k) * r->plane_size);
        ch->user_pixel_stride = sizeof(float);
        ch->user_line_stride = cw * (int32_t)sizeof(float);
        /* OpenEXRCore converts HALF to FLOAT but not UINT: those are decoded
         * as UINT into a float-sized slot and converted below. */
        ch->user_data_type = ch->data_type == EXR_PIXEL_UINT ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = sizeof(float);
    }
    if (!r->initialized) {
        rv = exr_decoding_choose_default_routines(r->ctxt, 0, &r->dec);
        if (rv)
            return rv;
        r->initialized = 1;
    }
    rv = exr_decoding_run(r->ctxt, 0, &r->dec);
    if (rv)
        return rv;
    for (int k = 0; k < nc; k++) {
        const float *plane = r->planes + (size_t)k * r->plane_size;
        for (int line = 0; line < chh; line++) {
            float *dst = lf_image_px(r->img, (int)x0, (int)y0 + line) + k;
            const float *src = plane + (size_t)line * (size_t)cw;
            for (int x = 0; x < cw; x++) {
                float v = src[x];
                if (r->uint_channel[k]) {
                    uint32_t u;
                    memcpy(&u, &v, sizeof u);
                    v = (float)u;
                }
                dst[(size_t)x * (size_t)nc] = v;
            }
        }
    }
    return EXR_ERR_SUCCESS;
}

static int read_code(exr_result_t rv)
{
    switch (rv) {
    case EXR_ERR_OUT_OF_MEMORY:
        return LF_ERR_NOMEM;
    case EXR_ERR_FILE_ACCESS:
        return LF_ERR_IO;
    default: /* read errors on a file we could open mean it is short or corrupt */
        return LF_ERR_PARSE;
    }
}

/* The file's channels in image order (map_channels), each file channel's
 * image channel (or -1) in out_of_file and which are stored as UINT;
 * subsampled channels are refused.  *nout: the image channel count. */
static int read_channel_map(const exr_attr_chlist_t *chl, const char *name, int *map, int *out_of_file, int *uint_of,
                            int *nout, lf_error *err)
{
    *nout = map_channels(chl, map);
    for (int i = 0; i < chl->num_channels; i++)
        out_of_file[i] = -1;
    for (int k = 0; k < *nout; k++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[map[k]];
        if (e->x_sampling != 1 || e->y_sampling != 1)
            return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot read '%s': channel '%s' is subsampled", name,
                                e->name.str);
        out_of_file[map[k]] = k;
        uint_of[k] = e->pixel_type == EXR_PIXEL_UINT;
    }
    return LF_OK;
}

/* How the file is cut into chunks (tile size, or scanlines per chunk in
 * *step), and the first chunk located before anything is allocated: a
 * header promising a large image on a truncated or garbage file fails
 * here, cheaply. */
static exr_result_t locate_chunks(exr_context_t ctxt, exr_storage_t storage, const exr_attr_box2i_t *dw, int32_t *tile_w,
                                  int32_t *tile_h, int32_t *step)
{
    exr_result_t rv;
    if (storage == EXR_STORAGE_TILED) {
        rv = exr_get_tile_sizes(ctxt, 0, 0, 0, tile_w, tile_h);
        *step = *tile_h;
        if (!rv && (*tile_w < 1 || *tile_h < 1))
            rv = EXR_ERR_INVALID_ATTR;
    } else {
        rv = exr_get_scanlines_per_chunk(ctxt, 0, step);
        if (!rv && *step < 1)
            rv = EXR_ERR_INVALID_ATTR;
    }
    exr_chunk_info_t ci;
    if (!rv)
        rv = storage == EXR_STORAGE_TILED ? exr_read_tile_chunk_info(ctxt, 0, 0, 0, 0, 0, &ci)
                                          : exr_read_scanline_chunk_info(ctxt, 0, dw->min.y, &ci);
    return rv;
}

/* No EXR codec packs more than about 1000:1 (deflate's limit; RLE, PIZ and
 * B44 far less), so a header promising more pixels than 2048 times the
 * file's bytes (beyond a 256 MiB floor) is a lie: refuse it before
 * allocating (a 747-byte file once asked for 2.4 GB). */
static int check_claimed_size(const char *file, const char *name, int64_t width, int64_t height, int nout,
                              lf_error *err)
{
    struct stat st;
    double need = (double)width * (double)height * (double)nout * 4.0;
    if (stat(file, &st) == 0 && need > 268435456.0 && need > 2048.0 * (double)st.st_size)
        return lf_error_set(err, LF_ERR_PARSE,
                            "cannot read '%s': its header claims %lldx%lld pixels (%.0f MB) but the file has only "
                            "%lld bytes",
                            name, (long long)width, (long long)height, need / 1e6, (long long)st.st_size);
    return LF_OK;
}

/* Every chunk, tile by tile or scanline block by block, into the image. */
static exr_result_t decode_chunks(exr_reader *r, exr_context_t ctxt, exr_storage_t storage, int64_t width,
                                  int64_t height, int32_t tile_w, int32_t tile_h, int32_t step)
{
    exr_result_t rv = EXR_ERR_SUCCESS;
    exr_chunk_info_t ci;
    if (storage == EXR_STORAGE_TILED) {
        int32_t tiles_x = (int32_t)((width + tile_w - 1) / tile_w), tiles_y = (int32_t)((height + tile_h - 1) / tile_h);
        for (int32_t ty = 0; ty < tiles_y && !rv; ty++)
            for (int32_t tx = 0; tx < tiles_x && !rv; tx++)
                if (!(rv = exr_read_tile_chunk_info(ctxt, 0, tx, ty, 0, 0, &ci)))
                    rv = decode_chunk(r, &ci, (int64_t)tx * tile_w, (int64_t)ty * tile_h);
    } else {
        for (int64_t y = r->dw.min.y; y <= r->dw.max.y && !rv; y += step)
            if (!(rv = exr_read_scanline_chunk_info(ctxt, 0, (int)y, &ci)))
                rv = decode_chunk(r, &ci, 0, (int64_t)ci.start_y - r->dw.min.y);
    }
    return rv;
}

int lf_exr_read(const char *file, const char *name, lf_image *img, lf_attrs *attrs, lf_error *err)
{
    exr_last_msg[0] = '\0';
    exr_context_initializer_t init = exr_init();
    exr_context_t ctxt = NULL;
    exr_result_t rv = exr_start_read(&ctxt, file, &init);
    if (rv) {
        exr_finish(&ctxt);
        return lf_error_set(err, read_code(rv), "cannot read '%s': %s", name, exr_msg(rv));
    }

    int rc = LF_OK;
    int *map = NULL, *out_of_file = NULL, uint_channel[4] = {0}, *uint_of = uint_channel;
    exr_reader r = {.ctxt = ctxt, .img = img, .dec = EXR_DECODE_PIPELINE_INITIALIZER};
    exr_storage_t storage;
    const exr_attr_chlist_t *chl = NULL;
    if ((rv = exr_get_storage(ctxt, 0, &storage)) || (rv = exr_get_data_window(ctxt, 0, &r.dw)) ||
        (rv = exr_get_channels(ctxt, 0, &chl))) {
        rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': %s", name, exr_msg(rv));
        goto done;
    }
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        rc = lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot read '%s': deep EXR images are not supported", name);
        goto done;
    }
    if (!chl || chl->num_channels <= 0) {
        rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': no channels", name);
        goto done;
    }
    map = malloc((size_t)chl->num_channels * sizeof *map + 4 * sizeof *map);
    out_of_file = malloc((size_t)chl->num_channels * sizeof *out_of_file);
    if (chl->num_channels > 4)
        uint_of = calloc((size_t)chl->num_channels, sizeof *uint_of);
    if (!map || !out_of_file || !uint_of) {
        rc = lf_error_set(err, LF_ERR_NOMEM, "cannot read '%s': out of memory", name);
        goto done;
    }
    int nout;
    if ((rc = read_channel_map(chl, name, map, out_of_file, uint_of, &nout, err)) != 0)
        goto done;
    r.out_of_file = out_of_file;
    r.uint_channel = uint_of;

    /* Size checks in 64 bits: a hostile data window can span all of int32. */
    int64_t width = (int64_t)r.dw.max.x - r.dw.min.x + 1, height = (int64_t)r.dw.max.y - r.dw.min.y + 1;
    if ((rc = lf_image_check_size(width, height, nout, name, LF_ERR_PARSE, err)) != 0)
        goto done;
    if (attrs && read_attrs(ctxt, attrs)) {
        rc = lf_error_set(err, LF_ERR_NOMEM, "cannot read '%s': out of memory for attributes", name);
        goto done;
    }
    int32_t tile_w = 0, tile_h = 0, step;
    if ((rv = locate_chunks(ctxt, storage, &r.dw, &tile_w, &tile_h, &step)) != 0) {
        rc = lf_error_set(err, read_code(rv), "cannot read '%s': %s", name, exr_msg(rv));
        goto done;
    }
    if ((rc = check_claimed_size(file, name, width, height, nout, err)) != 0)
        goto done;
    if ((rc = lf_image_alloc(img, (int)width, (int)height, nout, err)) != 0)
        goto done;
    /* A chunk never exceeds the image, whatever the header says of tiles. */
    int64_t chunk_w = storage == EXR_STORAGE_TILED && tile_w < width ? tile_w : width;
    int64_t chunk_h = step < height ? step : height;
    r.plane_size = (size_t)chunk_w * (size_t)chunk_h;
    r.planes = malloc(r.plane_size * (size_t)(nout + 1) * sizeof(float)); /* + a scratch plane */
    if (!r.planes) {
        rc = lf_error_set(err, LF_ERR_NOMEM, "cannot read '%s': out of memory", name);
        goto done;
    }
    if ((rv = decode_chunks(&r, ctxt, storage, width, height, tile_w, tile_h, step)) != 0)
        rc = lf_error_set(err, read_code(rv), "cannot read '%s': %s", name, exr_msg(rv));

done:
    if (r.initialized || r.dec.channels)
        exr_decoding_destroy(ctxt, &r.dec);
    exr_finish(&ctxt);
    free(map);
    free(out_of_file);
    if (uint_of != uint_channel)
        free(uint_of);
    free(r.planes);
    if (rc)
        lf_image_free(img);
    return rc;
}
