/* Microlens-grid estimation from a white plenoptic image. */
#include "lf_lightfield.h"

int lf_lf_calibrate(const lf_image *white, lf_lf_layout *lay, lf_error *err)
{
    (void)white;
    (void)lay;
    return lf_error_set(err, LF_ERR_UNSUPPORTED, "calibrate is not implemented yet");
}
