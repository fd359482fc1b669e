/* test_render_subsurface.c - Material "subsurface" rendered by the random
 * walk (render/subsurface.c), on a semi-infinite medium: a box 2 km wide
 * and 1 km deep (mean free path 1 m) seen straight down by an orthographic
 * camera under a uniform white sky (L = 1).  A pixel then measures the
 * total diffuse reflectance for normal incidence (the exit lobe S_w is
 * normalised, so whatever leaves collects the sky's 1).
 *  - eta = 1 (index matched), isotropic scattering: against the closed form
 *    of radiative transfer, R(mu0 = 1) = 1 - H(1) sqrt(1 - albedo) with
 *    Chandrasekhar's H function (computed here by iterating its integral
 *    equation), for albedos 0.99, 0.9 and 0.7 in the three channels.
 *  - eta = 1.33, g = 0.5: against an independent 1-D Monte Carlo of the same
 *    transport written here (Fresnel reflection R0 at entry, flights of
 *    mean 1, Henyey-Greenstein scattering, Fresnel internal reflection at
 *    the surface with the Fresnel equations written out).
 * Margins: 3 standard errors of the pixel mean (and of the reference MC)
 * plus 0.005 for the float arithmetic of a few hundred steps per walk.
 * Also: pbrt-v4's named media and parameter errors. */
#include "render/lf_render.h"
#include "shading/lf_shading.h"

#include "lf_test.h"
#include "lf_test_tools.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static unsigned long long rng = 0x1234567ull;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) * 0x1p-53;
}

/* Chandrasekhar's H for isotropic scattering of albedo a on a midpoint
 * grid of n points: H(mu) = 1 / (1 - (a/2) mu int_0^1 H(m) / (mu + m) dm). */
static double h_function(double a, double mu)
{
    enum { N = 800 };
    static double H[N], m[N], last_a = -1;
    for (int i = 0; i < N && a != last_a; i++) {
        m[i] = (i + 0.5) / N;
        H[i] = 1;
    }
    for (int it = 0; it < 2000 && a != last_a; it++) {
        double change = 0;
        for (int i = 0; i < N; i++) {
            double s = 0;
            for (int j = 0; j < N; j++)
                s += H[j] / (m[i] + m[j]) / N;
            double h = 1 / (1 - 0.5 * a * m[i] * s);
            change = fmax(change, fabs(h - H[i]));
            H[i] = h;
        }
        if (change < 1e-10)
            break;
    }
    last_a = a; /* the table is kept for the next call with this albedo */
    double s = 0;
    for (int j = 0; j < N; j++)
        s += H[j] / (mu + m[j]) / N;
    return 1 / (1 - 0.5 * a * mu * s);
}

/* Unpolarised Fresnel reflectance, light going from index n1 to n2 at cos_i. */
static double fresnel(double cos_i, double n1, double n2)
{
    double sin_t = n1 / n2 * sqrt(fmax(0, 1 - cos_i * cos_i));
    if (sin_t >= 1)
        return 1;
    double cos_t = sqrt(1 - sin_t * sin_t);
    double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

/* 1-D walk in z < 0: returns the reflectance for normal incidence and its
 * standard error. */
static void walk_1d(double albedo, double g, double eta, int n, double *mean, double *se)
{
    double r0 = fresnel(1, 1, eta), s = 0, s2 = 0;
    for (int k = 0; k < n; k++) {
        double z = 0, mu = -1, w = 1, out = 0; /* mu: cosine with +z */
        for (int step = 0; step < 100000; step++) {
            double t = -log(1 - urand()), zn = z + mu * t;
            if (zn >= 0) {
                if (urand() < fresnel(mu, eta, 1)) {
                    z = 0;
                    mu = -mu;
                    continue;
                }
                out = w;
                break;
            }
            z = zn;
            w *= albedo;
            if (w < 1e-3)
                break; /* contributes < 1e-3 of a walker: negligible, and rare */
            /* HG about the travel direction, then rotate: only the z cosine matters */
            double c = fabs(g) < 1e-3 ? 1 - 2 * urand()
                                      : (1 + g * g - pow((1 - g * g) / (1 - g + 2 * g * urand()), 2)) / (2 * g);
            double phi = 2 * M_PI * urand(), st = sqrt(fmax(0, 1 - c * c)), sm = sqrt(fmax(0, 1 - mu * mu));
            mu = mu * c + sm * st * cos(phi);
        }
        double v = r0 + (1 - r0) * out;
        s += v;
        s2 += v * v;
    }
    *mean = s / n;
    *se = sqrt(fmax(0, s2 / n - *mean * *mean) / n);
}

static const char *SCENE_FMT =
    "LookAt 0 0 10  0 0 0  0 1 0\n"
    "Camera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\n"
    "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
    "Sampler \"independent\" \"integer pixelsamples\" [%d] \"integer seed\" [7]\n"
    "PixelFilter \"box\" \"float xradius\" [0.5] \"float yradius\" [0.5]\n"
    "Integrator \"%s\" \"integer maxdepth\" [8]\n"
    "WorldBegin\n"
    "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
    "Material \"subsurface\" %s\n"
    "Shape \"trianglemesh\" \"integer indices\" [0 2 1 0 3 2  4 5 6 4 6 7  0 5 4 0 1 5  1 6 5 1 2 6  2 7 6 2 3 7  "
    "3 4 7 3 0 4]\n"
    "  \"point3 P\" [-1000 -1000 -1000  1000 -1000 -1000  1000 1000 -1000  -1000 1000 -1000\n"
    "               -1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0]\n";

/* Mean and standard error of each channel over the pixels. */
static int render_slab(const char *integrator, const char *params, int spp, double mean[3], double se[3])
{
    char scene[4096], msg[1024] = "";
    snprintf(scene, sizeof scene, SCENE_FMT, spp, integrator, params);
    lf_image img = {0};
    char *warnings = NULL;
    int rc = render_text(scene, &(lf_test_scene){.warnings = &warnings}, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    CHECK_MSG(warnings == NULL, "%s", warnings);
    free(warnings);
    if (rc)
        return rc;
    int n = img.width * img.height;
    for (int c = 0; c < 3; c++) {
        double s = 0, s2 = 0;
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++) {
                double v = lf_image_px(&img, x, y)[c];
                s += v;
                s2 += v * v;
            }
        mean[c] = s / n;
        se[c] = sqrt(fmax(0, s2 / n - mean[c] * mean[c]) / n);
    }
    lf_image_free(&img);
    return 0;
}

static void test_index_matched(void)
{
    double m[3], se[3];
    if (render_slab("path", "\"float eta\" [1] \"rgb sigma_a\" [0.01 0.1 0.3] \"rgb sigma_s\" [0.99 0.9 0.7]", 64, m,
                    se))
        return;
    const double albedo[3] = {0.99, 0.9, 0.7};
    for (int c = 0; c < 3; c++) {
        double want = 1 - h_function(albedo[c], 1.0) * sqrt(1 - albedo[c]);
        printf("index matched, albedo %.2f: walk %.4f +- %.4f, 1 - H(1) sqrt(1 - a) = %.4f\n", albedo[c], m[c], se[c],
               want);
        CHECK_MSG(fabs(m[c] - want) < 3 * se[c] + 0.005, "albedo %g: %g +- %g, want %g", albedo[c], m[c], se[c],
                  want);
    }
    /* the H function itself: int_0^1 H = (2/a)(1 - sqrt(1 - a)) (Chandrasekhar's zeroth moment) */
    double s = 0;
    for (int i = 0; i < 200; i++)
        s += h_function(0.9, (i + 0.5) / 200) / 200;
    CHECK_NEAR(s, 2 / 0.9 * (1 - sqrt(0.1)), 2e-3);
}

static void test_fresnel_boundary(void)
{
    double m[3], se[3];
    if (render_slab("volpath",
                    "\"float eta\" [1.33] \"float g\" [0.5] \"rgb sigma_a\" [0.02 0.1 0.3] \"rgb sigma_s\" [0.98 0.9 0.7]",
                    64, m, se))
        return;
    const double albedo[3] = {0.98, 0.9, 0.7};
    for (int c = 0; c < 3; c++) {
        double want, wse;
        walk_1d(albedo[c], 0.5, 1.33, 100000, &want, &wse);
        printf("eta 1.33, g 0.5, albedo %.2f: walk %.4f +- %.4f, 1-D Monte Carlo %.4f +- %.4f\n", albedo[c], m[c],
               se[c], want, wse);
        CHECK_MSG(fabs(m[c] - want) < 3 * sqrt(se[c] * se[c] + wse * wse) + 0.005, "albedo %g: %g vs %g", albedo[c],
                  m[c], want);
    }
}

/* "reflectance" r and "mfp": sigma_t = 1 / mfp and the albedo a from
 * Chiang, Kutz and Burley's fit.  The walk's normal-incidence reflectance
 * must be 1 - H(1) sqrt(1 - a) for that a (index matched), and the fit
 * should make the hemispherical albedo 2 int (1 - H(mu) sqrt(1 - a)) mu dmu
 * close to r (the fit's own accuracy: a few percent). */
static void test_reflectance_mode(void)
{
    double m[3], se[3];
    if (render_slab("path", "\"float eta\" [1] \"rgb reflectance\" [0.2 0.5 0.8] \"rgb mfp\" [1 1 1]", 64, m, se))
        return;
    lf_vec3 a3 = lf_subsurface_albedo_from_reflectance(lf_v3(0.2f, 0.5f, 0.8f));
    const double r[3] = {0.2, 0.5, 0.8}, a[3] = {a3.x, a3.y, a3.z};
    for (int c = 0; c < 3; c++) {
        double normal = 1 - h_function(a[c], 1.0) * sqrt(1 - a[c]), hemi = 0;
        for (int i = 0; i < 100; i++) {
            double mu = (i + 0.5) / 100;
            hemi += 2 * (1 - h_function(a[c], mu) * sqrt(1 - a[c])) * mu / 100;
        }
        printf("reflectance %.1f: albedo %.4f, walk %.4f +- %.4f, normal incidence %.4f, hemispherical %.4f\n", r[c],
               a[c], m[c], se[c], normal, hemi);
        CHECK_MSG(fabs(m[c] - normal) < 3 * se[c] + 0.005, "%g vs %g", m[c], normal);
        CHECK_MSG(fabs(hemi - r[c]) < 0.05 * r[c] + 0.01, "hemispherical albedo %g for reflectance %g", hemi, r[c]);
    }
}

static void test_named_and_errors(void)
{
    /* a mix resolves to its subsurface component as lf_material_bsdf does */
    lf_scene_desc d;
    lf_error err = {0};
    const char *mix = "WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"subsurface\" \"string name\" \"Skin2\"\n"
                      "MakeNamedMaterial \"b\" \"string type\" \"diffuse\"\n"
                      "Material \"mix\" \"string materials\" [\"a\" \"b\"] \"float amount\" 0\n";
    CHECK(lf_scene_parse_string(mix, "mix.pbrt", &d, &err) == 0);
    lf_materials *ms = NULL;
    CHECK_MSG(lf_materials_build(&d, &ms, &err) == 0, "%s", err.msg);
    if (ms) {
        lf_shading_ctx c;
        memset(&c, 0, sizeof c);
        lf_subsurface sub;
        CHECK(lf_material_subsurface(lf_materials_get(ms, 2), &c, &sub) == 1 && fabsf(sub.sigma_s.x - 1.09f) < 1e-6f);
        CHECK(lf_material_subsurface(lf_materials_get(ms, 1), &c, &sub) == 0);
    }
    lf_materials_free(ms);
    lf_scene_desc_free(&d);

    lf_vec3 a, s;
    CHECK(lf_named_medium("Skin1", &a, &s) == 0 && fabsf(a.z - 0.48f) < 1e-6f && fabsf(s.x - 0.74f) < 1e-6f);
    CHECK(lf_named_medium("Wholemilk", &a, &s) == 0 && fabsf(s.z - 3.77f) < 1e-6f);
    CHECK(lf_named_medium("skin1", &a, &s) != 0);
    const char *bad[] = {"WorldBegin\nMaterial \"subsurface\" \"string name\" \"Skin9\"\n",
                         "WorldBegin\nMaterial \"subsurface\" \"rgb sigma_a\" [1 1 1]\n"};
    const char *want[] = {"test.pbrt:2:23: subsurface: named medium \"Skin9\" not found", "without \"sigma_s\""};
    for (int i = 0; i < 2; i++) {
        char msg[1024] = "";
        int rc = render_text(bad[i], NULL, NULL, msg, sizeof msg);
        CHECK_MSG(rc != 0 && strstr(msg, want[i]), "%s", msg);
    }
}

int main(void)
{
    test_index_matched();
    test_fresnel_boundary();
    test_reflectance_mode();
    test_named_and_errors();
    return lf_test_end();
}
