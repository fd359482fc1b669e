/* The spherical camera against pbrt-v4's formulas, written here from the
 * definitions and inverted: for a known camera-space direction the expected
 * raster position is computed with the INVERSE maps (atan2/acos for the
 * equirectangular map; Clarke's sphere-to-square for the equal-area map),
 * then the camera's ray for that raster position must be the direction.
 *
 * pbrt-v4 (cameras.cpp, SphericalCamera::GenerateRay): (u, v) = raster /
 * resolution; equirectangular theta = pi v, phi = 2 pi u, d = (sin theta cos
 * phi, sin theta sin phi, cos theta); equal area: EqualAreaSquareToSphere;
 * then swap(d.y, d.z).  So a camera-space direction w = (wx, wy, wz) came
 * from the mapping's d = (wx, wz, wy). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lf_camera.h"
#include "lf_test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const char *mapping = "equalarea";
static double g_float(void *c, const char *n, double def) { (void)c, (void)n; return def; }
static int g_int(void *c, const char *n, int def) { (void)c, (void)n; return def; }
static const char *g_string(void *c, const char *n, const char *def)
{
    (void)c;
    return !strcmp(n, "mapping") && mapping ? mapping : def;
}
static int g_floats(void *c, const char *n, double *o, int m) { (void)c, (void)n, (void)o, (void)m; return 0; }
static int g_image(void *c, const char *p, int *w, int *h, float **px, char *e, size_t n)
{
    (void)c, (void)p, (void)w, (void)h, (void)px;
    snprintf(e, n, "no images");
    return -1;
}

static void *make(const char *map, int w, int h, char *err, size_t n)
{
    mapping = map;
    const lf_camera_type *t = lf_camera_find("spherical");
    if (!t)
        return NULL;
    lf_camera_params p = {NULL, g_float, g_int, g_int, g_string, g_floats, g_image};
    char warn[128] = "";
    lf_camera_create_args a = {sizeof a, &p, w, h, 35.0, 0.0, 1.0, ".", err, n, warn, sizeof warn};
    void *s = NULL;
    err[0] = 0;
    return t->create(&a, &s) ? NULL : s;
}

/* Equirectangular inverse: theta = acos(d.z), phi = atan2(d.y, d.x) in [0, 2pi). */
static void equirect_inverse(const double w[3], double *u, double *v)
{
    double dx = w[0], dy = w[2], dz = w[1]; /* undo the y/z swap */
    double phi = atan2(dy, dx);
    if (phi < 0)
        phi += 2 * M_PI;
    *u = phi / (2 * M_PI);
    *v = acos(dz) / M_PI;
}

/* Clarke's sphere-to-square, from the map's definition: r = sqrt(1 - |z|),
 * the azimuth within the quadrant phi = atan(|y| / |x|) in [0, pi/2] gives
 * the position along the diamond's edge, |y'| = r phi / (pi/2), |x'| = r -
 * |y'|; the lower hemisphere folds outward (|x'|, |y'|) -> (1 - |y'|, 1 - |x'|);
 * signs follow x and y; (u, v) = ((x' + 1) / 2, (y' + 1) / 2). */
static void equal_area_inverse(const double w[3], double *u, double *v)
{
    double x = w[0], y = w[2], z = w[1];
    double r = sqrt(fmax(0.0, 1 - fabs(z)));
    double phi = atan2(fabs(y), fabs(x));
    double b = r * phi / (M_PI / 2), a = r - b;
    if (z < 0) {
        double t = a;
        a = 1 - b;
        b = 1 - t;
    }
    a = copysign(a, x);
    b = copysign(b, y);
    *u = (a + 1) / 2;
    *v = (b + 1) / 2;
}

static void ray_at(void *c, double fx, double fy, double d[3])
{
    const lf_camera_type *t = lf_camera_find("spherical");
    lf_camera_sample s = {fx, fy, 0.5, 0.5, 0, 0.5};
    lf_camera_ray r;
    memset(&r, 0, sizeof r);
    double wt = t->generate_ray(c, &s, &r);
    CHECK(wt == 1.0);
    CHECK(r.origin[0] == 0 && r.origin[1] == 0 && r.origin[2] == 0);
    memcpy(d, r.dir, sizeof r.dir);
}

static double angle_between(const double a[3], const double b[3])
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

static void check_mapping(const char *map, int W, int H, void (*inverse)(const double *, double *, double *))
{
    char err[256];
    void *c = make(map, W, H, err, sizeof err);
    CHECK_MSG(c != NULL, "%s %dx%d: %s", map, W, H, err);
    if (!c)
        return;
    /* Known directions: the axes and diagonals, plus a pseudo-random set. */
    double dirs[64][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1}, {0.6, 0.8, 0}, {0.3, -0.4, 0.866},
                          {-0.5, 0.5, -0.7071}, {0.1, 0.2, -0.97}};
    unsigned st = 7;
    for (int i = 8; i < 64; i++) {
        double z, ph;
        st = st * 1664525u + 1013904223u;
        z = 2 * ((st >> 8) * 0x1p-24) - 1;
        st = st * 1664525u + 1013904223u;
        ph = 2 * M_PI * ((st >> 8) * 0x1p-24);
        double s = sqrt(1 - z * z);
        dirs[i][0] = s * cos(ph), dirs[i][1] = z, dirs[i][2] = s * sin(ph);
    }
    double worst = 0;
    for (int i = 0; i < 64; i++) {
        double *w = dirs[i];
        double len = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        w[0] /= len, w[1] /= len, w[2] /= len;
        double u, v, d[3];
        inverse(w, &u, &v);
        ray_at(c, u * W, v * H, d);
        double a = angle_between(d, w);
        if (a > worst)
            worst = a;
    }
    CHECK_MSG(worst < 1e-9, "%s: worst angle %g rad between the camera ray and the direction whose pixel it is", map,
              worst);
    lf_camera_type const *t = lf_camera_find("spherical");
    t->destroy(c);
}

int main(void)
{
    const lf_camera_type *t = lf_camera_find("spherical");
    CHECK(t != NULL);
    if (!t)
        return lf_test_end();
    char err[256];

    /* Landmarks stated in pbrt-v4's terms (after the y/z swap). */
    void *c = make("equirectangular", 200, 100, err, sizeof err);
    CHECK(c != NULL);
    double d[3];
    ray_at(c, 100, 0, d); /* top row: theta 0 -> +y */
    CHECK_NEAR(d[1], 1, 1e-12);
    ray_at(c, 100, 100, d); /* bottom row -> -y */
    CHECK_NEAR(d[1], -1, 1e-12);
    ray_at(c, 0, 50, d); /* left edge, horizon: phi 0 -> +x */
    CHECK_NEAR(d[0], 1, 1e-12);
    ray_at(c, 100, 50, d); /* centre: phi pi -> -x */
    CHECK_NEAR(d[0], -1, 1e-12);
    ray_at(c, 50, 50, d); /* a quarter across: phi pi/2 -> map +y -> camera +z */
    CHECK_NEAR(d[2], 1, 1e-12);
    t->destroy(c);

    c = make("equalarea", 64, 64, err, sizeof err);
    CHECK(c != NULL);
    ray_at(c, 32, 32, d); /* centre: the +z pole of the map -> camera +y */
    CHECK_NEAR(d[1], 1, 1e-12);
    ray_at(c, 0, 0, d); /* corners: the -z pole -> camera -y */
    CHECK_NEAR(d[1], -1, 1e-12);
    ray_at(c, 64, 32, d); /* right edge midpoint: map (1, 0, 0) -> camera +x */
    CHECK_NEAR(d[0], 1, 1e-12);
    ray_at(c, 32, 64, d); /* bottom edge midpoint: map +y -> camera +z */
    CHECK_NEAR(d[2], 1, 1e-12);
    /* Equal area: the solid angle of the inner diamond (|x'|+|y'| <= 1/2 in
     * [-1,1]^2, a quarter of the square's area) is a quarter of 4 pi, so the
     * diamond's edge point (x' = 1/2) is at z = 1 - r^2 = 3/4. */
    ray_at(c, 48, 32, d);
    CHECK_NEAR(d[1], 0.75, 1e-12);
    t->destroy(c);

    check_mapping("equirectangular", 360, 180, equirect_inverse);
    check_mapping("equirectangular", 37, 23, equirect_inverse);
    check_mapping("equalarea", 128, 128, equal_area_inverse);
    check_mapping("equalarea", 37, 37, equal_area_inverse);

    /* pbrt-v4's default mapping is equal area, which needs a square image. */
    mapping = NULL;
    CHECK(make(NULL, 200, 100, err, sizeof err) == NULL);
    CHECK(strstr(err, "square") != NULL);
    c = make(NULL, 50, 50, err, sizeof err);
    CHECK(c != NULL);
    if (c)
        t->destroy(c);
    CHECK(make("fisheye", 50, 50, err, sizeof err) == NULL);
    CHECK(strstr(err, "fisheye") != NULL);
    return lf_test_end();
}
