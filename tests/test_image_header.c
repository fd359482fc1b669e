/* test_image_header.c - image/lf_image.h compiles alone as strict C11 and
 * its types are usable without any other include. */
#include "image/lf_image.h"

#if !defined(__STDC_VERSION__) || __STDC_VERSION__ < 201112L
#error "this test must be compiled as C11"
#endif

int main(void)
{
    lf_image img = {0};
    lf_attrs attrs = {0};
    lf_write_opts opts = {0};
    int ok = sizeof img > 0 && sizeof attrs > 0 && sizeof opts > 0 && sizeof(lf_attr) > 0 && img.data == NULL &&
             attrs.count == 0 && LF_ATTR_M44D != LF_ATTR_STRING;
    return ok ? 0 : 1;
}
