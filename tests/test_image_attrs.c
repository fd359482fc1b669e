/* Attribute copies, the half-float range test and picture write options
 * (image/image.c, image/tonemap.c). */
#include <math.h>
#include <string.h>

#include "image/lf_image.h"
#include "lf_test.h"

int main(void)
{
    lf_attrs a = {0}, b = {0};
    const float v[3] = {1.5f, -2, 3};
    double m[16];
    for (int i = 0; i < 16; i++)
        m[i] = i * 0.5;
    CHECK(lf_attrs_set_string(&a, "s", "text", NULL) == 0 && lf_attrs_set_int(&a, "i", -7, NULL) == 0);
    CHECK(lf_attrs_set_float(&a, "f", 0.25f, NULL) == 0 && lf_attrs_set_double(&a, "d", 1e-300, NULL) == 0);
    CHECK(lf_attrs_set_floats(&a, "v", v, 3, NULL) == 0 && lf_attrs_set_m44d(&a, "m", m, NULL) == 0);
    for (size_t k = 0; k < a.count; k++)
        CHECK(lf_attrs_set_copy(&b, &a.items[k], NULL) == 0);
    CHECK(b.count == 6);
    /* failures are an LF_ERR_* status with the library's message */
    lf_error e = {0};
    CHECK(lf_attrs_set_floats(&b, "bad", NULL, 3, &e) == LF_ERR_PARAM && !strcmp(e.msg, "attribute \"bad\": 3 values"));
    lf_error_clear(&e);
    CHECK(lf_attrs_set_int(NULL, "x", 1, &e) == LF_ERR_PARAM && e.code == LF_ERR_PARAM);
    CHECK(b.count == 6);
    const lf_attr *x;
    CHECK((x = lf_attrs_get(&b, "s")) && x->type == LF_ATTR_STRING && !strcmp(x->s, "text"));
    CHECK((x = lf_attrs_get(&b, "i")) && x->type == LF_ATTR_INT && x->i == -7);
    CHECK((x = lf_attrs_get(&b, "f")) && x->type == LF_ATTR_FLOAT && x->d == 0.25);
    CHECK((x = lf_attrs_get(&b, "d")) && x->type == LF_ATTR_DOUBLE && x->d == 1e-300);
    CHECK((x = lf_attrs_get(&b, "v")) && x->type == LF_ATTR_FLOATS && x->n == 3 && !memcmp(x->v, v, sizeof v));
    CHECK((x = lf_attrs_get(&b, "m")) && x->type == LF_ATTR_M44D && !memcmp(x->m, m, sizeof m));
    /* a copy is independent of its source */
    lf_attrs_free(&a);
    CHECK((x = lf_attrs_get(&b, "s")) && !strcmp(x->s, "text"));
    lf_attrs_free(&b);

    /* 65504 is the largest finite IEEE half: (2 - 2^-10) * 2^15 */
    float px[4] = {0, -65504, (float)((2 - ldexp(1, -10)) * ldexp(1, 15)), 1};
    lf_image img = {2, 2, 1, px};
    CHECK(lf_image_fits_half(&img));
    px[3] = 65520; /* rounds to Inf as a half */
    CHECK(!lf_image_fits_half(&img));
    px[3] = -1e6f;
    CHECK(!lf_image_fits_half(&img));
    px[3] = NAN;
    CHECK(!lf_image_fits_half(&img));

    lf_write_opts wo = lf_write_opts_picture(-1.5, "aces");
    CHECK(wo.exposure == -1.5f && wo.tonemap == LF_TONEMAP_ACES && !wo.half && !wo.allow_nonfinite);
    wo = lf_write_opts_picture(0, NULL);
    CHECK(wo.tonemap == LF_TONEMAP_CLAMP && wo.exposure == 0);
    return lf_test_end();
}
