/* Issue 17 acceptance: the plenoptic demo refocuses visibly, and its
 * refocusable range is Ng's.
 *
 * The demo scene (scenes/lightfield/plenoptic.pbrt: 12 mm f/2 focused at
 * 0.5 m, 5.76 mm sensor, 9 px per microlens, cards at 0.25, 0.5, 1 m and a
 * wall at 5 m) is rendered through the CLI at a smaller variant: the same
 * sensor and main lens with 240 instead of 320 microlenses (2160 x 1458
 * pixels, still 9 x 9 views) at 2 spp.  The microlens pitch p grows by 4/3,
 * so disparities shrink by 3/4 (near card +0.68 px/view, far card -0.34,
 * wall -0.62).
 *
 * Expected numbers come from the thin-lens design, computed here:
 *   z_i = f z_o / (z_o - f); D = f/N; the matched design's image spacing is
 *   P_m = p (1 + p/D) (docs/lightfield.md), solved for p;
 *   Ng 2005's exact-refocus bound b = P p / (D + p) (P = 9 views; his
 *   P p / D for p << D): alpha in [1/(1+b), 1/(1-b)], depths
 *   1/z = 1/z_o +- b/z_i; disparity of depth z: d = z_i (1/z - 1/z_o) / b;
 *   a point (X, Y, Z) appears in the views at column
 *   s = (X/Z (z_i + f_mla) + w/2) / P_m (the chief ray through the lens centre).
 * Sharpness of a region: mean squared difference of neighbouring pixels'
 * luminance over the squared mean (contrast energy).  Refocused at a card's
 * depth, that card's region must be the sharpest of the four refocused
 * images by a factor >= 1.3 (measured: 1.58 for the wall against the far
 * card, 1.93 and more otherwise; the 2 spp Monte Carlo noise adds about the
 * same small energy to every image, so it only lowers the ratios).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lf_test.h"
#include "lf_test_tools.h"

#define LFRENDER LF_BINARY_DIR "/bin/lfrender"
#define LFTOOL LF_BINARY_DIR "/bin/lftool"

static char dir[256];
static char out_text[65536];

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *s = malloc(1 << 16);
    size_t n = s ? fread(s, 1, (1 << 16) - 1, f) : 0;
    fclose(f);
    if (s)
        s[n] = 0;
    return s;
}

/* replaces the first occurrence of a by b in s (in place, s has room) */
static int edit(char *s, size_t cap, const char *a, const char *b)
{
    char *at = strstr(s, a);
    if (!at)
        return -1;
    size_t la = strlen(a), lb = strlen(b), rest = strlen(at + la);
    if (strlen(s) - la + lb + 1 > cap)
        return -1;
    memmove(at + lb, at + la, rest + 1);
    memcpy(at, b, lb);
    return 0;
}

/* contrast energy of the luminance over [x0,x1) x [y0,y1) */
static double sharpness(const lf_image *im, int x0, int y0, int x1, int y1)
{
    double e = 0, m = 0;
    long n = 0;
    for (int y = y0; y < y1 - 1; y++)
        for (int x = x0; x < x1 - 1; x++) {
            const float *p = lf_image_px(im, x, y), *r = lf_image_px(im, x + 1, y), *d = lf_image_px(im, x, y + 1);
            double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            double lr = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2];
            double ld = 0.2126 * d[0] + 0.7152 * d[1] + 0.0722 * d[2];
            e += (l - lr) * (l - lr) + (l - ld) * (l - ld);
            m += l;
            n++;
        }
    m /= n;
    return e / n / (m * m);
}

int main(void)
{
    lf_test_run_setup(dir, 0, out_text, sizeof out_text);
    snprintf(dir, sizeof dir, "/tmp/lf_plenoptic_demo_XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    /* ---- the demo at a smaller variant ---- */
    char *scene = slurp(LF_SOURCE_DIR "/scenes/lightfield/plenoptic.pbrt");
    CHECK(scene != NULL);
    if (!scene)
        return lf_test_end();
    scene = realloc(scene, 1 << 17);
    CHECK(!edit(scene, 1 << 17, "\"integer microlenses\" [320]", "\"integer microlenses\" [240]"));
    CHECK(!edit(scene, 1 << 17, "\"integer xresolution\" [2880] \"integer yresolution\" [1944]",
                "\"integer xresolution\" [2160] \"integer yresolution\" [1458]"));
    CHECK(!edit(scene, 1 << 17, "\"integer pixelsamples\" [8]", "\"integer pixelsamples\" [2]"));
    CHECK(!edit(scene, 1 << 17, "Include \"cards.pbrt\"", "Include \"" LF_SOURCE_DIR "/scenes/lightfield/cards.pbrt\""));
    char path[512], raw[512];
    snprintf(path, sizeof path, "%s/small.pbrt", dir);
    snprintf(raw, sizeof raw, "%s/raw.exr", dir);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return lf_test_end();
    fputs(scene, f);
    fclose(f);
    free(scene);

    /* ---- the design, computed independently ---- */
    const double fl = 12e-3, N = 2, zo = 0.5, sw = 5.76e-3, Wpx = 2160, Hpx = 1458, count = 240, P = 9;
    double zi = fl * zo / (zo - fl), D = fl / N, Pm = sw / count;
    double p = 0.5 * D * (sqrt(1 + 4 * Pm / D) - 1), fmla = p * zi / D;
    /* P pixels span the microlens' image of the aperture, (D + p) / P of
     * the aperture per view (Ng's P p / D for p << D) */
    double b = P * p / (D + p);
    double a_lo = 1 / (1 + b), a_hi = 1 / (1 - b);
    double z_near = 1 / (1 / zo + b / zi), inv_far = 1 / zo - b / zi;
    printf("design: z_i %.6g mm, p %.6g um, bound b = P p / (D + p) = %.6g: alpha %.6g .. %.6g, depths %.5g m .. %s\n",
           zi * 1e3, p * 1e6, b, a_lo, a_hi, z_near, inv_far > 0 ? "finite" : "infinity");

    /* ---- --explain prints Ng's range ---- */
    CHECK(run("%s %s --explain", LFRENDER, path) == 0);
    const char *r = strstr(out_text, "refocusable range");
    CHECK_MSG(r != NULL, "%s", out_text);
    if (r) {
        double bb = 0, lo = 0, hi = 0, zn = 0;
        const char *q = strstr(r, "P p / (D + p) = ");
        CHECK(q && sscanf(q, "P p / (D + p) = %lf", &bb) == 1);
        q = strstr(r, "alpha ");
        CHECK(q && sscanf(q, "alpha %lf .. %lf", &lo, &hi) == 2);
        q = strstr(r, "depths ");
        CHECK(q && sscanf(q, "depths %lf m ..", &zn) == 1);
        CHECK_NEAR(bb, b, 1e-3 * b);
        CHECK_NEAR(lo, a_lo, 1e-5);
        CHECK_NEAR(hi, a_hi, 1e-5);
        CHECK_NEAR(zn, z_near, 1e-3 * z_near);
        CHECK(inv_far <= 0 ? strstr(r, ".. infinity") != NULL : strstr(r, ".. infinity") == NULL);
    }

    /* ---- render and refocus at each subject ---- */
    CHECK(run("%s %s --threads 2 -o %s", LFRENDER, path, raw) == 0);
    struct {
        const char *name;
        double z, X0, X1, Y0, Y1; /* camera-space corners of the subject */
    } subj[4] = {
        {"near card", 0.25, -0.0537, -0.021, -0.0331, 0.0079},
        {"middle card", 0.5, -0.0327, 0.0327, -0.0473, 0.0441},
        {"far card", 1.0, 0.0841, 0.2148, -0.0504, 0.1324},
        {"wall", 5.0, 0, 0, 0, 0},
    };
    lf_image img[4];
    memset(img, 0, sizeof img);
    for (int k = 0; k < 4; k++) {
        char out[512];
        snprintf(out, sizeof out, "%s/refocus%d.exr", dir, k);
        CHECK(run("%s refocus %s --depth %g -o %s", LFTOOL, raw, subj[k].z, out) == 0);
        /* the disparity lftool used, against the design's */
        double d = 0, want = zi * (1 / subj[k].z - 1 / zo) / b;
        const char *q = strstr(out_text, "refocused at disparity ");
        CHECK(q && sscanf(q, "refocused at disparity %lf", &d) == 1);
        CHECK_NEAR(d, want, 1e-6 + 1e-6 * fabs(want));
        CHECK(strstr(out_text, "warning") == NULL); /* every subject is inside the range */
        lf_error err = {0};
        CHECK(lf_image_read(out, &img[k], NULL, &err) == 0);
        CHECK(img[k].width == count && img[k].height == (int)(Hpx / P + 0.5));
    }
    /* a depth nearer than the range: a warning, still exit 0 */
    {
        char out[512];
        snprintf(out, sizeof out, "%s/tooclose.exr", dir);
        double z = 0.8 * z_near;
        CHECK(run("%s refocus %s --depth %g -o %s", LFTOOL, raw, z, out) == 0);
        CHECK_MSG(strstr(out_text, "warning") && strstr(out_text, "outside the refocusable range"), "%s", out_text);
        char lim[64];
        snprintf(lim, sizeof lim, "depths %.4g m", z_near);
        CHECK_MSG(strstr(out_text, lim) != NULL, "%s (want %s)", out_text, lim);
        /* and just inside it: no warning */
        CHECK(run("%s refocus %s --depth %g -o %s", LFTOOL, raw, 1.02 * z_near, out) == 0);
        CHECK(strstr(out_text, "warning") == NULL);
    }
    if (img[0].data && img[1].data && img[2].data && img[3].data) {
        double Zs = zi + fmla, sh = sw * Hpx / Wpx;
        double S[4][4];
        for (int c = 0; c < 4; c++) {
            int x0, x1, y0, y1;
            if (c == 3) { /* wall: the strip above the near card, left of the middle card */
                x0 = 4, x1 = (int)(0.3 * count), y0 = 4, y1 = (int)(0.25 * img[0].height);
            } else {
                double s0 = (subj[c].X0 / subj[c].z * Zs + sw / 2) / Pm, s1 = (subj[c].X1 / subj[c].z * Zs + sw / 2) / Pm;
                double t0 = (-subj[c].Y1 / subj[c].z * Zs + sh / 2) / Pm, t1 = (-subj[c].Y0 / subj[c].z * Zs + sh / 2) / Pm;
                /* inset by 4 view pixels: the blurred border of a defocused card is not its texture */
                x0 = (int)ceil(s0) + 4, x1 = (int)floor(s1) - 4, y0 = (int)ceil(t0) + 4, y1 = (int)floor(t1) - 4;
            }
            CHECK(x0 >= 0 && x1 <= img[0].width && y0 >= 0 && y1 <= img[0].height && x1 - x0 > 8 && y1 - y0 > 8);
            for (int k = 0; k < 4; k++)
                S[c][k] = sharpness(&img[k], x0, y0, x1, y1);
            printf("%-12s (%g m) region [%d,%d)x[%d,%d): sharpness refocused at 0.25/0.5/1/5 m: %.4g %.4g %.4g %.4g\n",
                   subj[c].name, subj[c].z, x0, x1, y0, y1, S[c][0], S[c][1], S[c][2], S[c][3]);
        }
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 4; k++)
                if (k != c)
                    CHECK_MSG(S[c][c] >= 1.3 * S[c][k], "%s: refocused at its depth %.4g, at %g m %.4g", subj[c].name,
                              S[c][c], subj[k].z, S[c][k]);
    }
    for (int k = 0; k < 4; k++)
        lf_image_free(&img[k]);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return lf_test_end();
}
