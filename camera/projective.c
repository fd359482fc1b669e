/* pbrt-v4's projective cameras: "perspective" and "orthographic".
 *
 * Both map a raster position to the screen window (pbrt: [-aspect, aspect] x
 * [-1, 1] for wide images, [-1, 1] x [-1/aspect, 1/aspect] for tall ones, so
 * "fov" spans the SHORTER image axis), raster (0,0) at the top-left corner,
 * screen y up.  With a lens radius > 0 the ray starts on a disk of that
 * radius at the camera origin and is aimed at the point the pinhole ray hits
 * on the plane z = focaldistance (pbrt-v4 PerspectiveCamera::GenerateRay).
 *
 * Extension (pbrt-v4 has none): the lens may have a shaped aperture of
 * radius lensradius ("string aperture", "integer blades", "float
 * aperturerotation", "float anamorphic"; camera/aperture.h).  The default
 * circular aperture draws exactly pbrt's lens points, and the ray weight
 * stays 1 (pbrt's convention: pixel values are radiance, not exposure).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "aperture.h"
#include "camera_internal.h"

typedef struct projective {
    int orthographic;
    double screen[4];        /* x0 x1 y0 y1 */
    double tan_half_fov;     /* perspective: tan(fov/2) */
    double fov_deg;
    double lens_radius, focal_distance;
    int width, height;
    double sx, sy;           /* screen units per pixel */
    lf_aperture aperture;    /* shape of the lens, in units of lens_radius */
} projective;

static int projective_create(const lf_camera_create_args *a, void **state, int ortho)
{
    const lf_camera_params *p = a->params;
    projective *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    c->orthographic = ortho;
    c->width = a->image_width;
    c->height = a->image_height;
    double aspect = p->get_float(p->ctx, "frameaspectratio", (double)a->image_width / a->image_height);
    if (!(aspect >= 1e-15 && aspect <= 1e15)) { /* the screen spans 1/aspect: the same reach bound */
        snprintf(a->error, a->error_size, "\"frameaspectratio\" must be in 1e-15..1e15, got %g", aspect);
        free(c);
        return -1;
    }
    if (aspect > 1.0) {
        c->screen[0] = -aspect, c->screen[1] = aspect, c->screen[2] = -1.0, c->screen[3] = 1.0;
    } else {
        c->screen[0] = -1.0, c->screen[1] = 1.0, c->screen[2] = -1.0 / aspect, c->screen[3] = 1.0 / aspect;
    }
    double sw[4];
    int n = p->get_floats(p->ctx, "screenwindow", sw, 4);
    if (n == 4) {
        /* beyond 1e15 the rays' extent overflows (the renderer's reach
         * bound, docs/testing.md); an empty window maps every pixel to one point */
        for (int k = 0; k < 4; k++)
            if (!(fabs(sw[k]) <= 1e15)) {
                snprintf(a->error, a->error_size, "\"screenwindow\" values must be within +-1e15, got %g", sw[k]);
                free(c);
                return -1;
            }
        if (sw[0] == sw[1] || sw[2] == sw[3]) {
            snprintf(a->error, a->error_size, "\"screenwindow\" [%g %g %g %g] is empty", sw[0], sw[1], sw[2], sw[3]);
            free(c);
            return -1;
        }
        memcpy(c->screen, sw, sizeof sw);
    } else if (n != 0) {
        snprintf(a->error, a->error_size, "\"screenwindow\" needs 4 values (x0 x1 y0 y1), got %d", n);
        free(c);
        return -1;
    }
    if (!ortho) {
        c->fov_deg = p->get_float(p->ctx, "fov", 90.0);
        if (!(c->fov_deg > 0.0 && c->fov_deg < 180.0)) {
            snprintf(a->error, a->error_size, "\"fov\" must be in (0, 180) degrees, got %g", c->fov_deg);
            free(c);
            return -1;
        }
        c->tan_half_fov = tan(c->fov_deg * 0.5 * M_PI / 180.0);
    }
    c->lens_radius = p->get_float(p->ctx, "lensradius", 0.0);
    c->focal_distance = p->get_float(p->ctx, "focaldistance", 1e6);
    if (!(c->lens_radius >= 0.0 && c->lens_radius <= 1e15)) { /* the renderer's reach, docs/testing.md */
        snprintf(a->error, a->error_size, "\"lensradius\" must be in 0..1e15, got %g", c->lens_radius);
        free(c);
        return -1;
    }
    if (!(c->focal_distance > 0.0 && c->focal_distance <= 1e15)) {
        snprintf(a->error, a->error_size, "\"focaldistance\" must be in (0, 1e15], got %g", c->focal_distance);
        free(c);
        return -1;
    }
    lf_error err = {0};
    if (lf_cam_error(lf_aperture_parse(p, &c->aperture, &err), &err, a->error, a->error_size)) {
        free(c);
        return -1;
    }
    c->sx = (c->screen[1] - c->screen[0]) / c->width;
    c->sy = (c->screen[3] - c->screen[2]) / c->height;
    *state = c;
    return 0;
}

static int perspective_create(const lf_camera_create_args *a, void **state)
{
    return projective_create(a, state, 0);
}

static int orthographic_create(const lf_camera_create_args *a, void **state)
{
    return projective_create(a, state, 1);
}

static uint32_t projective_needs(const void *state)
{
    const projective *c = state;
    return c->lens_radius > 0.0 ? LF_CAMERA_NEEDS_LENS : 0u;
}

/* The steps of one ray, shared by the single-ray and the batch paths so
 * that both agree to the bit (ISO C: no contraction into FMA).  Branch-free
 * within a camera mode, so loops over them vectorise. */
static inline void pinhole_dir(const projective *c, double fx, double fy, double *d)
{
    /* raster -> screen: x grows right, y grows up from the bottom edge. */
    double x = (c->screen[0] + fx * c->sx) * c->tan_half_fov;
    double y = (c->screen[3] - fy * c->sy) * c->tan_half_fov;
    double inv = 1.0 / sqrt(x * x + y * y + 1.0);
    d[0] = x * inv, d[1] = y * inv, d[2] = inv;
}
static inline void ortho_origin(const projective *c, double fx, double fy, double *o)
{
    o[0] = c->screen[0] + fx * c->sx;
    o[1] = c->screen[3] - fy * c->sy;
    o[2] = 0.0;
}
/* The lens: the ray leaves lens point (lx, ly) (lens-radius units, weight
 * aw) towards the point the pinhole ray (o, d) meets on the plane of focus. */
static inline double lens_ray(const projective *c, double lx, double ly, double aw, double *o, double *d)
{
    double ft = c->focal_distance / d[2];
    double f0 = o[0] + d[0] * ft, f1 = o[1] + d[1] * ft, f2 = o[2] + d[2] * ft;
    o[0] += lx * c->lens_radius, o[1] += ly * c->lens_radius;
    double e0 = f0 - o[0], e1 = f1 - o[1], e2 = f2 - o[2];
    double inv = 1.0 / sqrt(e0 * e0 + e1 * e1 + e2 * e2);
    int ok = aw > 0.0;
    d[0] = ok ? e0 * inv : 0.0, d[1] = ok ? e1 * inv : 0.0, d[2] = ok ? e2 * inv : 1.0;
    return ok ? 1.0 : 0.0;
}

/* Up to LF_CAM_CHUNK rays, each step a loop over the whole padded chunk
 * (structure of arrays) so that the compiler vectorises it. */
LF_CAM_SIMD_CLONES
static void projective_chunk(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r, double *wt)
{
    const projective *c = state;
    enum { N = LF_CAM_CHUNK };
    double fx[N], fy[N], lu[N], lv[N], lx[N], ly[N], aw[N], w[N], o[3][N], d[3][N];
    lf_cam_stage_samples(n, s, fx, fy, lu, lv);
    for (int i = 0; i < N; i++)
        w[i] = 1.0;
    if (c->orthographic) {
        for (int i = 0; i < N; i++) {
            double oi[3];
            ortho_origin(c, fx[i], fy[i], oi);
            o[0][i] = oi[0], o[1][i] = oi[1], o[2][i] = oi[2];
            d[0][i] = 0.0, d[1][i] = 0.0, d[2][i] = 1.0;
        }
    } else {
        for (int i = 0; i < N; i++) {
            double di[3];
            pinhole_dir(c, fx[i], fy[i], di);
            o[0][i] = o[1][i] = o[2][i] = 0.0;
            d[0][i] = di[0], d[1][i] = di[1], d[2][i] = di[2];
        }
    }
    if (c->lens_radius > 0.0) {
        lf_aperture_sample_chunk(&c->aperture, n, N, lu, lv, lx, ly, aw);
        for (int i = 0; i < N; i++) {
            double oi[3] = {o[0][i], o[1][i], o[2][i]}, di[3] = {d[0][i], d[1][i], d[2][i]};
            w[i] = lens_ray(c, lx[i], ly[i], aw[i], oi, di);
            o[0][i] = oi[0], o[1][i] = oi[1], o[2][i] = oi[2];
            d[0][i] = di[0], d[1][i] = di[1], d[2][i] = di[2];
        }
    }
    for (int i = 0; i < n; i++) {
        r[i].origin[0] = o[0][i], r[i].origin[1] = o[1][i], r[i].origin[2] = o[2][i];
        r[i].dir[0] = d[0][i], r[i].dir[1] = d[1][i], r[i].dir[2] = d[2][i];
        wt[i] = w[i];
    }
}

static void projective_generate_rays(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r,
                                     double *w)
{
    lf_cam_chunks(projective_chunk, state, n, s, r, w);
}

static double projective_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const projective *c = state;
    if (c->orthographic) {
        ortho_origin(c, s->film_x, s->film_y, r->origin);
        r->dir[0] = 0.0, r->dir[1] = 0.0, r->dir[2] = 1.0;
    } else {
        r->origin[0] = r->origin[1] = r->origin[2] = 0.0;
        pinhole_dir(c, s->film_x, s->film_y, r->dir);
    }
    if (!(c->lens_radius > 0.0))
        return 1.0;
    double lx, ly;
    double aw = lf_aperture_sample(&c->aperture, s->lens_u, s->lens_v, &lx, &ly);
    return lens_ray(c, lx, ly, aw, r->origin, r->dir);
}

static void projective_destroy(void *state)
{
    projective *c = state;
    if (c)
        lf_aperture_free(&c->aperture);
    free(c);
}

static int projective_describe(const void *state, char *buf, size_t size)
{
    const projective *c = state;
    int n;
    if (c->orthographic)
        n = snprintf(buf, size, "model: orthographic, screen window [%g %g] x [%g %g] camera units\n", c->screen[0],
                     c->screen[1], c->screen[2], c->screen[3]);
    else
        n = snprintf(buf, size,
                     "model: pinhole projection, fov %g deg across the shorter image axis\n"
                     "focal length in pixels: %.6g\n",
                     c->fov_deg, (c->width < c->height ? c->width : c->height) * 0.5 / c->tan_half_fov);
    if (n < 0 || (size_t)n >= size)
        return n;
    if (c->lens_radius > 0.0) {
        n += snprintf(buf + n, size - n, "defocus: thin lens, radius %g, focal distance %g (pbrt semantics)\n",
                      c->lens_radius, c->focal_distance);
        if (n < 0 || (size_t)n >= size)
            return n;
        n += snprintf(buf + n, size - n,
                      "aperture: %s, %d blades, rotation %g deg, anamorphic %g, open area %.6g x radius^2\n",
                      lf_aperture_name(&c->aperture), c->aperture.kind == LF_APERTURE_CIRCLE ? 0 : c->aperture.blades,
                      c->aperture.rotation_rad * 180.0 / M_PI, c->aperture.anamorphic, lf_aperture_area(&c->aperture));
    }
    else
        n += snprintf(buf + n, size - n, "defocus: none (lensradius 0: no lens samples drawn)\n");
    return n;
}

const lf_camera_type lf_camera_perspective = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "perspective",
    .create = perspective_create,
    .needs = projective_needs,
    .generate_ray = projective_generate_ray,
    .generate_rays = projective_generate_rays,
    .destroy = projective_destroy,
    .describe = projective_describe,
    .metadata = NULL,
};

const lf_camera_type lf_camera_orthographic = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "orthographic",
    .create = orthographic_create,
    .needs = projective_needs,
    .generate_ray = projective_generate_ray,
    .generate_rays = projective_generate_rays,
    .destroy = projective_destroy,
    .describe = projective_describe,
    .metadata = NULL,
};
