/* "fisheye": an ideal fisheye camera (no lens elements, no vignetting), the
 * like of Blender Cycles' fisheye cameras, beside the traced fisheye
 * prescriptions of the "realistic" camera.
 *
 * A film point at distance r (mm) from the film centre, at azimuth phi,
 * sees the direction at angle theta from the optical axis (+z) and the same
 * azimuth, where r = f g(theta) for the mapping ("string mapping"):
 *   equidistant    r = f theta
 *   equisolid      r = 2 f sin(theta/2)    (equal-area)
 *   orthographic   r = f sin(theta)
 *   stereographic  r = 2 f tan(theta/2)    (conformal)
 * The film is Film "diagonal" mm across (pbrt's physical film, as for the
 * realistic camera), centred on the axis; raster (0,0) is its top-left
 * corner, film x grows right and y up, as for the projective cameras.
 * Rays with theta > fov/2 do not exist (weight 0: the black outside the
 * image circle).  "float focallength" (mm) gives f; without it, f is the
 * one that makes the image circle (theta = fov/2) touch the film's shorter
 * sides: a circular fisheye.  The weight inside the circle is 1 (pixel
 * values are radiance, pbrt's convention for ideal cameras).
 *
 * No trigonometric call per ray: for each mapping sin(theta)/r and
 * cos(theta) follow from r/f algebraically (half-angle identities), and
 * the equidistant mapping evaluates sin and cos of theta/4 by series and
 * doubles twice, so the batch kernel vectorises like the others. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_keys.h"
#include "camera_internal.h"

typedef enum fisheye_mapping { FE_EQUIDISTANT, FE_EQUISOLID, FE_ORTHOGRAPHIC, FE_STEREOGRAPHIC } fisheye_mapping;

static const char *const mapping_names[] = {"equidistant", "equisolid", "orthographic", "stereographic"};

typedef struct fisheye {
    fisheye_mapping mapping;
    double f_mm;              /* focal length */
    double fov_deg;           /* full angle of the image circle */
    double film_w_mm, film_h_mm, diagonal_mm;
    double mm_per_px_x, mm_per_px_y;
    double r_max_mm;          /* image circle radius on the film, f g(fov/2) */
    double inv_f;
    int width, height;
    int focal_given;
} fisheye;

/* r = f g(theta) / f, for theta in the mapping's domain. */
static double mapping_g(fisheye_mapping m, double theta)
{
    switch (m) {
    case FE_EQUISOLID: return 2.0 * sin(0.5 * theta);
    case FE_ORTHOGRAPHIC: return sin(theta);
    case FE_STEREOGRAPHIC: return 2.0 * tan(0.5 * theta);
    case FE_EQUIDISTANT:
    default: return theta;
    }
}

/* The largest field (degrees) a mapping can image: orthographic stops at 90
 * deg off axis, stereographic goes to infinity at 180, the others reach 180
 * (the whole sphere). */
static double mapping_max_fov(fisheye_mapping m)
{
    return m == FE_ORTHOGRAPHIC ? 180.0 : 360.0;
}

static int fisheye_create(const lf_camera_create_args *a, void **state)
{
    const lf_camera_params *p = a->params;
    const char *ms = p->get_string(p->ctx, "mapping", "equidistant");
    int mi = -1;
    for (int i = 0; i < 4; i++)
        if (!strcmp(ms, mapping_names[i]))
            mi = i;
    if (mi < 0) {
        snprintf(a->error, a->error_size,
                 "unknown fisheye \"mapping\" \"%s\" (known: equidistant, equisolid, orthographic, stereographic)", ms);
        return -1;
    }
    fisheye_mapping m = (fisheye_mapping)mi;
    double maxfov = mapping_max_fov(m);
    double fov = p->get_float(p->ctx, "fov", 180.0);
    int fov_ok = m == FE_STEREOGRAPHIC ? (fov > 0.0 && fov < maxfov) : (fov > 0.0 && fov <= maxfov);
    if (!fov_ok || !isfinite(fov)) {
        snprintf(a->error, a->error_size, "fisheye \"fov\" must be in (0, %g%s degrees for the %s mapping, got %g",
                 maxfov, m == FE_STEREOGRAPHIC ? ")" : "]", mapping_names[m], fov);
        return -1;
    }
    if (!(a->film_diagonal_mm > 0.0) || !isfinite(a->film_diagonal_mm) || a->image_width <= 0 ||
        a->image_height <= 0) {
        snprintf(a->error, a->error_size, "film diagonal (%g mm) and resolution must be positive", a->film_diagonal_mm);
        return -1;
    }
    double fl = p->get_float(p->ctx, "focallength", 0.0);
    if (!(fl >= 0.0) || !isfinite(fl)) {
        snprintf(a->error, a->error_size, "fisheye \"focallength\" must be > 0 mm, got %g", fl);
        return -1;
    }
    fisheye *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    c->mapping = m;
    c->fov_deg = fov;
    c->width = a->image_width, c->height = a->image_height;
    double aspect = (double)a->image_width / a->image_height;
    c->diagonal_mm = a->film_diagonal_mm;
    c->film_w_mm = sqrt(c->diagonal_mm * c->diagonal_mm / (1.0 + 1.0 / (aspect * aspect)));
    c->film_h_mm = c->film_w_mm / aspect;
    double half_theta = 0.5 * fov * M_PI / 180.0;
    double g_max = mapping_g(m, half_theta);
    c->focal_given = fl > 0.0;
    if (c->focal_given)
        c->f_mm = fl;
    else /* circular fisheye: the circle touches the shorter sides */
        c->f_mm = 0.5 * fmin(c->film_w_mm, c->film_h_mm) / g_max;
    c->inv_f = 1.0 / c->f_mm;
    c->r_max_mm = c->f_mm * g_max;
    c->mm_per_px_x = c->film_w_mm / c->width;
    c->mm_per_px_y = c->film_h_mm / c->height;
    *state = c;
    return 0;
}

static uint32_t fisheye_needs(const void *state)
{
    (void)state;
    return 0u;
}

/* One ray: film point (x, y) mm (y up) -> unit direction d; returns the
 * weight (1 inside the image circle, 0 outside).  Branch-free within a
 * mapping, shared by the single-ray and batch paths so they agree to the
 * bit. */
static inline double fisheye_dir(const fisheye *c, fisheye_mapping m, double x, double y, double *d)
{
    double r2 = x * x + y * y;
    double q = sqrt(r2) * c->inv_f; /* r / f */
    double q2 = q * q;
    double s_over_r, ct; /* sin(theta) / r and cos(theta) */
    switch (m) {
    case FE_EQUISOLID: {
        /* s = sin(theta/2) = q/2: sin(theta) = 2 s sqrt(1 - s^2), cos = 1 - 2 s^2 */
        double s2 = 0.25 * q2;
        s_over_r = sqrt(fmax(0.0, 1.0 - s2)) * c->inv_f;
        ct = 1.0 - 2.0 * s2;
        break;
    }
    case FE_ORTHOGRAPHIC:
        s_over_r = c->inv_f;
        ct = sqrt(fmax(0.0, 1.0 - q2));
        break;
    case FE_STEREOGRAPHIC: {
        /* t = tan(theta/2) = q/2: sin = 2t / (1 + t^2), cos = (1 - t^2) / (1 + t^2) */
        double t2 = 0.25 * q2, inv = 1.0 / (1.0 + t2);
        s_over_r = inv * c->inv_f;
        ct = (1.0 - t2) * inv;
        break;
    }
    case FE_EQUIDISTANT:
    default: {
        /* theta = q; sin and cos of theta/4 (<= pi/4) by series, doubled twice */
        double sq, cq;
        lf_sincos_quarter(0.25 * q, &sq, &cq);
        double s1 = 2.0 * sq * cq, c1 = 1.0 - 2.0 * sq * sq; /* theta/2 */
        double st = 2.0 * s1 * c1;
        ct = 1.0 - 2.0 * s1 * s1;
        /* sin(theta)/r = (sin(theta)/theta) / f; at the centre the limit 1/f */
        s_over_r = q > 0.0 ? st / (q > 0.0 ? q : 1.0) * c->inv_f : c->inv_f;
        break;
    }
    }
    int inside = r2 <= c->r_max_mm * c->r_max_mm;
    d[0] = inside ? x * s_over_r : 0.0;
    d[1] = inside ? y * s_over_r : 0.0;
    d[2] = inside ? ct : 1.0;
    return inside ? 1.0 : 0.0;
}

static inline void film_mm(const fisheye *c, double fx, double fy, double *x, double *y)
{
    *x = (fx - 0.5 * c->width) * c->mm_per_px_x;
    *y = (0.5 * c->height - fy) * c->mm_per_px_y;
}

static double fisheye_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const fisheye *c = state;
    double x, y;
    film_mm(c, s->film_x, s->film_y, &x, &y);
    r->origin[0] = r->origin[1] = r->origin[2] = 0.0;
    return fisheye_dir(c, c->mapping, x, y, r->dir);
}

/* Up to LF_CAM_CHUNK rays as structure of arrays; the mapping is a constant
 * within each loop so the compiler vectorises it. */
LF_CAM_SIMD_CLONES
static void fisheye_chunk(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r, double *wt)
{
    const fisheye *c = state;
    enum { N = LF_CAM_CHUNK };
    double fx[N], fy[N], lu[N], lv[N], w[N], d[3][N];
    lf_cam_stage_samples(n, s, fx, fy, lu, lv);
#define FE_LOOP(M)                                           \
    for (int i = 0; i < N; i++) {                            \
        double x, y, di[3];                                  \
        film_mm(c, fx[i], fy[i], &x, &y);                    \
        w[i] = fisheye_dir(c, M, x, y, di);                  \
        d[0][i] = di[0], d[1][i] = di[1], d[2][i] = di[2];   \
    }
    switch (c->mapping) {
    case FE_EQUISOLID: FE_LOOP(FE_EQUISOLID) break;
    case FE_ORTHOGRAPHIC: FE_LOOP(FE_ORTHOGRAPHIC) break;
    case FE_STEREOGRAPHIC: FE_LOOP(FE_STEREOGRAPHIC) break;
    default: FE_LOOP(FE_EQUIDISTANT) break;
    }
#undef FE_LOOP
    for (int i = 0; i < n; i++) {
        r[i].origin[0] = r[i].origin[1] = r[i].origin[2] = 0.0;
        r[i].dir[0] = d[0][i], r[i].dir[1] = d[1][i], r[i].dir[2] = d[2][i];
        wt[i] = w[i];
    }
}

static void fisheye_generate_rays(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r, double *w)
{
    lf_cam_chunks(fisheye_chunk, state, n, s, r, w);
}

static void fisheye_destroy(void *state)
{
    free(state);
}

static int fisheye_describe(const void *state, char *buf, size_t size)
{
    const fisheye *c = state;
    int n = 0;
    LF_CAM_APPEND("model: ideal fisheye, %s mapping (r = %s), no lens elements, no vignetting\n",
                  mapping_names[c->mapping],
                  (const char *[]){"f theta", "2 f sin(theta/2)", "f sin(theta)", "2 f tan(theta/2)"}[c->mapping]);
    LF_CAM_APPEND("focal length: %.6g mm (%s)\n", c->f_mm,
                  c->focal_given ? "\"focallength\"" : "circle fitted to the film's shorter side");
    LF_CAM_APPEND("film: %.4g x %.4g mm (diagonal %.4g mm)\n", c->film_w_mm, c->film_h_mm, c->diagonal_mm);
    LF_CAM_APPEND("image circle: field %g deg, radius %.6g mm = %.6g px; no rays outside it\n", c->fov_deg,
                  c->r_max_mm, c->r_max_mm / c->mm_per_px_x);
    return n;
}

static void fisheye_metadata(const void *state, const lf_camera_attr_sink *sink)
{
    const fisheye *c = state;
    sink->set_string(sink->ctx, LF_KEY_FISHEYE_MAPPING, mapping_names[c->mapping]);
    sink->set_double(sink->ctx, LF_KEY_FISHEYE_FOCAL_LENGTH_MM, c->f_mm);
    sink->set_double(sink->ctx, LF_KEY_FISHEYE_FOV_DEG, c->fov_deg);
    sink->set_double(sink->ctx, LF_KEY_FISHEYE_CIRCLE_RADIUS_MM, c->r_max_mm);
}

const lf_camera_type lf_camera_fisheye = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "fisheye",
    .create = fisheye_create,
    .needs = fisheye_needs,
    .generate_ray = fisheye_generate_ray,
    .generate_rays = fisheye_generate_rays,
    .destroy = fisheye_destroy,
    .describe = fisheye_describe,
    .metadata = fisheye_metadata,
};
