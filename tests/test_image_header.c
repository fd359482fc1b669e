/* test_image_header.c - image/lf_image.h compiles alone as strict C11 and
 * its types are usable without any other include. */
#include "image/lf_image.h"
#include "lf_test.h"

#if !defined(__STDC_VERSION__) || __STDC_VERSION__ < 201112L
#error "this test must be compiled as C11"
#endif

int main(void)
{
    lf_image img = {0};
    lf_attrs attrs = {0};
    lf_write_opts opts = {0};
    CHECK(sizeof img > 0 && sizeof attrs > 0 && sizeof opts > 0 && sizeof(lf_attr) > 0);
    CHECK(img.data == NULL);
    CHECK(attrs.count == 0);
    CHECK(LF_ATTR_M44D != LF_ATTR_STRING);
    return lf_test_end();
}
