/* The sensor parameters shared by the physical cameras (thinlens,
 * plenoptic): "string sensor" (a named format, table in lens.c) or
 * "float sensorsize" [w h] in mm. */
#include <math.h>
#include <stdio.h>

#include "camera_internal.h"
#include "lens.h"

int lf_cam_read_sensor(const lf_camera_params *p, double *w_mm, double *h_mm, char *name, size_t name_size,
                       lf_error *err)
{
    double wh[2] = {0, 0};
    int nsz = p->get_floats(p->ctx, "sensorsize", wh, 2);
    const char *given = p->get_string(p->ctx, "sensor", NULL);
    if (nsz != 0 && given)
        return lf_error_set(err, LF_ERR_PARAM, "give either \"sensor\" \"%s\" or \"sensorsize\", not both", given);
    if (nsz != 0) {
        if (nsz != 2 || !(wh[0] > 0.0) || !(wh[1] > 0.0) || !isfinite(wh[0]) || !isfinite(wh[1]))
            return lf_error_set(err, LF_ERR_PARAM,
                                "\"sensorsize\" needs two positive values [width height] in mm (got %d values)", nsz);
        *w_mm = wh[0], *h_mm = wh[1];
        snprintf(name, name_size, "custom");
        return 0;
    }
    const char *n = given ? given : "fullframe";
    if (lf_lens_sensor_size(n, w_mm, h_mm))
        return lf_error_set(err, LF_ERR_PARAM,
                            "unknown \"sensor\" \"%s\" (known: %s; or give \"float sensorsize\" [w h] mm)", n,
                            lf_lens_sensor_names());
    snprintf(name, name_size, "%s", n);
    return 0;
}
