/* Light-field cameras end to end: the camera array against pinhole renders
 * from each data camera, the plenoptic camera's white image and layout
 * metadata, and its centre sub-aperture view against a pinhole render. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lens.h"
#include "camera/lf_camera.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Emitters only (black surfaces that glow): a pixel's value depends only
 * on where its rays land, so differences are geometry, not light noise. */
static const char *emitter_world =
    "WorldBegin\n"
    "LightSource \"infinite\" \"rgb L\" [0.1 0.15 0.2]\n"
    "AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [1 0.3 0.2]\n Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
    " Translate -0.4 0.2 3\n Shape \"sphere\" \"float radius\" [0.5]\nAttributeEnd\n"
    "AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [0.2 0.9 0.3]\n Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
    " Translate 0.6 -0.3 5\n Shape \"sphere\" \"float radius\" [0.8]\nAttributeEnd\n"
    "AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [0.3 0.4 1]\n Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
    " Translate 0.1 0.5 1.6\n Shape \"sphere\" \"float radius\" [0.12]\nAttributeEnd\n";

static double psnr(const lf_image *a, int ax, int ay, const lf_image *b, int bx, int by, int w, int h, double peak,
                   int *identical)
{
    double se = 0;
    int same = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *p = lf_image_px((lf_image *)a, ax + x, ay + y), *q = lf_image_px((lf_image *)b, bx + x, by + y);
            same += p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
            for (int c = 0; c < 3; c++)
                se += (double)(p[c] - q[c]) * (p[c] - q[c]);
        }
    if (identical)
        *identical = same;
    double mse = se / (3.0 * w * h);
    return mse > 0 ? 10 * log10(peak * peak / mse) : INFINITY;
}

/* Each tile of the camera array equals a pinhole render from its data
 * camera.  The pinhole reference is the perspective camera placed at the
 * data camera, rendering the whole film with the screen window that puts
 * the tile's view on the tile's pixels and cropped to them: the pixels,
 * hence the sampler's streams, are the same, so the images agree up to
 * rounding of the ray (a different arithmetic path); a second reference at
 * the tile's own resolution (different sample streams) must reach 40 dB. */
static void test_array_matches_pinholes(void)
{
    const int nx = 3, ny = 2, tw = 32, th = 32, W = nx * tw, H = ny * th;
    const double b[4] = {-0.3, 0.3, -0.2, 0.2}, fov = 40;
    char scene[8192];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"lightfield\" \"float fov\" [%g] \"integer camerasperdim\" [%d %d]\n"
             "  \"float cameragridbounds\" [%g %g %g %g]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [256] \"integer seed\" [7]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [1]\n%s",
             fov, nx, ny, b[0], b[1], b[2], b[3], W, H, emitter_world);
    lf_image arr;
    lf_attrs meta = {0};
    char msg[1024];
    if (render_text(scene, &(lf_test_scene){.meta = &meta}, &arr, msg, sizeof msg)) {
        CHECK_MSG(0, "array render failed: %s", msg);
        return;
    }
    const lf_attr *a = lf_attrs_get(&meta, "lensfield:kind");
    CHECK(a && a->type == LF_ATTR_STRING && !strcmp(a->s, "camera-array"));
    a = lf_attrs_get(&meta, "lensfield:tile_size");
    CHECK(a && a->type == LF_ATTR_FLOATS && a->n == 2 && a->v[0] == tw && a->v[1] == th);
    a = lf_attrs_get(&meta, "lensfield:cameras_per_dim");
    CHECK(a && a->n == 2 && a->v[0] == nx && a->v[1] == ny);
    a = lf_attrs_get(&meta, "lensfield:camera_grid_bounds");
    CHECK(a && a->n == 4 && fabs(a->v[0] - b[0]) < 1e-7 && fabs(a->v[3] - b[3]) < 1e-7);
    a = lf_attrs_get(&meta, "lensfield:fov_deg");
    CHECK(a && a->type == LF_ATTR_DOUBLE && a->d == fov);
    lf_attrs_free(&meta);
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            double cx = b[0] + i * (b[1] - b[0]) / (nx - 1), cy = b[3] - j * (b[3] - b[2]) / (ny - 1);
            /* tile screen window [-1,1]^2 (square tile), 2/32 per pixel */
            double x0 = -1 - 2.0 * i, y1 = 1 + 2.0 * j;
            snprintf(scene, sizeof scene,
                     "LookAt %.17g %.17g 0  %.17g %.17g 1  0 1 0\n"
                     "Camera \"perspective\" \"float fov\" [%g] \"float screenwindow\" [%.17g %.17g %.17g %.17g]\n"
                     "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
                     "Sampler \"zsobol\" \"integer pixelsamples\" [256] \"integer seed\" [7]\nPixelFilter \"box\"\n"
                     "Integrator \"path\" \"integer maxdepth\" [1]\n%s",
                     cx, cy, cx, cy, fov, x0, x0 + 2.0 * W / tw, y1 - 2.0 * H / th, y1, W, H, emitter_world);
            int crop[4] = {i * tw, (i + 1) * tw, j * th, (j + 1) * th};
            lf_image pin;
            if (render_text(scene, &(lf_test_scene){.crop = crop}, &pin, msg, sizeof msg)) {
                CHECK_MSG(0, "pinhole render failed: %s", msg);
                continue;
            }
            int same = 0;
            double p = psnr(&arr, i * tw, j * th, &pin, 0, 0, tw, th, 1.0, &same);
            /* same pixels, same streams: all but a few edge pixels (where a
             * ray's last bit decides a hit) are bit-identical */
            CHECK_MSG(same >= tw * th * 99 / 100 && p > 60, "tile (%d,%d): %d of %d pixels identical, PSNR %.1f dB", i,
                      j, same, tw * th, p);
            lf_image_free(&pin);
            /* the plain pinhole at the tile's resolution: other sample streams */
            snprintf(scene, sizeof scene,
                     "LookAt %.17g %.17g 0  %.17g %.17g 1  0 1 0\n"
                     "Camera \"perspective\" \"float fov\" [%g]\n"
                     "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
                     "Sampler \"zsobol\" \"integer pixelsamples\" [256] \"integer seed\" [7]\nPixelFilter \"box\"\n"
                     "Integrator \"path\" \"integer maxdepth\" [1]\n%s",
                     cx, cy, cx, cy, fov, tw, th, emitter_world);
            if (render_text(scene, NULL, &pin, msg, sizeof msg)) {
                CHECK_MSG(0, "pinhole render failed: %s", msg);
                continue;
            }
            /* Only pixels on emitter edges differ (coverage estimated from
             * 256 samples, error ~ 0.5/sqrt(256) of the contrast ~1 on some
             * 10 % of pixels): MSE ~ 1e-4 * 0.1 -> ~ 50 dB; 40 dB as the issue asks. */
            p = psnr(&arr, i * tw, j * th, &pin, 0, 0, tw, th, 1.0, NULL);
            printf("note: tile (%d,%d): %d/%d pixels identical to the cropped pinhole; %.1f dB vs the %dx%d pinhole\n", i, j,
                   same, tw * th, p, tw, th);
            CHECK_MSG(p > 40, "tile (%d,%d) vs %dx%d pinhole render: PSNR %.1f dB", i, j, tw, th, p);
            lf_image_free(&pin);
        }
    lf_image_free(&arr);
}

/* The plenoptic camera's white image (uniform radiance 1): layout
 * metadata, brightest at microlens centres, dark corners (square grid,
 * matched f-numbers), nothing non-finite. */
static void test_plenoptic_white(void)
{
    const int P = 9, nlx = 16, nly = 12, W = P * nlx, H = P * nly;
    char scene[4096];
    snprintf(scene, sizeof scene,
             "Camera \"plenoptic\" \"float focallength\" [50] \"float fstop\" [4] \"float focusdistance\" [2]\n"
             "  \"integer microlenses\" [%d] \"string sensor\" \"fullframe\"\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
             "WorldBegin\nShape \"sphere\" \"float radius\" [1]\n",
             nlx, W, H);
    lf_image img;
    lf_attrs meta = {0};
    char msg[1024];
    if (render_text(scene, &(lf_test_scene){.white = 1, .meta = &meta}, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "white render failed: %s", msg);
        return;
    }
    const lf_attr *a = lf_attrs_get(&meta, "lensfield:kind");
    CHECK(a && !strcmp(a->s, "plenoptic"));
    a = lf_attrs_get(&meta, "lensfield:white");
    CHECK(a && a->type == LF_ATTR_INT && a->i == 1);
    a = lf_attrs_get(&meta, "lensfield:grid");
    CHECK(a && !strcmp(a->s, "square"));
    a = lf_attrs_get(&meta, "lensfield:microlens_pitch_px");
    CHECK(a && a->type == LF_ATTR_DOUBLE && fabs(a->d - P) < 1e-9);
    a = lf_attrs_get(&meta, "lensfield:microlens_count");
    CHECK(a && a->type == LF_ATTR_FLOATS && a->n == 2 && a->v[0] == nlx && a->v[1] == nly);
    a = lf_attrs_get(&meta, "lensfield:microlens_offset_px");
    CHECK(a && a->n == 2 && fabs(a->v[0] - P / 2.0) < 1e-5 && fabs(a->v[1] - P / 2.0) < 1e-5);
    const char *names[] = {"lensfield:microlens_rotation_rad", "lensfield:microlens_pitch_um",
                           "lensfield:microlens_focal_mm",     "lensfield:main_focal_mm",
                           "lensfield:main_fstop",             "lensfield:focus_distance_m",
                           "lensfield:mla_distance_mm",        "lensfield:sensor_offset_mm"};
    for (int k = 0; k < 8; k++) {
        a = lf_attrs_get(&meta, names[k]);
        CHECK_MSG(a && a->type == LF_ATTR_DOUBLE && isfinite(a->d), "%s", names[k]);
    }
    a = lf_attrs_get(&meta, "lensfield:mla_distance_mm");
    CHECK(a && fabs(a->d - 50.0 / (1 - 0.025)) < 1e-9); /* thin lens: z_i = f z_o/(z_o - f) */
    a = lf_attrs_get(&meta, "lensfield:sensor_size_mm");
    CHECK(a && a->n == 2 && fabs(a->v[0] - 36) < 1e-5 && fabs(a->v[1] - 27) < 1e-5);
    lf_attrs_free(&meta);
    CHECK(lf_image_count_nonfinite(&img) == 0);
    /* Brightest at the microlens centres: the mean of an image's vignetted
     * rim (pixels centred beyond P/2 - 1 px: part of their aperture patch
     * falls outside the main aperture) is below the centre pixel.  Within
     * the unvignetted core the irradiance follows cos^4 of the oblique ray
     * to the microlens: off axis the pixel one step towards the axis gains
     * ~ 4 tan(theta_c) pix/f_mla (theta_c the chief-ray angle), so the
     * centre is the maximum of the whole image only for the microlenses next
     * to the axis (tan(theta_c) < 0.02: gain < 0.3 %, the noise margin). */
    int not_brightest = 0, rim_brighter = 0, corner_lit = 0, centre_dark = 0;
    double zi_mm = 50.0 / (1 - 0.025);
    for (int j = 0; j < nly; j++)
        for (int i = 0; i < nlx; i++) {
            int cx = i * P + P / 2, cy = j * P + P / 2;
            float c = lf_image_px(&img, cx, cy)[1];
            centre_dark += !(c > 0);
            double rim = 0;
            int n_rim = 0;
            double tan_c = hypot(cx + 0.5 - W / 2.0, cy + 0.5 - H / 2.0) * (36.0 / W) / zi_mm;
            for (int y = j * P; y < (j + 1) * P; y++)
                for (int x = i * P; x < (i + 1) * P; x++) {
                    float v = lf_image_px(&img, x, y)[1];
                    double rr = hypot(x - cx, y - cy);
                    /* 64 spp noise on the cos^4 term is ~1e-3 of the value */
                    if (tan_c < 0.02 && (x != cx || y != cy) && v > c * 1.003f)
                        not_brightest++;
                    if (rr > P / 2.0 - 1)
                        rim += v, n_rim++;
                    if (rr > P / 2.0 + 0.75)
                        corner_lit += v > 0;
                }
            rim_brighter += !(rim / n_rim < c);
        }
    CHECK_MSG(rim_brighter == 0, "%d microlens images with a rim as bright as their centre", rim_brighter);
    CHECK(centre_dark == 0);
    CHECK_MSG(not_brightest == 0, "%d pixels brighter than their microlens centre", not_brightest);
    CHECK_MSG(corner_lit == 0, "%d corner pixels lit", corner_lit);
    /* the centre pixel under the axis: (1/d^2) \int_cell cos^4 dA ~
     * (p/f_mla)^2 = 1/N_image^2 to within the cos^4 over the cell (<= 4 %) */
    double zi = 50.0 / (1 - 0.025), D = 12.5;
    float c = lf_image_px(&img, (nlx / 2) * P + P / 2, (nly / 2) * P + P / 2)[1];
    CHECK_MSG(c < 1 / pow(zi / D, 2) && c > 0.96 / pow(zi / D, 2), "centre %.5g vs 1/N^2 %.5g", c, 1 / pow(zi / D, 2));
    lf_image_free(&img);
}

/* The centre sub-aperture view: the centre pixel of every microlens image
 * sees the scene through the main-lens centre, so the array of centre
 * pixels is a pinhole image from the origin with film distance z_i + f_mla,
 * at the microlens resolution.  The scene is smooth and large (diffuse
 * spheres and a wall near the focus distance under a distant light with
 * maxdepth 1: no light-sampling noise).  Both images are divided by their
 * means after removing the plenoptic image's natural cos^4 falloff (the
 * pinhole is radiance, the plenoptic exposure). */
static void test_plenoptic_centre_view(int compound)
{
    const int P = 9, nlx = 24, nly = 16, W = P * nlx, H = P * nly;
    double f = 50, N = 4, zo = 3000, D = f / N, zi = f * zo / (zo - f);
    /* Compound: scenes/lenses/dgauss.50mm.dat, stop 8 mm, focused at 3 m
     * from the MLA.  From the lens library's paraxial analysis: the lattice
     * sees the exit pupil (Z from the MLA, diameter D_xp, Z/D_xp = N_w) in
     * place of the thin lens (zi, D); the centre view is a pinhole at the
     * entrance pupil whose film distance is (Z + f_mla) D_ep/D_xp (chief
     * rays: tan theta_object = tan theta_image D_xp/D_ep, paraxially). */
    double pin_z = 0, mag = 1;
    if (compound) {
        lf_lens lens;
        lf_error lerr = {0};
        lf_lens_paraxial px;
        if (lf_lens_load(LF_SOURCE_DIR "/scenes/lenses/dgauss.50mm.dat", &lens, &lerr)) {
            CHECK_MSG(0, "%s", lerr.msg);
            return;
        }
        lf_lens_set_stop_diameter(&lens, 8.0, NULL);
        lf_lens_paraxial_analyse(&lens, &px);
        lf_lens_focus_thick(&lens, zo, &lens.film_distance_mm, &lerr);
        zi = lens.film_distance_mm - px.exit_pupil_mm, D = px.exit_pupil_diameter_mm;
        mag = px.entrance_pupil_diameter_mm / px.exit_pupil_diameter_mm;
        pin_z = (px.front_principal_mm - px.entrance_pupil_mm) * 1e-3; /* camera origin at H */
        printf("note: dgauss 50 mm at stop 8 mm: exit pupil %.4g mm wide %.4g mm before the MLA (f/%.4g), pupil "
               "magnification %.4f\n", D, zi, zi / D, 1 / mag);
        lf_lens_free(&lens);
    }
    /* matched design, "microlenses" 24 across 36 mm: image spacing Pm = p (1 + p/D) */
    double Pm = 36.0 / nlx, p = D * (sqrt(1 + 4 * Pm / D) - 1) / 2, fm = p * zi / D, zs = zi + fm;
    double fov = 2 * atan(0.5 * 24.0 / (zs * mag)) * 180 / M_PI; /* across the shorter side: 24 mm */
    const char *world =
        "WorldBegin\n"
        "LightSource \"distant\" \"point3 from\" [-1 2 -2] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n"
        "LightSource \"infinite\" \"rgb L\" [0.2 0.2 0.2]\n"
        "AttributeBegin\n Material \"diffuse\" \"rgb reflectance\" [0.7 0.5 0.3]\n"
        " Translate -0.35 0.05 3\n Shape \"sphere\" \"float radius\" [0.3]\nAttributeEnd\n"
        "AttributeBegin\n Material \"diffuse\" \"rgb reflectance\" [0.3 0.5 0.7]\n"
        " Translate 0.4 -0.1 3.2\n Shape \"sphere\" \"float radius\" [0.35]\nAttributeEnd\n"
        "AttributeBegin\n Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
        " Shape \"bilinearmesh\" \"point3 P\" [-3 -3 3.6  3 -3 3.6  -3 3 3.6  3 3 3.6]\nAttributeEnd\n";
    char scene[4096], main_lens[256];
    if (compound)
        snprintf(main_lens, sizeof main_lens,
                 "\"string lensfile\" \"%s/scenes/lenses/dgauss.50mm.dat\" \"float aperturediameter\" [8]",
                 LF_SOURCE_DIR);
    else
        snprintf(main_lens, sizeof main_lens, "\"float focallength\" [%g] \"float fstop\" [%g]", f, N);
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"plenoptic\" %s \"float focusdistance\" [%g]\n"
             "  \"integer microlenses\" [%d] \"float sensorsize\" [36 24]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [1]\n%s",
             main_lens, zo / 1000, nlx, W, H, world);
    lf_image plen, pin;
    char msg[1024];
    if (render_text(scene, NULL, &plen, msg, sizeof msg)) {
        CHECK_MSG(0, "plenoptic render failed: %s", msg);
        return;
    }
    snprintf(scene, sizeof scene,
             "LookAt 0 0 %.17g  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" [%.17g]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [1]\n%s",
             pin_z, fov, nlx, nly, world);
    if (render_text(scene, NULL, &pin, msg, sizeof msg)) {
        CHECK_MSG(0, "pinhole render failed: %s", msg);
        lf_image_free(&plen);
        return;
    }
    /* decode: the centre pixel of each image (spacing 9 px, centres at
     * 4.5 + 9 i: pixel 4 + 9 i), cos^4 of its chief ray removed */
    double *view = malloc(sizeof(double) * nlx * nly * 3);
    double sv = 0, sp = 0;
    double pix = 36.0 / W;
    for (int j = 0; j < nly; j++)
        for (int i = 0; i < nlx; i++) {
            int x = i * P + P / 2, y = j * P + P / 2;
            double gx = (x + 0.5 - W / 2.0) * pix, gy = (y + 0.5 - H / 2.0) * pix;
            double c2 = zs * zs / (zs * zs + gx * gx + gy * gy);
            for (int c = 0; c < 3; c++) {
                view[(j * nlx + i) * 3 + c] = lf_image_px(&plen, x, y)[c] / (c2 * c2);
                sv += view[(j * nlx + i) * 3 + c];
                sp += lf_image_px(&pin, i, j)[c];
            }
        }
    double se = 0, ss = 0;
    for (int j = 0; j < nly; j++)
        for (int i = 0; i < nlx; i++)
            for (int c = 0; c < 3; c++) {
                double a = view[(j * nlx + i) * 3 + c] / sv, b = lf_image_px(&pin, i, j)[c] / sp;
                se += (a - b) * (a - b);
                ss += b * b;
            }
    double rel_rmse = sqrt(se / ss);
    /* the metric can tell: against the mirrored pinhole view it is large */
    double se_m = 0;
    for (int j = 0; j < nly; j++)
        for (int i = 0; i < nlx; i++)
            for (int c = 0; c < 3; c++) {
                double a = view[(j * nlx + i) * 3 + c] / sv, b = lf_image_px(&pin, nlx - 1 - i, j)[c] / sp;
                se_m += (a - b) * (a - b);
            }
    CHECK_MSG(sqrt(se_m / ss) > 0.15, "mirrored view: relative RMSE only %.4f", sqrt(se_m / ss));
    /* Metric: relative RMSE after normalising each image by its mean.
     * Sources of difference: the centre pixel integrates 1/9 of the
     * aperture (the 0.6 m depth range around the 3 m focus blurs by < 0.3
     * view pixels), a microlens cell vs a box pixel (the same footprint on
     * the focus plane, but the cell's is sampled through the pixel's 1/9
     * aperture patch), and sphere-edge pixels whose coverage differs by up
     * to ~20 %; those are ~10 % of the view, giving ~0.03-0.05.  A wrong
     * orientation gives > 0.15 (checked below). */
    printf("note: %s main lens: centre sub-aperture view vs pinhole: relative RMSE %.4f (threshold 0.06), exposure "
           "ratio x N^2 = %.4f\n",
           compound ? "compound (dgauss 50 mm)" : "thin", rel_rmse, (sv / sp) * pow(zi / D, 2));
    CHECK_MSG(rel_rmse < 0.06, "centre view vs pinhole: relative RMSE %.4f", rel_rmse);
    /* and the exposure: radiance x (p/f_mla)^2 cos^4 ~ radiance / N_image^2 */
    double ratio = (sv / (3 * nlx * nly)) / (sp / (3 * nlx * nly)), Ni = zi / D;
    CHECK_MSG(ratio > 0.95 / (Ni * Ni) && ratio < 1.02 / (Ni * Ni), "exposure ratio %.5g vs 1/N^2 %.5g", ratio,
              1 / (Ni * Ni));
    free(view);
    lf_image_free(&plen);
    lf_image_free(&pin);
}

int main(void)
{
    test_array_matches_pinholes();
    test_plenoptic_white();
    test_plenoptic_centre_view(0);
    test_plenoptic_centre_view(1);
    return lf_test_end();
}
