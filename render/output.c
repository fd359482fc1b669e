/* Writing a render's disparity AOV (lf_render.h). */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/lf_file.h"
#include "base/lf_keys.h"
#include "lf_render.h"

int lf_render_write_disparity(lf_renderer *r, const char *out, lf_attrs *meta, char *written, size_t written_size,
                              float range[2], lf_error *err)
{
    size_t len = strlen(out);
    if (!lf_path_has_ext(out, ".exr"))
        return lf_error_set(err, LF_ERR_PARAM, "the disparity AOV needs an .exr output, not %s", out);
    lf_image d;
    int rc = lf_renderer_disparity(r, &d, err);
    if (rc)
        return rc;
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%.*s.disparity.exr", (int)(len - 4), out);
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    range[0] = INFINITY, range[1] = -INFINITY;
    for (size_t i = 0; i < (size_t)d.width * d.height; i++)
        range[0] = fminf(range[0], d.data[i]), range[1] = fmaxf(range[1], d.data[i]);
    lf_attrs a = {0};
    rc = lf_attrs_set_string(meta, LF_KEY_DISPARITY_FILE, base, NULL) |
         lf_attrs_set_floats(meta, LF_KEY_DISPARITY_RANGE, range, 2, NULL);
    for (size_t k = 0; k < meta->count && !rc; k++)
        rc = lf_attrs_set_copy(&a, &meta->items[k], NULL);
    if (!rc)
        rc = lf_attrs_set_string(&a, LF_KEY_AOV, "disparity", NULL);
    if (rc)
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory for the disparity AOV's attributes");
    else
        rc = lf_image_write(path, &d, &a, NULL, err);
    if (!rc && written)
        snprintf(written, written_size, "%s", path);
    lf_attrs_free(&a);
    lf_image_free(&d);
    return rc;
}
