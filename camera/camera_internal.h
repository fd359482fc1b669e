/* Private helpers shared by the built-in cameras. */
#ifndef LF_CAMERA_INTERNAL_H
#define LF_CAMERA_INTERNAL_H

#include <math.h>

#include "lf_camera.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Shirley-Chiu concentric mapping of [0,1)^2 onto the unit disk: area
 * preserving, so a uniform sample stays uniform and strata stay compact. */
static inline void lf_cam_concentric_disk(double u, double v, double *x, double *y)
{
    double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    double r, th;
    if (fabs(a) > fabs(b)) {
        r = a;
        th = (M_PI / 4.0) * (b / a);
    } else {
        r = b;
        th = M_PI / 2.0 - (M_PI / 4.0) * (a / b);
    }
    *x = r * cos(th);
    *y = r * sin(th);
}

/* "string sensor" (named format) or "float sensorsize" [w h] mm; default
 * full frame.  Returns 0, or -1 with a message in err. (camera/sensor.c) */
int lf_cam_read_sensor(const lf_camera_params *p, double *w_mm, double *h_mm, char *name, size_t name_size,
                       char *err, size_t err_size);

/* For describe(): appends to buf (size bytes) with snprintf semantics; the
 * caller's int n stays the would-be length. */
#define LF_CAM_APPEND(...)                                           \
    do {                                                             \
        size_t off_ = (size_t)n < size ? (size_t)n : size;           \
        int k_ = snprintf(buf + off_, size - off_, __VA_ARGS__);     \
        if (k_ > 0)                                                  \
            n += k_;                                                 \
    } while (0)

extern const lf_camera_type lf_camera_perspective;
extern const lf_camera_type lf_camera_orthographic;
extern const lf_camera_type lf_camera_thinlens;
extern const lf_camera_type lf_camera_realistic;
extern const lf_camera_type lf_camera_lightfield;
extern const lf_camera_type lf_camera_plenoptic;

#endif
