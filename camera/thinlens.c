/* The physical thin-lens camera "thinlens": photographer's parameters
 * (focal length, f-number, focus distance, sensor size) and pixel values
 * that are exposure, not radiance.  docs/thinlens.md is the user's page.
 *
 * Geometry (camera space, metres; course notes "Ray Tracing for Defocus Blur
 * (Thin Lens)"; docs/physics.md "Two thin-lens cameras"):
 *   - the thin lens is the plane z = 0, centred on the origin, looking +z;
 *   - the sensor is the plane z = -z_s behind it, z_s the image distance of
 *     the focus plane z = z_o: 1/f = 1/z_s + 1/z_o, so z_s = f z_o/(z_o - f)
 *     (focusing moves the sensor: magnification m = z_s/z_o and the field of
 *     view 2 atan(w / 2 z_s) change with focus, as on a real lens);
 *   - raster (x, y) -> upright sensor coordinates (sx, sy) in metres,
 *       sx = (x/W - 1/2) w,   sy = (1/2 - y/H) h,   h = w H/W (square pixels),
 *     and the physical film point is p_s = (-sx, -sy, -z_s): the lens images
 *     the scene upside down and reversed, so reading the sensor through the
 *     point reflection gives pbrt's orientation (raster x right = camera +x,
 *     raster y down = camera -y);
 *   - the chief ray from p_s through the lens centre is undeviated and meets
 *     the focus plane at the conjugate point
 *       P = -p_s z_o/z_s = (sx/m, sy/m, z_o);
 *     every ray from p_s through any lens point p_l passes through P (the
 *     lens images p_s to P), so the ray leaves p_l towards P.
 *
 * Radiometry (docs/physics.md "Exposure and radiometry"): the irradiance at p_s is
 *   E = (1/z_s^2) \int_aperture L cos^4(theta) dA,
 * theta the angle between p_l - p_s and the axis.  With p_l uniform over the
 * open aperture of area A_ap = R^2 lf_aperture_area() (R = f/2N), the
 * estimator is L times weight = A_ap cos^4(theta)/z_s^2 (times the aperture
 * sample's weight).  The host multiplies by the imaging ratio (shutter time
 * x ISO/100), so a pixel is the exposure H = E t ISO/100 (W/m^2 s): about
 * pi/(4 N^2) times the scene radiance on axis (the camera equation), with
 * the natural cos^4 falloff off axis.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_keys.h"
#include "aperture.h"
#include "camera_internal.h"


typedef struct thinlens {
    double focal_length;      /* f, metres */
    double fstop;             /* N */
    double aperture_radius;   /* R = f / 2N, metres */
    double focus_distance;    /* z_o, metres from the lens */
    double sensor_distance;   /* z_s, metres behind the lens */
    double sensor_w, sensor_h;            /* metres, as imaged (h = w H/W) */
    double nominal_w_mm, nominal_h_mm;    /* the named or given sensor */
    char sensor_name[32];
    double coc_mm;            /* circle of confusion for depth of field */
    double open_area;         /* A_ap, m^2 */
    double weight_scale;      /* A_ap / z_s^2 */
    double inv_m;             /* z_o / z_s */
    int width, height;
    lf_aperture aperture;
} thinlens;

static int fail(const lf_camera_create_args *a, thinlens *c, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static int fail(const lf_camera_create_args *a, thinlens *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(a->error, a->error_size, fmt, ap);
    va_end(ap);
    if (c) {
        lf_aperture_free(&c->aperture);
        free(c);
    }
    return -1;
}

static int thinlens_create(const lf_camera_create_args *a, void **state)
{
    const lf_camera_params *p = a->params;
    thinlens *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    c->width = a->image_width;
    c->height = a->image_height;
    double f_mm = p->get_float(p->ctx, "focallength", 50.0);
    c->fstop = p->get_float(p->ctx, "fstop", 2.8);
    c->focus_distance = p->get_float(p->ctx, "focusdistance", 10.0);
    if (!(f_mm > 0.0) || !isfinite(f_mm))
        return fail(a, c, "\"focallength\" must be > 0 mm, got %g", f_mm);
    if (!(c->fstop > 0.0) || !isfinite(c->fstop))
        return fail(a, c, "\"fstop\" must be > 0, got %g", c->fstop);
    c->focal_length = f_mm * 1e-3;
    if (!isfinite(c->focus_distance))
        return fail(a, c, "\"focusdistance\" must be finite (use e.g. 1e6 m for infinity)");
    if (!(c->focus_distance > c->focal_length))
        return fail(a, c,
                    "\"focusdistance\" %g m is closer than the focal length (%g mm): a thin lens cannot focus there "
                    "(1/f = 1/z_i + 1/z_o has no real image); it must exceed %g m",
                    c->focus_distance, f_mm, c->focal_length);

    /* sensor: "float sensorsize" [w h] mm wins over "string sensor" */
    lf_error err = {0};
    if (lf_cam_read_sensor(p, &c->nominal_w_mm, &c->nominal_h_mm, c->sensor_name, sizeof c->sensor_name, &err))
        return fail(a, c, "%s", err.msg);
    /* the width maps to the image width; square pixels fix the height */
    c->sensor_w = c->nominal_w_mm * 1e-3;
    c->sensor_h = c->sensor_w * c->height / c->width;
    if (fabs(c->sensor_h * 1e3 - c->nominal_h_mm) > 0.01 * c->nominal_h_mm && a->warning && a->warning_size)
        snprintf(a->warning, a->warning_size,
                 "the image is %dx%d, so the %s sensor (%g x %g mm) is used as %g x %.4g mm (its width maps to the "
                 "image width, pixels are square)",
                 c->width, c->height, c->sensor_name, c->nominal_w_mm, c->nominal_h_mm, c->nominal_w_mm,
                 c->sensor_h * 1e3);

    double diag_mm = hypot(c->nominal_w_mm, c->nominal_h_mm);
    c->coc_mm = p->get_float(p->ctx, "coc", diag_mm / 1500.0);
    if (!(c->coc_mm > 0.0) || !isfinite(c->coc_mm))
        return fail(a, c, "\"coc\" (circle of confusion, mm) must be > 0, got %g", c->coc_mm);

    if (lf_aperture_parse(p, &c->aperture, &err))
        return fail(a, c, "%s", err.msg);

    /* thin lens equation, written to stay accurate when z_o >> f */
    double f = c->focal_length, zo = c->focus_distance;
    c->sensor_distance = f / (1.0 - f / zo);
    c->inv_m = zo / c->sensor_distance;
    c->aperture_radius = f / (2.0 * c->fstop);
    c->open_area = c->aperture_radius * c->aperture_radius * lf_aperture_area(&c->aperture);
    c->weight_scale = c->open_area / (c->sensor_distance * c->sensor_distance);
    if (!isfinite(c->sensor_distance) || !isfinite(c->inv_m) || !(c->weight_scale > 0) || !isfinite(c->weight_scale))
        return fail(a, c, "focus distance %g m gives no finite sensor position", zo);
    *state = c;
    return 0;
}

static uint32_t thinlens_needs(const void *state)
{
    const thinlens *c = state;
    return c->aperture_radius > 0.0 ? LF_CAMERA_NEEDS_LENS : 0u;
}

/* One ray from its film point (fx, fy) and its aperture point (ax, ay) in
 * radius units with the aperture weight aw.  Shared by the single-ray and
 * the batch paths: with ISO C's default -ffp-contract=off the vectorised
 * loop performs the same correctly rounded operations, so both paths agree
 * to the bit. */
static inline double thinlens_ray(const thinlens *c, double fx, double fy, double apx, double apy, double aw,
                                  double *o, double *d)
{
    /* upright sensor coordinates, metres */
    double sx = (fx / c->width - 0.5) * c->sensor_w;
    double sy = (0.5 - fy / c->height) * c->sensor_h;
    double X = apx * c->aperture_radius, Y = apy * c->aperture_radius;
    /* towards the conjugate point P = (sx/m, sy/m, z_o) on the focus plane */
    double ex = sx * c->inv_m - X, ey = sy * c->inv_m - Y, zo = c->focus_distance;
    double len2 = ex * ex + ey * ey + zo * zo;
    double il = 1.0 / sqrt(len2);
    /* cos(theta) of the ray p_s -> p_l, with p_s = (-sx, -sy, -z_s) */
    double ax = X + sx, ay = Y + sy, zs2 = c->sensor_distance * c->sensor_distance;
    double cos2 = zs2 / (ax * ax + ay * ay + zs2);
    double w = c->weight_scale * cos2 * cos2 * aw;
    int ok = aw > 0.0 && len2 > 0.0 && len2 <= 1.79e308 && il <= 1.79e308 && w <= 1.79e308;
    o[0] = X, o[1] = Y;
    d[0] = ok ? ex * il : 0.0, d[1] = ok ? ey * il : 0.0, d[2] = ok ? zo * il : 1.0;
    return ok ? w : 0.0;
}

/* Up to LF_CAM_CHUNK rays, each step a loop over the whole padded chunk
 * (structure of arrays), so the compiler vectorises it and the square roots
 * and divisions of different rays overlap. */
LF_CAM_SIMD_CLONES
static void thinlens_chunk(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r, double *wt)
{
    const thinlens *c = state;
    enum { N = LF_CAM_CHUNK };
    double fx[N], fy[N], lu[N], lv[N], lx[N], ly[N], aw[N];
    double ox[N], oy[N], dx[N], dy[N], dz[N], w[N];
    lf_cam_stage_samples(n, s, fx, fy, lu, lv);
    lf_aperture_sample_chunk(&c->aperture, n, N, lu, lv, lx, ly, aw);
    for (int i = 0; i < N; i++) {
        double o[2], d[3];
        w[i] = thinlens_ray(c, fx[i], fy[i], lx[i], ly[i], aw[i], o, d);
        ox[i] = o[0], oy[i] = o[1], dx[i] = d[0], dy[i] = d[1], dz[i] = d[2];
    }
    for (int i = 0; i < n; i++) {
        r[i].origin[0] = ox[i], r[i].origin[1] = oy[i], r[i].origin[2] = 0.0;
        r[i].dir[0] = dx[i], r[i].dir[1] = dy[i], r[i].dir[2] = dz[i];
        wt[i] = w[i];
    }
}

static void thinlens_generate_rays(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r,
                                   double *w)
{
    lf_cam_chunks(thinlens_chunk, state, n, s, r, w);
}

static double thinlens_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const thinlens *c = state;
    double lx, ly, o[2];
    double aw = lf_aperture_sample(&c->aperture, s->lens_u, s->lens_v, &lx, &ly);
    double w = thinlens_ray(c, s->film_x, s->film_y, lx, ly, aw, o, r->dir);
    r->origin[0] = o[0], r->origin[1] = o[1], r->origin[2] = 0.0;
    return w;
}

static void thinlens_destroy(void *state)
{
    thinlens *c = state;
    if (c)
        lf_aperture_free(&c->aperture);
    free(c);
}

static int thinlens_describe(const void *state, char *buf, size_t size)
{
    const thinlens *c = state;
    int n = 0;
    char scratch[1];
    if (size == 0) /* measuring only */
        buf = scratch, size = 1;
    double f = c->focal_length, N = c->fstop, s = c->focus_distance, zs = c->sensor_distance;
    double A = f / N;
    double m = zs / s;
    double pitch = c->sensor_w / c->width;
    double coc = c->coc_mm * 1e-3;
    double H = f * f / (N * coc) + f;
    double near = s * (H - f) / (H + s - 2.0 * f);
    LF_CAM_APPEND("model: physical thin lens (lens at the origin, sensor at z = -z_s; pixel values are exposure)\n");
    LF_CAM_APPEND("focal length f: %g mm\n", f * 1e3);
    LF_CAM_APPEND("f-number N: %g\n", N);
    LF_CAM_APPEND("aperture diameter A = f/N: %.6g mm\n", A * 1e3);
    LF_CAM_APPEND("aperture: %s, %d blades, rotation %g deg, anamorphic %g, open area %.6g mm^2\n",
           lf_aperture_name(&c->aperture), c->aperture.kind == LF_APERTURE_CIRCLE ? 0 : c->aperture.blades,
           c->aperture.rotation_rad * 180.0 / M_PI, c->aperture.anamorphic, c->open_area * 1e6);
    LF_CAM_APPEND("focus distance z_o: %.9g m\n", s);
    LF_CAM_APPEND("sensor distance z_s (= z_i of the focus plane): %.9g mm\n", zs * 1e3);
    LF_CAM_APPEND("magnification m = z_s/z_o: %.6g\n", m);
    LF_CAM_APPEND("sensor: %s %g x %g mm, imaged as %g x %.6g mm, pixel pitch %.6g um, crop factor %.4g\n", c->sensor_name,
           c->nominal_w_mm, c->nominal_h_mm, c->sensor_w * 1e3, c->sensor_h * 1e3, pitch * 1e6,
           43.27 / hypot(c->nominal_w_mm, c->nominal_h_mm));
    LF_CAM_APPEND("horizontal FOV: %.6g deg\n", 2.0 * atan(c->sensor_w / (2.0 * zs)) * 180.0 / M_PI);
    LF_CAM_APPEND("vertical FOV: %.6g deg\n", 2.0 * atan(c->sensor_h / (2.0 * zs)) * 180.0 / M_PI);
    LF_CAM_APPEND("diagonal FOV: %.6g deg\n", 2.0 * atan(hypot(c->sensor_w, c->sensor_h) / (2.0 * zs)) * 180.0 / M_PI);
    LF_CAM_APPEND("circle of confusion c: %.6g mm\n", c->coc_mm);
    LF_CAM_APPEND("hyperfocal distance H = f^2/(N c) + f: %.6g m\n", H);
    LF_CAM_APPEND("near limit of acceptable sharpness: %.6g m\n", near);
    if (s >= H)
        LF_CAM_APPEND("far limit of acceptable sharpness: infinity\n");
    else
        LF_CAM_APPEND("far limit of acceptable sharpness: %.6g m\n", s * (H - f) / (H - s));
    /* C = A z_s |1/d - 1/z| (docs/physics.md), in pixels of the sensor pitch */
    static const double factors[] = {0.5, 0.8, 2.0, 10.0};
    for (int i = 0; i < 4; i++) {
        double z = factors[i] * s;
        double C = A * zs * fabs(1.0 / s - 1.0 / z);
        LF_CAM_APPEND("blur diameter at %.6g m (%gx focus): %.6g px (%.6g mm)%s\n", z, factors[i], C / pitch, C * 1e3,
               z <= f ? " [closer than f: no real image]" : "");
    }
    double Cinf = A * zs / s;
    LF_CAM_APPEND("blur diameter at infinity: %.6g px (%.6g mm)\n", Cinf / pitch, Cinf * 1e3);
    LF_CAM_APPEND("exposure: pixel = (1/z_s^2) int L cos^4 dA x shutter x ISO/100; on axis ~ pi/(4 N^2) L = %.6g L per "
           "imaging ratio\n",
           M_PI / (4.0 * N * N));
    return n;
}

/* EXR header facts: enough to reproduce the optics of the image. */
static void thinlens_metadata(const void *state, const lf_camera_attr_sink *sink)
{
    const thinlens *c = state;
    sink->set_double(sink->ctx, LF_KEY_FOCAL_LENGTH_MM, c->focal_length * 1e3);
    sink->set_double(sink->ctx, LF_KEY_FSTOP, c->fstop);
    sink->set_double(sink->ctx, LF_KEY_FOCUS_DISTANCE_M, c->focus_distance);
    sink->set_double(sink->ctx, LF_KEY_SENSOR_DISTANCE_MM, c->sensor_distance * 1e3);
    double wh[2] = {c->sensor_w * 1e3, c->sensor_h * 1e3};
    sink->set_doubles(sink->ctx, LF_KEY_SENSOR_SIZE_MM, wh, 2);
    sink->set_string(sink->ctx, LF_KEY_APERTURE, lf_aperture_name(&c->aperture));
}

const lf_camera_type lf_camera_thinlens = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "thinlens",
    .create = thinlens_create,
    .needs = thinlens_needs,
    .generate_ray = thinlens_generate_ray,
    .destroy = thinlens_destroy,
    .describe = thinlens_describe,
    .metadata = thinlens_metadata,
    .generate_rays = thinlens_generate_rays,
};
