/* lfrender merge: parts of one render (sample ranges and/or row bands)
 * summed exactly into the image an unsplit render gives (film.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_keys.h"
#include "film.h"
#include "lf_render.h"

typedef struct part {
    lf_image img;
    lf_attrs attrs;
    int bounds[4];
    int spp_begin, spp_end;
} part;

static int get_int(const lf_attrs *a, const char *name, int *out)
{
    const lf_attr *x = lf_attrs_get(a, name);
    if (!x || x->type != LF_ATTR_INT)
        return -1;
    *out = x->i;
    return 0;
}

int lf_render_merge(const char *const *paths, int n, lf_image *out, lf_attrs *meta, lf_error *err)
{
    memset(out, 0, sizeof *out);
    if (n <= 0)
        return lf_error_set(err, LF_ERR_PARAM, "merge: no part files given");
    part *parts = calloc((size_t)n, sizeof *parts);
    if (!parts)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    int rc = 0, spp_total = 0, bx0 = 1 << 30, bx1 = -1, by0 = 1 << 30, by1 = -1;
    const char *settings = NULL;
    double seconds = 0;
    for (int i = 0; i < n && !rc; i++) {
        part *p = &parts[i];
        lf_error e = {0};
        if (lf_image_read(paths[i], &p->img, &p->attrs, &e)) {
            rc = lf_error_set(err, e.code, "merge: %s", e.msg);
            break;
        }
        const lf_attr *st = lf_attrs_get(&p->attrs, LF_KEY_SETTINGS);
        const lf_attr *pb = lf_attrs_get(&p->attrs, LF_KEY_PIXEL_BOUNDS);
        int is_part = 0, total = 0;
        if (get_int(&p->attrs, LF_KEY_PART, &is_part) || !is_part || !st || st->type != LF_ATTR_STRING || !pb ||
            pb->n != 4 || get_int(&p->attrs, LF_KEY_SPP_BEGIN, &p->spp_begin) ||
            get_int(&p->attrs, LF_KEY_SPP_END, &p->spp_end) ||
            get_int(&p->attrs, LF_KEY_SPP_TOTAL, &total) || p->img.channels != 3 + LF_ACC_CHANNELS) {
            rc = lf_error_set(err, LF_ERR_PARAM,
                              "merge: %s is not a render part (render parts with --spp-range, --tile or --part)",
                              paths[i]);
            break;
        }
        if (!settings) {
            settings = st->s;
            spp_total = total;
        } else if (strcmp(settings, st->s) != 0 || total != spp_total) {
            rc = lf_error_set(err, LF_ERR_PARAM,
                              "merge: %s comes from a different render than %s:\n  %s\nvs\n  %s", paths[i], paths[0],
                              st->s, settings);
            break;
        }
        for (int k = 0; k < 4; k++)
            p->bounds[k] = (int)pb->v[k];
        if (p->bounds[1] - p->bounds[0] != p->img.width || p->bounds[3] - p->bounds[2] != p->img.height) {
            rc = lf_error_set(err, LF_ERR_PARAM, "merge: %s: pixel bounds do not match its size", paths[i]);
            break;
        }
        bx0 = p->bounds[0] < bx0 ? p->bounds[0] : bx0;
        bx1 = p->bounds[1] > bx1 ? p->bounds[1] : bx1;
        by0 = p->bounds[2] < by0 ? p->bounds[2] : by0;
        by1 = p->bounds[3] > by1 ? p->bounds[3] : by1;
        const lf_attr *t = lf_attrs_get(&p->attrs, LF_KEY_RENDER_TIME_S);
        if (t && t->type == LF_ATTR_DOUBLE)
            seconds += t->d;
    }
    lf_pixel_acc *acc = NULL;
    int *count = NULL;
    int w = bx1 - bx0, h = by1 - by0;
    if (!rc) {
        acc = calloc((size_t)w * h, sizeof *acc);
        count = calloc((size_t)w * h, sizeof *count);
        if (!acc || !count)
            rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    for (int i = 0; i < n && !rc; i++) {
        part *p = &parts[i];
        for (int y = 0; y < p->img.height; y++)
            for (int x = 0; x < p->img.width; x++) {
                size_t k = (size_t)(y + p->bounds[2] - by0) * w + (x + p->bounds[0] - bx0);
                const float *in = lf_image_px(&p->img, x, y);
                for (int c = 0; c < 4; c++)
                    acc[k].v[c] += lf_acc_from_limbs(in + 3 + LF_ACC_LIMBS * c);
                count[k] += p->spp_end - p->spp_begin;
            }
    }
    /* every pixel must have got every sample exactly once */
    for (int k = 0; k < w * h && !rc; k++)
        if (count[k] != spp_total)
            rc = lf_error_set(err, LF_ERR_PARAM,
                              "merge: pixel (%d, %d) has %d of %d samples: a part is missing or two overlap",
                              bx0 + k % w, by0 + k / w, count[k], spp_total);
    if (!rc && !lf_image_alloc(out, w, h, 3, err)) {
        for (int k = 0; k < w * h; k++)
            for (int c = 0; c < 3; c++)
                out->data[3 * (size_t)k + c] = lf_acc_value(&acc[k], c);
        if (meta) {
            const lf_attrs *a0 = &parts[0].attrs;
            int oom = 0;
            for (size_t j = 0; j < a0->count; j++) {
                const lf_attr *x = &a0->items[j];
                if (strncmp(x->name, LF_KEY_PREFIX, sizeof LF_KEY_PREFIX - 1) != 0 || !strcmp(x->name, LF_KEY_PART) ||
                    !strcmp(x->name, LF_KEY_SPP_BEGIN) || !strcmp(x->name, LF_KEY_SPP_END))
                    continue;
                oom |= lf_attrs_set_copy(meta, x, NULL);
            }
            float b[4] = {(float)bx0, (float)bx1, (float)by0, (float)by1};
            oom |= lf_attrs_set_int(meta, LF_KEY_SPP, spp_total, NULL) |
                   lf_attrs_set_int(meta, LF_KEY_MERGED_PARTS, n, NULL) |
                   lf_attrs_set_double(meta, LF_KEY_RENDER_TIME_S, seconds, NULL) |
                   lf_attrs_set_floats(meta, LF_KEY_PIXEL_BOUNDS, b, 4, NULL);
            if (oom) {
                lf_image_free(out);
                rc = lf_error_set(err, LF_ERR_NOMEM, "merge: out of memory for the merged image's attributes");
            }
        }
    } else if (!rc) {
        rc = err->code;
    }
    free(acc);
    free(count);
    for (int i = 0; i < n; i++) {
        lf_image_free(&parts[i].img);
        lf_attrs_free(&parts[i].attrs);
    }
    free(parts);
    return rc;
}
