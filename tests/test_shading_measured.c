/* test_shading_measured.c - Material "measured": an RGL .bsdf tensor file
 * written here (a Lambertian reflector of albedo 0.5 over a GGX normal
 * distribution, tabulated onto the file's grids the way Dupuy & Jakob's
 * format defines f = R D / (4 sigma(wo) cos theta_i)), read back through the
 * scene parser and checked for: reciprocity; albedo by an independent
 * quadrature of the file's BRDF against the Lambertian's 0.5; the
 * importance-sampling estimate against that quadrature; the sampling pdf
 * against the pdf function and its normalisation.  The piecewise-linear
 * warp the format relies on is checked on its own: sample and invert are
 * inverse maps and the density is the normalised bilinear interpolant. */
#include "scenefile/lf_scene_desc.h"
#include "shading/lf_shading.h"

#include "lf_test.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define DIR LF_BINARY_DIR "/test_shading_measured.d"

static unsigned long long rng = 0x2545F4914F6CDD1Dull;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) * 0x1p-53;
}

/* ------------------------------------------------ writing a tensor file */

typedef struct field {
    const char *name;
    int dtype; /* 1 uint8, 10 float32 */
    int ndim;
    uint64_t shape[5];
    const void *data;
} field;

static void put(FILE *f, uint64_t v, int n)
{
    for (int i = 0; i < n; i++)
        fputc((int)((v >> (8 * i)) & 255), f);
}

static size_t field_bytes(const field *fl)
{
    size_t n = fl->dtype == 10 ? 4 : 1;
    for (int d = 0; d < fl->ndim; d++)
        n *= fl->shape[d];
    return n;
}

/* The tensor_file layout: header, field table, then the data blocks. */
static int write_tensor(const char *path, const field *fields, int n)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    fwrite("tensor_file", 1, 12, f);
    fputc(1, f);
    fputc(0, f);
    put(f, (uint64_t)n, 4);
    size_t table = 18;
    for (int i = 0; i < n; i++)
        table += 2 + strlen(fields[i].name) + 2 + 1 + 8 + 8 * (size_t)fields[i].ndim;
    size_t offset = table;
    for (int i = 0; i < n; i++) {
        put(f, strlen(fields[i].name), 2);
        fwrite(fields[i].name, 1, strlen(fields[i].name), f);
        put(f, (uint64_t)fields[i].ndim, 2);
        fputc(fields[i].dtype, f);
        put(f, offset, 8);
        for (int d = 0; d < fields[i].ndim; d++)
            put(f, fields[i].shape[d], 8);
        offset += field_bytes(&fields[i]);
    }
    for (int i = 0; i < n; i++)
        fwrite(fields[i].data, 1, field_bytes(&fields[i]), f);
    return fclose(f);
}

/* ------------------------------------------------------ the test BRDF */

#define ALPHA 0.5
#define RHO 0.5
#define NT 9   /* theta_i nodes */
#define NW 5   /* wavelengths */
#define NM 48  /* half-vector grid, both axes */

static double ggx_d(double cos_m)
{
    if (cos_m <= 0)
        return 0;
    double c2 = cos_m * cos_m, t2 = (1 - c2) / c2, a2 = ALPHA * ALPHA;
    return 1.0 / (M_PI * a2 * c2 * c2 * (1 + t2 / a2) * (1 + t2 / a2));
}

/* sigma(w) = integral of D(m) max(0, w.m) dm = cos(theta) (1 + Lambda) for GGX. */
static double ggx_sigma(double theta)
{
    double c = cos(theta);
    if (c < 1e-6)
        c = 1e-6;
    double t2 = (1 - c * c) / (c * c);
    return c * (1 + (-1 + sqrt(1 + ALPHA * ALPHA * t2)) / 2);
}

static double u2theta(double u) { return u * u * M_PI / 2; }
static double u2phi(double u) { return (2 * u - 1) * M_PI; }

/* Writes the file: vndf uniform (its warp is then the identity, so R's
 * grid is the half-vector grid), luminance proportional to R (a good
 * sampling density), R = f 4 sigma(wo) cos(theta_i) / D(wm) at each node. */
static int write_lambertian(const char *path)
{
    static float theta_i[NT], phi_i[1] = {0}, wl[NW] = {360, 480, 600, 720, 830};
    static float ndf[2][NM], sigma[2][NM], vndf[NT][NM][NM], lum[NT][NM][NM], spectra[NT][NW][NM][NM];
    static uint8_t desc[] = "lensfield test: Lambertian 0.5 over GGX 0.5", jac[1] = {1};
    for (int t = 0; t < NT; t++)
        theta_i[t] = (float)(t * 10.0 * M_PI / 180.0);
    for (int x = 0; x < NM; x++) {
        double th = u2theta(x / (NM - 1.0));
        ndf[0][x] = ndf[1][x] = (float)ggx_d(cos(th));
        sigma[0][x] = sigma[1][x] = (float)ggx_sigma(th);
    }
    for (int t = 0; t < NT; t++) {
        double to = theta_i[t];
        double wo[3] = {sin(to), 0, cos(to)};
        for (int y = 0; y < NM; y++)
            for (int x = 0; x < NM; x++) {
                double thm = u2theta(x / (NM - 1.0)), phm = u2phi(y / (NM - 1.0)); /* phi relative to phi_o = 0 */
                double m[3] = {sin(thm) * cos(phm), sin(thm) * sin(phm), cos(thm)};
                double d = wo[0] * m[0] + wo[1] * m[1] + wo[2] * m[2];
                double wiz = 2 * d * m[2] - wo[2];
                double r = 0;
                if (wiz > 0 && d > 0)
                    r = RHO / M_PI * 4 * ggx_sigma(to) * wiz / ggx_d(m[2]);
                vndf[t][y][x] = 1.f;
                lum[t][y][x] = (float)(r + 1e-3);
                for (int w = 0; w < NW; w++)
                    spectra[t][w][y][x] = (float)r;
            }
    }
    field f[] = {
        {"description", 1, 1, {sizeof desc - 1}, desc},
        {"jacobian", 1, 1, {1}, jac},
        {"theta_i", 10, 1, {NT}, theta_i},
        {"phi_i", 10, 1, {1}, phi_i},
        {"wavelengths", 10, 1, {NW}, wl},
        {"ndf", 10, 2, {2, NM}, ndf},
        {"sigma", 10, 2, {2, NM}, sigma},
        {"vndf", 10, 4, {1, NT, NM, NM}, vndf},
        {"luminance", 10, 4, {1, NT, NM, NM}, lum},
        {"spectra", 10, 5, {1, NT, NW, NM, NM}, spectra},
    };
    return write_tensor(path, f, (int)(sizeof f / sizeof f[0]));
}

/* ------------------------------------------------------------- tests */

static lf_vec3 dir(double theta, double phi)
{
    return lf_v3((float)(sin(theta) * cos(phi)), (float)(sin(theta) * sin(phi)), (float)cos(theta));
}

/* Midpoint quadrature of f cos over the upper hemisphere in (cos theta, phi). */
static double hemi_integral(const lf_measured *m, lf_vec3 wo, int what)
{
    const int nc = 256, np = 256;
    double sum = 0;
    for (int i = 0; i < nc; i++) {
        double c = (i + 0.5) / nc, th = acos(c);
        for (int j = 0; j < np; j++) {
            lf_vec3 wi = dir(th, 2 * M_PI * (j + 0.5) / np);
            sum += what == 0 ? lf_measured_f(m, wo, wi).y * c : lf_measured_pdf(m, wo, wi);
        }
    }
    return sum * 2 * M_PI / ((double)nc * np);
}

/* The integral of the pdf over the hemisphere, taken in the half-vector
 * coordinates the file's tables use (u: theta_m = pi u^2 / 2, v: phi_m =
 * (2v - 1) pi) where the pdf times the Jacobian d omega_i / du dv =
 * 4 (wo . wm) 2 pi^2 u sin(theta_m) is smooth. */
static double pdf_integral(const lf_measured *m, lf_vec3 wo)
{
    const int n = 400;
    double sum = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double u = (i + 0.5) / n, v = (j + 0.5) / n, th = u2theta(u), ph = u2phi(v);
            lf_vec3 wm = dir(th, ph);
            double d = lf_dot(wo, wm);
            lf_vec3 wi = lf_sub(lf_scale(wm, (float)(2 * d)), wo);
            if (d <= 0 || wi.z <= 0)
                continue;
            sum += lf_measured_pdf(m, wo, wi) * 4 * d * 2 * M_PI * M_PI * u * sin(th);
        }
    return sum / ((double)n * n);
}

static void test_brdf(const lf_measured *m)
{
    /* reciprocity over directions below 70 degrees */
    double worst = 0, mean = 0;
    int n = 0;
    for (int k = 0; k < 400; k++) {
        lf_vec3 a = dir(acos(1 - urand() * (1 - cos(70 * M_PI / 180))), urand() * 2 * M_PI);
        lf_vec3 b = dir(acos(1 - urand() * (1 - cos(70 * M_PI / 180))), urand() * 2 * M_PI);
        double fab = lf_measured_f(m, a, b).y, fba = lf_measured_f(m, b, a).y;
        double rel = fabs(fab - fba) / (0.5 * (fab + fba) + 1e-9);
        worst = fmax(worst, rel);
        mean += rel;
        n++;
        /* and each is the Lambertian 0.5/pi (table interpolation error) */
        CHECK_MSG(fabs(fab * M_PI / RHO - 1) < 0.08, "f = %g, Lambertian %g", fab, RHO / M_PI);
    }
    mean /= n;
    /* interpolation of R, D and sigma on a 48-node grid: a few percent at worst */
    CHECK_MSG(worst < 0.08 && mean < 0.02, "reciprocity: worst %.3g, mean %.3g relative", worst, mean);
    printf("reciprocity |f(a,b) - f(b,a)| / f: mean %.4f, worst %.4f (400 pairs below 70 deg)\n", mean, worst);

    for (int t = 0; t < 3; t++) {
        double th = (double[]){0.1, 0.55, 1.0}[t];
        lf_vec3 wo = dir(th, 0.7);
        double albedo = hemi_integral(m, wo, 0), pdf_mass = pdf_integral(m, wo);
        /* sampling estimate, fixed seed: N = 40000, noise < 0.5 % (3 sigma) for this pdf */
        const int N = 40000;
        double est = 0, est2 = 0;
        int pdf_bad = 0, f_bad = 0, ok = 0;
        for (int k = 0; k < N; k++) {
            lf_vec3 wi, f;
            float pdf;
            if (!lf_measured_sample(m, wo, (float)urand(), (float)urand(), &wi, &f, &pdf))
                continue;
            double v = f.y * wi.z / pdf;
            est += v / N;
            est2 += v * v / N;
            ok++;
            /* the same direction through lf_measured_pdf / _f; near the
             * mirror direction (theta_m -> 0, where the warp's Jacobian
             * vanishes as u^3) float rounding of the half vector shows */
            float p2 = lf_measured_pdf(m, wo, wi);
            pdf_bad += fabs(p2 - pdf) > 1e-2 * pdf;
            lf_vec3 f2 = lf_measured_f(m, wo, wi);
            f_bad += fabs(f2.y - f.y) > 1e-3 * f.y + 1e-7;
        }
        double sd = sqrt(fmax(0, est2 - est * est) / N);
        printf("theta_o %.2f: albedo by quadrature %.4f (Lambertian %.2f), by sampling %.4f +- %.4f, pdf mass %.4f\n",
               th, albedo, RHO, est, sd, pdf_mass);
        CHECK_MSG(fabs(albedo - RHO) < 0.02 * RHO, "quadrature albedo %g, want %g", albedo, RHO);
        CHECK_MSG(fabs(est - albedo) < 3 * sd + 0.003, "sampled albedo %g +- %g, quadrature %g", est, sd, albedo);
        /* the pdf's mass is the probability that a sample succeeds (wi above the horizon) */
        double rate = (double)ok / N, rate_sd = sqrt(rate * (1 - rate) / N);
        CHECK_MSG(pdf_mass <= 1.002 && fabs(pdf_mass - rate) < 3 * rate_sd + 0.003, "pdf mass %g, success rate %g",
                  pdf_mass, rate);
        CHECK_MSG(pdf_bad < N / 200 && f_bad == 0, "%d pdfs and %d values differ from lf_measured_pdf / _f", pdf_bad,
                  f_bad);
    }
}

/* The warp on its own: a 5 x 4 table over 2 x 3 parameter points. */
static void test_warp(void)
{
    float data[2][3][4][5], p0[2] = {0.f, 1.f}, p1[3] = {0.f, 0.5f, 2.f};
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 3; b++)
            for (int y = 0; y < 4; y++)
                for (int x = 0; x < 5; x++)
                    data[a][b][y][x] = (float)(0.2 + urand() * (1 + a + b));
    lf_pl2d t;
    int res[2] = {2, 3};
    const float *vals[2] = {p0, p1};
    CHECK(lf_pl2d_init(&t, &data[0][0][0][0], 5, 4, 2, res, vals, 1) == 0);
    double worst_rt = 0, worst_pdf = 0, worst_eval = 0;
    for (int k = 0; k < 2000; k++) {
        float par[2] = {(float)urand(), (float)(urand() * 2)};
        float ux = (float)urand(), uy = (float)urand(), x = ux, y = uy;
        float pdf = lf_pl2d_sample(&t, &x, &y, par);
        float e = lf_pl2d_eval(&t, x, y, par);
        float ix = x, iy = y;
        float ipdf = lf_pl2d_invert(&t, &ix, &iy, par);
        worst_rt = fmax(worst_rt, fmax(fabs(ix - ux), fabs(iy - uy)));
        worst_pdf = fmax(worst_pdf, fmax(fabs(pdf - e), fabs(ipdf - e)) / e);
        /* the density: the parameter-interpolated table, bilinear, divided by its own integral */
        if (k < 100) {
            int bi = par[1] < 0.5f ? 0 : 1;
            double wa = par[0], wb = bi == 0 ? par[1] / 0.5 : (par[1] - 0.5) / 1.5;
            double gx = x * 4, gy = y * 3;
            int cx = gx >= 4 ? 3 : (int)gx, cy = gy >= 3 ? 2 : (int)gy;
            double fx = gx - cx, fy = gy - cy, want = 0;
            for (int a = 0; a < 2; a++)
                for (int b = 0; b < 2; b++) {
                    double w = (a ? wa : 1 - wa) * (b ? wb : 1 - wb), integral = 0;
                    const float(*s)[5] = data[a][bi + b];
                    for (int yy = 0; yy < 3; yy++)
                        for (int xx = 0; xx < 4; xx++)
                            integral += (s[yy][xx] + s[yy][xx + 1] + s[yy + 1][xx] + s[yy + 1][xx + 1]) / 4.0 / 12.0;
                    double v = (1 - fy) * ((1 - fx) * s[cy][cx] + fx * s[cy][cx + 1]) +
                               fy * ((1 - fx) * s[cy + 1][cx] + fx * s[cy + 1][cx + 1]);
                    want += w * v / integral;
                }
            worst_eval = fmax(worst_eval, fabs(e - want) / want);
        }
    }
    CHECK_MSG(worst_rt < 2e-4, "invert(sample(u)) - u up to %g", worst_rt);
    CHECK_MSG(worst_pdf < 1e-3, "sample / invert / eval densities differ by %g", worst_pdf);
    CHECK_MSG(worst_eval < 1e-4, "density differs from the normalised bilinear table by %g", worst_eval);
    lf_pl2d_free(&t);
}

static void test_material(void)
{
    const char *text = "WorldBegin\nMaterial \"measured\" \"string filename\" \"lambert.bsdf\"\n";
    lf_scene_desc d;
    lf_error err = {0};
    CHECK(lf_scene_parse_string(text, DIR "/scene.pbrt", &d, &err) == 0);
    lf_materials *ms = NULL;
    int rc = lf_materials_build(&d, &ms, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (!rc) {
        lf_shading_ctx c;
        memset(&c, 0, sizeof c);
        c.ns = c.ng = lf_v3(0, 0, 1);
        c.dpdu = lf_v3(1, 0, 0);
        lf_bsdf b;
        lf_material_bsdf(lf_materials_get(ms, 0), &c, &b);
        CHECK(b.kind == LF_LOBE_MEASURED && strcmp(lf_material_type(lf_materials_get(ms, 0)), "measured") == 0);
        lf_vec3 f = lf_bsdf_f(&b, dir(0.3, 0), dir(0.5, 2));
        CHECK_MSG(fabs(f.x * M_PI / RHO - 1) < 0.05 && fabs(f.z * M_PI / RHO - 1) < 0.05, "grey 0.5: %g %g %g", f.x, f.y,
                  f.z);
        test_brdf(b.u.measured.data);
    }
    lf_materials_free(ms);
    lf_scene_desc_free(&d);
    /* errors name the file:line:col of "filename" */
    const char *bad[] = {"WorldBegin\nMaterial \"measured\" \"string filename\" \"nope.bsdf\"\n",
                         "WorldBegin\nMaterial \"measured\" \"string filename\" \"scene.pbrt\"\n",
                         "WorldBegin\nMaterial \"measured\"\n",
                         "WorldBegin\nMaterial \"measured\" \"string filename\" \"trunc.bsdf\"\n"};
    const char *want[] = {"nope.bsdf", "not a tensor file", "filename\" is required", "runs past the end of the file"};
    for (int i = 0; i < 4; i++) {
        CHECK(lf_scene_parse_string(bad[i], DIR "/scene.pbrt", &d, &err) == 0);
        ms = NULL;
        memset(&err, 0, sizeof err);
        rc = lf_materials_build(&d, &ms, &err);
        CHECK_MSG(rc != 0 && strstr(err.msg, "scene.pbrt:2:") && strstr(err.msg, want[i]), "%s", err.msg);
        lf_materials_free(ms);
        lf_scene_desc_free(&d);
    }
}

int main(void)
{
    mkdir(DIR, 0755);
    FILE *s = fopen(DIR "/scene.pbrt", "w");
    if (s)
        fputs("# not a tensor file\n", s), fclose(s);
    CHECK(write_lambertian(DIR "/lambert.bsdf") == 0);
    /* the same file cut inside its field table */
    FILE *in = fopen(DIR "/lambert.bsdf", "rb"), *cut = fopen(DIR "/trunc.bsdf", "wb");
    char head[100];
    if (in && cut && fread(head, 1, sizeof head, in) == sizeof head)
        fwrite(head, 1, sizeof head, cut);
    if (in)
        fclose(in);
    if (cut)
        fclose(cut);
    test_warp();
    test_material();
    return lf_test_end();
}
