/* The ground-truth disparity AOV of light-field renders
 * (lf_renderer_disparity, docs/lightfield-format.md "Disparity AOV") against
 * disparities computed here from projection alone:
 *   - camera array, fronto-parallel and tilted planes: the first-hit point P
 *     of each pixel's ray (pbrt's perspective projection, intersected with
 *     the plane in closed form) projected into the neighbouring data camera
 *     one baseline to the right: the pixel shift there is -d;
 *   - plenoptic, fronto-parallel planes nearer and farther than the focus:
 *     the thin-lens image of a plane point, seen from two main-lens points
 *     one view step apart, lands on the microlens array one disparity of
 *     microlens pitches apart;
 *   - the decoded light field's depth-to-disparity map agrees with the AOV.
 * Embree intersects in float: tolerances are 1e-5 relative. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lightfield/lf_lightfield.h"
#include "render/lf_render.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int disparity_of(const char *text, lf_image *d, lf_attrs *meta)
{
    lf_scene_desc desc;
    lf_error err = {0};
    if (lf_scene_parse_string(text, "test.pbrt", &desc, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    lf_render_opts o = lf_render_opts_default();
    o.threads = 1;
    o.spp = 1;
    lf_renderer *r;
    int rc = lf_renderer_create(&desc, &o, &r, &err);
    if (!rc) {
        rc = lf_renderer_disparity(r, d, &err);
        lf_image img;
        if (!rc && meta && !(rc = lf_renderer_render(r, &img, meta, &err)))
            lf_image_free(&img);
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&desc);
    if (rc)
        fprintf(stderr, "%s\n", err.msg);
    return rc;
}

/* A plane z = z0 + gx x + gy y (camera space = world: LookAt along +z), a
 * big quad of it. */
static void plane_scene(char *buf, size_t n, const char *camera, int xres, int yres, double z0, double gx, double gy)
{
    double c[4][2] = {{-20, -20}, {20, -20}, {20, 20}, {-20, 20}};
    int k = snprintf(buf, n,
                     "LookAt 0 0 0  0 0 1  0 1 0\n%s\nFilm \"rgb\" \"integer xresolution\" [%d] \"integer "
                     "yresolution\" [%d]\nSampler \"independent\" \"integer pixelsamples\" [1]\nWorldBegin\n"
                     "LightSource \"infinite\" \"rgb L\" [1 1 1]\nMaterial \"diffuse\"\n"
                     "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [",
                     camera, xres, yres);
    for (int i = 0; i < 4; i++)
        k += snprintf(buf + k, n - (size_t)k, " %.17g %.17g %.17g", c[i][0], c[i][1],
                      z0 + gx * c[i][0] + gy * c[i][1]);
    snprintf(buf + k, n - (size_t)k, "]\n");
}

/* Camera array: 3 x 3 cameras, tiles 40 x 30, fov 30 deg (shorter side). */
static void test_camera_array(double z0, double gx, double gy)
{
    const int nx = 3, ny = 3, tw = 40, th = 30;
    const double fov = 30, b[4] = {-0.1, 0.1, -0.06, 0.06};
    char cam[512], scene[4096];
    snprintf(cam, sizeof cam,
             "Camera \"lightfield\" \"float fov\" [%g] \"integer camerasperdim\" [%d %d] \"float cameragridbounds\" "
             "[%g %g %g %g]",
             fov, nx, ny, b[0], b[1], b[2], b[3]);
    plane_scene(scene, sizeof scene, cam, nx * tw, ny * th, z0, gx, gy);
    lf_image d;
    if (disparity_of(scene, &d, NULL)) {
        CHECK(0);
        return;
    }
    CHECK(d.width == nx * tw && d.height == ny * th && d.channels == 1);
    /* pbrt perspective: screen window [-a, a] x [-1, 1] for a = tw/th > 1,
     * direction (screen * tan(fov/2), 1); focal length in pixels F */
    double t = tan(fov * M_PI / 360), a = (double)tw / th, F = 0.5 * th / t;
    double bx = (b[1] - b[0]) / (nx - 1), by = (b[3] - b[2]) / (ny - 1);
    double worst = 0, dmin = INFINITY, dmax = -INFINITY;
    for (int y = 0; y < d.height; y++)
        for (int x = 0; x < d.width; x++) {
            int i = x / tw, j = y / th;
            double C[3] = {b[0] + i * bx, b[3] - j * by, 0};
            double sx = -a + 2 * a * (x - i * tw + 0.5) / tw, sy = 1 - 2.0 * (y - j * th + 0.5) / th;
            double dir[3] = {sx * t, sy * t, 1};
            double s = (z0 + gx * C[0] + gy * C[1] - C[2]) / (dir[2] - gx * dir[0] - gy * dir[1]);
            double P[3] = {C[0] + s * dir[0], C[1] + s * dir[1], C[2] + s * dir[2]};
            /* image column of P in this camera and in one a baseline to the right */
            double col = (P[0] - C[0]) / P[2] * F, col_right = (P[0] - (C[0] + bx)) / P[2] * F;
            double expect = -(col_right - col);
            double got = d.data[(size_t)y * d.width + x];
            double e = fabs(got - expect) / fabs(expect);
            worst = e > worst ? e : worst;
            dmin = got < dmin ? got : dmin, dmax = got > dmax ? got : dmax;
        }
    CHECK_MSG(worst < 1e-5, "z0 %g tilt (%g, %g): worst relative error %g", z0, gx, gy, worst);
    if (gx == 0 && gy == 0)
        CHECK_NEAR(dmin, F * bx / z0, 1e-5 * F * bx / z0);
    else
        CHECK(dmax - dmin > 0.1); /* the tilt shows */
    lf_image_free(&d);
}

/* Plenoptic: the disparity of a fronto-parallel plane from thin-lens
 * imaging and the microlens geometry the camera reports. */
static void test_plenoptic(double z0)
{
    char scene[4096];
    plane_scene(scene, sizeof scene,
                "Camera \"plenoptic\" \"float focallength\" [50] \"float fstop\" [2.8] \"float focusdistance\" [1]\n"
                "    \"string sensor\" \"fullframe\" \"integer microlenses\" [24]",
                240, 160, z0, 0, 0);
    lf_image d;
    lf_attrs meta = {0};
    if (disparity_of(scene, &d, &meta)) {
        CHECK(0);
        return;
    }
    const lf_attr *s = lf_attrs_get(&meta, "lensfield:sensor_size_mm");
    const lf_attr *fm = lf_attrs_get(&meta, "lensfield:main_focal_mm");
    const lf_attr *zi = lf_attrs_get(&meta, "lensfield:mla_distance_mm");
    const lf_attr *fl = lf_attrs_get(&meta, "lensfield:microlens_focal_mm");
    const lf_attr *pu = lf_attrs_get(&meta, "lensfield:microlens_pitch_um");
    CHECK(s && fm && zi && fl && pu);
    if (!(s && fm && zi && fl && pu)) {
        lf_image_free(&d), lf_attrs_free(&meta);
        return;
    }
    /* metres */
    double pixel = s->v[0] * 1e-3 / 240, f = fm->d * 1e-3, Zi = zi->d * 1e-3, dm = fl->d * 1e-3, p = pu->d * 1e-6;
    CHECK_NEAR(1 / f - 1 / Zi, 1.0, 1e-9); /* focused at 1 m */
    /* a plane point and its thin-lens image (camera space, the image inverted) */
    double X = 0.013, zimg = f * z0 / (z0 - f), Xi = -X * zimg / z0;
    /* one view step to the right: a pixel offset of one pixel under a
     * microlens sees the main lens pixel * Zi / dm away (through the microlens
     * centre), to the right in camera space */
    double h = pixel * Zi / dm;
    /* rays from the main-lens points 0 and h through the image point reach
     * the microlens array (z = -Zi) at: */
    double m0 = 0 + (Xi - 0) * Zi / zimg, m1 = h + (Xi - h) * Zi / zimg;
    /* microlens columns grow with the sensor's x, camera -x: s = -m / p */
    double expect = -(-m1 / p - -m0 / p);
    double worst = 0, mean = 0;
    for (size_t i = 0; i < (size_t)d.width * d.height; i++) {
        double e = fabs(d.data[i] - expect);
        worst = e > worst ? e : worst;
        mean += d.data[i];
    }
    mean /= (double)d.width * d.height;
    CHECK_MSG(worst < 1e-5 * fabs(expect) + 1e-7, "plane at %g m: expected %.9g, worst error %g", z0, expect, worst);
    CHECK_MSG(z0 < 1 ? expect > 0.005 : expect < -0.005, "expected %g", expect); /* nearer than focus: d > 0 */
    /* the decoded light field's own depth -> disparity map agrees */
    lf_lightfield_layout lay, resolved;
    lf_error err = {0};
    lf_image raw = {0};
    lf_lightfield lf = {0};
    CHECK(lf_lightfield_layout_from_attrs(&meta, &lay, &err) == 0);
    CHECK(lf_lightfield_layout_resolve(&lay, NULL, 240, 160, &resolved, &err) == 0);
    CHECK(lf_image_alloc(&raw, 240, 160, 1, &err) == 0);
    CHECK(lf_lightfield_decode(&raw, &resolved, NULL, &lf, &err) == 0);
    double dd = 0;
    CHECK(lf_lightfield_depth_to_disparity(&lf, z0, &dd, &err) == 0);
    CHECK_NEAR(dd, expect, 1e-6 * fabs(expect));
    (void)mean;
    lf_lightfield_free(&lf);
    lf_image_free(&raw);
    lf_image_free(&d);
    lf_attrs_free(&meta);
}

/* Plenoptic, a tilted plane: every pixel's microlens (the nearest image
 * centre of the lattice lightfield-format.md documents), its chief ray from
 * the microlens centre through the main-lens centre, the plane hit, and the
 * thin-lens disparity of that depth. */
static void test_plenoptic_tilted(void)
{
    const double z0 = 0.9, gx = 0.5, gy = -0.3;
    char scene[4096];
    plane_scene(scene, sizeof scene,
                "Camera \"plenoptic\" \"float focallength\" [50] \"float fstop\" [2] \"float focusdistance\" [1]\n"
                "    \"string sensor\" \"fullframe\" \"integer microlenses\" [30]",
                300, 200, z0, gx, gy);
    lf_image d;
    lf_attrs meta = {0};
    if (disparity_of(scene, &d, &meta)) {
        CHECK(0);
        return;
    }
    const lf_attr *s = lf_attrs_get(&meta, "lensfield:sensor_size_mm");
    const lf_attr *fm = lf_attrs_get(&meta, "lensfield:main_focal_mm");
    const lf_attr *zi = lf_attrs_get(&meta, "lensfield:mla_distance_mm");
    const lf_attr *fl = lf_attrs_get(&meta, "lensfield:microlens_focal_mm");
    const lf_attr *pp = lf_attrs_get(&meta, "lensfield:microlens_pitch_px");
    const lf_attr *off = lf_attrs_get(&meta, "lensfield:microlens_offset_px");
    const lf_attr *cnt = lf_attrs_get(&meta, "lensfield:microlens_count");
    CHECK(s && fm && zi && fl && pp && off && cnt);
    if (!(s && fm && zi && fl && pp && off && cnt)) {
        lf_image_free(&d), lf_attrs_free(&meta);
        return;
    }
    double pixel = s->v[0] * 1e-3 / 300, f = fm->d * 1e-3, Zi = zi->d * 1e-3, dm = fl->d * 1e-3, P = pp->d;
    double p = P * pixel * Zi / (Zi + dm); /* physical pitch from the image pitch */
    double worst = 0, dmin = INFINITY, dmax = -INFINITY, wexp = 0;
    int wx = 0, wy = 0;
    for (int y = 0; y < 200; y++)
        for (int x = 0; x < 300; x++) {
            /* nearest image centre on the square, unrotated lattice */
            int i = (int)floor((x + 0.5 - off->v[0]) / P + 0.5), j = (int)floor((y + 0.5 - off->v[1]) / P + 0.5);
            i = i < 0 ? 0 : i >= (int)cnt->v[0] ? (int)cnt->v[0] - 1 : i;
            j = j < 0 ? 0 : j >= (int)cnt->v[1] ? (int)cnt->v[1] - 1 : j;
            double Gx = off->v[0] + i * P, Gy = off->v[1] + j * P;
            /* microlens centre, camera space (the sensor seen point-reflected) */
            double cx = -(Gx - 150) * pixel * Zi / (Zi + dm), cy = (Gy - 100) * pixel * Zi / (Zi + dm);
            /* chief ray from (cx, cy, -Zi) through the origin: direction (-cx, -cy, Zi) */
            double dir[3] = {-cx / Zi, -cy / Zi, 1};
            double t = z0 / (1 - gx * dir[0] - gy * dir[1]);
            double Z = t, X = t * dir[0];
            double zimg = f * Z / (Z - f), Xi = -X * zimg / Z, h = pixel * Zi / dm;
            double m0 = Xi * Zi / zimg, m1 = h + (Xi - h) * Zi / zimg;
            double expect = (m1 - m0) / p;
            double got = d.data[(size_t)y * 300 + x];
            if (fabs(got - expect) > worst)
                worst = fabs(got - expect), wx = x, wy = y, wexp = expect;
            dmin = fmin(dmin, got), dmax = fmax(dmax, got);
        }
    CHECK_MSG(worst < 1e-5 * fmax(fabs(dmin), fabs(dmax)), "plenoptic tilted plane: worst error %g at (%d, %d), expected %g (range %g .. %g)", worst, wx, wy, wexp, dmin, dmax);
    CHECK(dmin < 0 && dmax > 0); /* the plane crosses the plane in focus */
    lf_image_free(&d);
    lf_attrs_free(&meta);
}

/* The AOV agrees with the rendered light: the right neighbour's view,
 * sampled at x - d (d from the centre view's AOV), reproduces the centre
 * view; with d off by 0.5 px it does not.  Checkerboard on a tilted plane,
 * 16 spp box filter (edges anti-aliased), bilinear lookups. */
static void test_consistent_with_render(void)
{
    const int tw = 64, th = 48;
    char scene[4096];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"lightfield\" \"float fov\" [40] \"integer camerasperdim\" [3 1] \"float cameragridbounds\" "
             "[-0.06 0.06 0 0]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [16]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [1]\nWorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
             "Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" [5] \"float vscale\" [5]\n"
             "  \"rgb tex1\" [0.9 0.9 0.9] \"rgb tex2\" [0.1 0.1 0.1]\n"
             "Material \"diffuse\" \"texture reflectance\" \"c\"\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-2 -2 1.2  2 -2 2.4  -2 2 1.2  2 2 2.4] \"point2 uv\" [0 0 1 0 0 1 1 1]\n",
             3 * tw, th);
    lf_image d, img;
    lf_attrs meta = {0};
    lf_scene_desc desc;
    lf_error err = {0};
    CHECK(lf_scene_parse_string(scene, "test.pbrt", &desc, &err) == 0);
    lf_render_opts o = lf_render_opts_default();
    o.threads = 2;
    lf_renderer *r;
    if (lf_renderer_create(&desc, &o, &r, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        lf_scene_desc_free(&desc);
        return;
    }
    CHECK(lf_renderer_disparity(r, &d, &err) == 0);
    CHECK(lf_renderer_render(r, &img, &meta, &err) == 0);
    lf_renderer_free(r);
    lf_scene_desc_free(&desc);
    /* mean |error| with the AOV's d shifted by -0.5, -0.25, 0, 0.25, 0.5 px */
    double e[5] = {0};
    int n = 0;
    for (int y = 2; y < th - 2; y++)
        for (int x = 8; x < tw - 8; x++) {
            double disp = d.data[(size_t)y * d.width + tw + x];
            for (int k = 0; k < 5; k++) {
                double sx = x + 0.5 - (disp + 0.25 * (k - 2)); /* continuous column in the right view */
                int x0 = (int)floor(sx - 0.5);
                double fx = sx - 0.5 - x0;
                for (int c = 0; c < 3; c++) {
                    double a = lf_image_px(&img, 2 * tw + x0, y)[c], b = lf_image_px(&img, 2 * tw + x0 + 1, y)[c];
                    e[k] += fabs(a + fx * (b - a) - lf_image_px(&img, tw + x, y)[c]);
                }
            }
            n += 3;
        }
    for (int k = 0; k < 5; k++)
        e[k] /= n;
    printf("note: right view warped to the centre by the AOV's d + (-0.5, -0.25, 0, 0.25, 0.5) px: mean |error| "
           "%.4f %.4f %.4f %.4f %.4f\n",
           e[0], e[1], e[2], e[3], e[4]);
    CHECK(e[2] < e[1] && e[2] < e[3]);
    CHECK(e[2] < 0.6 * e[0] && e[2] < 0.6 * e[4]);
    lf_image_free(&d), lf_image_free(&img);
    lf_attrs_free(&meta);
}

static void test_not_lightfield(void)
{
    char scene[4096];
    plane_scene(scene, sizeof scene, "Camera \"perspective\"", 32, 32, 2, 0, 0);
    lf_scene_desc desc;
    lf_error err = {0};
    CHECK(lf_scene_parse_string(scene, "test.pbrt", &desc, &err) == 0);
    lf_render_opts o = lf_render_opts_default();
    lf_renderer *r;
    CHECK(lf_renderer_create(&desc, &o, &r, &err) == 0);
    lf_image d;
    CHECK(lf_renderer_disparity(r, &d, &err) == LF_ERR_PARAM);
    CHECK(strstr(err.msg, "light-field camera") != NULL);
    lf_renderer_free(r);
    lf_scene_desc_free(&desc);
}

int main(void)
{
    test_camera_array(2.0, 0, 0);
    test_camera_array(0.7, 0, 0);
    test_camera_array(2.0, 0.4, -0.25); /* tilted */
    test_plenoptic(0.8);
    test_plenoptic(1.6);
    test_plenoptic_tilted();
    test_consistent_with_render();
    test_not_lightfield();
    return lf_test_end();
}
