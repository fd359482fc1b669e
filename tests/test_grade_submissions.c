/* lfgrade's core on submissions the test builds itself (docs/grading.md):
 * a correct submission rendered at the required sample count passes; each
 * mutant loses the right check with the right reason; bad and hostile
 * submissions are reported, nothing outside the submission is read or run. */
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "camera/lf_camera.h"
#include "grade/lf_grade.h"
#include "lightfield/lf_lightfield.h"
#include "lf_test.h"

static char tmp[256];

static void write_text(const char *dir, const char *name, const char *text)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "wb");
    if (f) {
        fwrite(text, 1, strlen(text), f);
        fclose(f);
    }
}

static void write_bytes(const char *dir, const char *name, const void *d, size_t n)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "wb");
    if (f) {
        fwrite(d, 1, n, f);
        fclose(f);
    }
}

static char *new_sub(const char *name)
{
    static char p[16][512];
    static int k;
    char *d = p[k++ % 16];
    snprintf(d, 512, "%s/%s", tmp, name);
    mkdir(d, 0755);
    return d;
}

/* a student's render: the assignment's scene, another seed */
static int render_to(const char *scene, const lf_grade_edit *e, int ne, int spp, const char *post, const char *dir,
                     const char *name)
{
    lf_image img;
    lf_attrs meta = {0};
    lf_error err = {0};
    if (lf_grade_render(scene, e, ne, spp, 77, 2, &img, &meta, &err)) {
        fprintf(stderr, "render %s: %s\n", scene, err.msg);
        return -1;
    }
    if (post)
        lf_grade_post(post, &img, &err);
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    int rc = lf_image_write(p, &img, &meta, NULL, &err);
    lf_image_free(&img), lf_attrs_free(&meta);
    return rc;
}

static const lf_grade_check_result *check(const lf_grade_result *r, const char *id)
{
    for (int i = 0; i < r->nchecks; i++)
        if (!strcmp(r->checks[i].id, id))
            return &r->checks[i];
    static lf_grade_check_result none;
    snprintf(none.reason, sizeof none.reason, "(no check %s)", id);
    none.status = LF_GRADE_FAIL;
    return &none;
}

static int grade(lf_grade_ctx *g, const char *dir, lf_grade_result *r)
{
    lf_error err = {0};
    int rc = lf_grade_submission(g, dir, r, &err);
    /* the measured statistics, for docs/grading.md */
    for (int i = 0; !rc && i < r->nchecks; i++)
        if (isfinite(r->checks[i].noise_ratio))
            printf("  %-18s %-12s ratio %6.2f  ssim %.3f (refs %.3f)%s%s\n", r->student, r->checks[i].id,
                   r->checks[i].noise_ratio, r->checks[i].ssim, r->checks[i].ssim_noise,
                   r->checks[i].best_variant[0] ? "  closest mistake: " : "", r->checks[i].best_variant);
    CHECK_MSG(rc == 0, "grader error on %s: %s", dir, err.msg);
    return rc;
}

#define EXPECT_PASS(r, id)                                                                                \
    CHECK_MSG(check(&(r), id)->status == LF_GRADE_PASS, "%s: %s should pass: %s (ratio %.2f) OK", (r).student, id, \
              check(&(r), id)->reason, check(&(r), id)->noise_ratio)
#define EXPECT_FAIL(r, id, text)                                                                          \
    CHECK_MSG(check(&(r), id)->status == LF_GRADE_FAIL && strstr(check(&(r), id)->reason, text),          \
              "%s: %s should fail with \"%s\", got: %s (ratio %.2f)", (r).student, id, text, check(&(r), id)->reason, \
              check(&(r), id)->noise_ratio)

static const char *md_ok = "# Submission\n## Answers\nThe blur circle grows as 1/d - 1/z.\n"
                           "## Commands\n```sh\nlfrender bokeh.pbrt --spp 64 -o bokeh.png\n```\n";

static void thinlens(void)
{
    lf_grade_opts o = lf_grade_opts_default();
    char cache[300];
    snprintf(cache, sizeof cache, "%s/cache", tmp);
    o.cache_dir = cache;
    o.threads = 2;
    lf_grade_ctx *g;
    lf_error err = {0};
    if (lf_grade_ctx_new("assignments/1-thinlens", &o, &g, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return;
    }
    const char *bokeh = "assignments/1-thinlens/scenes/bokeh.pbrt", *flat = "assignments/1-thinlens/scenes/flatfield.pbrt";
    /* correct, at the required 64 and 16 spp (PNG and EXR) */
    char *ok = new_sub("t-correct");
    render_to(bokeh, NULL, 0, 64, NULL, ok, "bokeh.png");
    render_to(flat, NULL, 0, 16, NULL, ok, "flatfield.exr");
    write_text(ok, "Submission.md", md_ok);
    lf_grade_result r;
    if (!grade(g, ok, &r)) {
        CHECK_MSG(r.score == r.max && r.max == 25, "correct submission: %d/%d", r.score, r.max);
        EXPECT_PASS(r, "bokeh");
        EXPECT_PASS(r, "flatfield");
        lf_grade_result_free(&r);
    }
    /* mutant: focus distance off by 5% */
    char *m = new_sub("t-focus");
    lf_grade_edit e = {"\"float focusdistance\" [0.25]", "\"float focusdistance\" [0.2625]"};
    render_to(bokeh, &e, 1, 64, NULL, m, "bokeh.png");
    render_to(flat, NULL, 0, 16, NULL, m, "flatfield.exr");
    write_text(m, "Submission.md", md_ok);
    if (!grade(g, m, &r)) {
        EXPECT_FAIL(r, "bokeh", "focus distance off by +");
        EXPECT_FAIL(r, "bokeh", "the lens focused at 0.26");
        EXPECT_PASS(r, "flatfield");
        CHECK(r.score == 15);
        lf_grade_result_free(&r);
    }
    /* mutant: missing cos^4 falloff (the right image divided by cos^4 of the chief ray) */
    m = new_sub("t-cos4");
    render_to(bokeh, NULL, 0, 64, NULL, m, "bokeh.png");
    render_to(flat, NULL, 0, 16, "no_cos4:0.512486", m, "flatfield.png");
    write_text(m, "Submission.md", md_ok);
    if (!grade(g, m, &r)) {
        EXPECT_FAIL(r, "flatfield", "missing cos^4 falloff");
        EXPECT_PASS(r, "bokeh");
        lf_grade_result_free(&r);
    }
    /* mutant: an image of the wrong size */
    m = new_sub("t-size");
    lf_image small;
    lf_image_alloc(&small, 32, 24, 3, &err);
    char p[512];
    snprintf(p, sizeof p, "%s/bokeh.png", m);
    lf_image_write(p, &small, NULL, NULL, &err);
    lf_image_free(&small);
    render_to(flat, NULL, 0, 16, NULL, m, "flatfield.exr");
    write_text(m, "Submission.md", md_ok);
    if (!grade(g, m, &r)) {
        EXPECT_FAIL(r, "bokeh-size", "wrong size: 32x24, expected 64x48");
        EXPECT_FAIL(r, "bokeh", "wrong size");
        EXPECT_PASS(r, "flatfield");
        lf_grade_result_free(&r);
    }

    /* ---- bad and hostile submissions: each reported, nothing crashes ---- */
    struct {
        const char *name, *check, *text;
    } cases[] = {
        {"h-missing", "files", "missing: neither bokeh.png nor bokeh.exr"},
        {"h-empty", "bokeh", "empty file"},
        {"h-corrupt-png", "bokeh", "bokeh.png"},
        {"h-truncated-exr", "bokeh", "bokeh.exr"},
        {"h-huge-png", "bokeh", "claims 100000 x 100000"},
        {"h-huge-exr", "bokeh", "claims 100000 x 100000"},
        {"h-nan", "bokeh", "NaN/Inf"},
        {"h-symlink", "bokeh", "outside the submission (not followed)"},
        {"h-fifo", "bokeh", "not a regular file"},
        {"h-nomd", "handout", "Submission.md: missing"},
        {"h-wrongmagic", "bokeh", "neither a PNG nor an OpenEXR"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        char *d = new_sub(cases[k].name);
        if (strcmp(cases[k].name, "h-nomd"))
            write_text(d, "Submission.md", md_ok);
        render_to(flat, NULL, 0, 16, NULL, d, "flatfield.exr");
        const char *n = cases[k].name;
        if (!strcmp(n, "h-empty"))
            write_bytes(d, "bokeh.png", "", 0);
        else if (!strcmp(n, "h-corrupt-png")) {
            unsigned char b[64] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                   0,    0,   0,   64,  0,    0,    0,    48,   8, 2};
            for (int i = 26; i < 64; i++)
                b[i] = (unsigned char)(i * 37);
            write_bytes(d, "bokeh.png", b, sizeof b);
        } else if (!strcmp(n, "h-truncated-exr")) {
            char src[512];
            snprintf(src, sizeof src, "%s/flatfield.exr", d);
            FILE *f = fopen(src, "rb");
            unsigned char buf[4096];
            size_t got = f ? fread(buf, 1, sizeof buf, f) : 0;
            if (f)
                fclose(f);
            write_bytes(d, "bokeh.exr", buf, got > 600 ? 600 : got / 2);
        } else if (!strcmp(n, "h-huge-png")) {
            unsigned char b[33] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                   0,    1,   0x86, 0xa0, 0, 1, 0x86, 0xa0, 8, 2};
            write_bytes(d, "bokeh.png", b, sizeof b);
        } else if (!strcmp(n, "h-huge-exr")) {
            unsigned char b[128] = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
            size_t q = 8;
            memcpy(b + q, "dataWindow\0box2i\0", 17), q += 17;
            int32_t v[5] = {16, 0, 0, 99999, 99999};
            memcpy(b + q, v, sizeof v), q += sizeof v;
            b[q++] = 0;
            write_bytes(d, "bokeh.exr", b, q);
        } else if (!strcmp(n, "h-nan")) {
            lf_image img;
            lf_image_alloc(&img, 64, 48, 3, &err);
            img.data[5] = NAN, img.data[100] = INFINITY;
            lf_write_opts wo = {0};
            wo.allow_nonfinite = 1;
            snprintf(p, sizeof p, "%s/bokeh.exr", d);
            lf_image_write(p, &img, NULL, &wo, &err);
            lf_image_free(&img);
        } else if (!strcmp(n, "h-symlink")) {
            snprintf(p, sizeof p, "%s/bokeh.png", d);
            CHECK(symlink("/etc/passwd", p) == 0);
        } else if (!strcmp(n, "h-fifo")) {
            snprintf(p, sizeof p, "%s/bokeh.png", d);
            CHECK(mkfifo(p, 0600) == 0);
        } else if (!strcmp(n, "h-wrongmagic")) {
            write_text(d, "bokeh.png", "#!/bin/sh\necho hello\n");
        }
        if (!grade(g, d, &r)) {
            EXPECT_FAIL(r, cases[k].check, cases[k].text);
            CHECK_MSG(r.score < r.max, "%s scored %d/%d", n, r.score, r.max);
            lf_grade_result_free(&r);
        }
    }
    /* a symlink inside the submission is followed */
    char *d = new_sub("h-symlink-inside");
    render_to(bokeh, NULL, 0, 64, NULL, d, "real.png");
    render_to(flat, NULL, 0, 16, NULL, d, "flatfield.exr");
    write_text(d, "Submission.md", md_ok);
    snprintf(p, sizeof p, "%s/bokeh.png", d);
    CHECK(symlink("real.png", p) == 0);
    if (!grade(g, d, &r)) {
        EXPECT_PASS(r, "bokeh");
        lf_grade_result_free(&r);
    }
    /* a folder that does not exist */
    snprintf(p, sizeof p, "%s/nobody", tmp);
    if (!grade(g, p, &r)) {
        CHECK(r.score == 0 && strstr(r.checks[0].reason, "not a folder"));
        lf_grade_result_free(&r);
    }
    lf_grade_ctx_release(g);
}

/* The student's Part 2: lftool synth's meaning on their own light field. */
static void student_synth(const char *dir, const char *lfname, double lens_radius, const char *out)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, lfname);
    lf_image raw;
    lf_attrs a = {0};
    lf_error err = {0};
    lf_lightfield_layout file, flags, lay;
    lf_lightfield_layout_init(&flags);
    lf_lightfield lf;
    memset(&lf, 0, sizeof lf);
    if (lf_image_read(p, &raw, &a, &err) || lf_lightfield_layout_from_attrs(&a, &file, &err) ||
        lf_lightfield_layout_resolve(&file, &flags, raw.width, raw.height, &lay, &err) ||
        lf_lightfield_decode(&raw, &lay, NULL, &lf, &err)) {
        CHECK_MSG(0, "student synth: %s", err.msg);
        return;
    }
    lf_lightfield_synth_opts s = lf_lightfield_synth_defaults();
    s.width = 96, s.height = 72, s.fov_deg = 30;
    s.pos[0] = 0.03, s.pos[1] = 0.05, s.pos[2] = 0;
    s.lens_radius = lens_radius;
    s.focal_distance = 2.5;
    s.spp = 64;
    s.seed = 99;
    lf_image img;
    if (!lf_lightfield_synth(&lf, &s, &img, NULL, NULL, &err)) {
        snprintf(p, sizeof p, "%s/%s", dir, out);
        lf_image_write(p, &img, NULL, NULL, &err);
        lf_image_free(&img);
    }
    lf_lightfield_free(&lf);
    lf_image_free(&raw);
    lf_attrs_free(&a);
}


/* Part 3: a student's lftool refocus of their own plenoptic render at
 * disparity d (aperture < 0: every view) */
static void student_refocus(const char *dir, const char *rawname, double d, double aperture, const char *out)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, rawname);
    lf_image raw;
    lf_attrs a = {0};
    lf_error err = {0};
    lf_lightfield_layout file, flags, lay;
    lf_lightfield_layout_init(&flags);
    lf_lightfield lf;
    memset(&lf, 0, sizeof lf);
    if (lf_image_read(p, &raw, &a, &err) || lf_lightfield_layout_from_attrs(&a, &file, &err) ||
        lf_lightfield_layout_resolve(&file, &flags, raw.width, raw.height, &lay, &err) ||
        lf_lightfield_decode(&raw, &lay, NULL, &lf, &err)) {
        CHECK_MSG(0, "student refocus: %s", err.msg);
        return;
    }
    lf_lightfield_refocus_opts o = lf_lightfield_refocus_defaults();
    o.disparity_px = d;
    if (aperture >= 0)
        o.aperture_radius = aperture;
    lf_image img;
    if (!lf_lightfield_refocus(&lf, &o, &img, &err)) {
        snprintf(p, sizeof p, "%s/%s", dir, out);
        lf_image_write(p, &img, NULL, NULL, &err);
        lf_image_free(&img);
    }
    lf_lightfield_free(&lf);
    lf_image_free(&raw);
    lf_attrs_free(&a);
}

/* Disparity (px per view step) of depth z in assignments/4-lightfield/scenes/
 * plenoptic.pbrt, from its design (docs/lightfield.md): f = 25 mm f/2
 * focused at 0.5 m, 96 microlenses of 9 px over 5.76 mm, matched:
 * P_m = p (1 + p/D); d = z_i (1/z - 1/z_o) D / (9 p). */
static double a4_disparity(double z)
{
    double f = 25e-3, D = f / 2, zo = 0.5, zi = f * zo / (zo - f), Pm = 5.76e-3 / 96;
    double p = 0.5 * D * (sqrt(1 + 4 * Pm / D) - 1);
    return zi * (1 / z - 1 / zo) * D / (9 * p);
}

/* the depth in "looks focused at X m" of a reason */
static double looks_focused_at(const char *reason)
{
    const char *q = strstr(reason, "looks focused at ");
    double z = NAN;
    if (!q || sscanf(q, "looks focused at %lf", &z) != 1)
        return NAN;
    return z;
}

static const char *md_lf =
    "# Submission\n## Answers\nRays meet the camera plane between four data cameras.\n## Commands\n"
    "lfrender lightfield.pbrt --spp 16 -o lightfield.exr\n"
    "`lftool synth lightfield.exr novel.png --camerapos 0.03 0.05 0 --lensradius %s --focaldistance 2.5 "
    "--samplesperpixel 64 --outputdim 96 72 --outputfov 30`\n"
    "lftool refocus plenoptic.exr --depth 0.3 -o refocused.png\n";

static void lightfield(void)
{
    lf_grade_opts o = lf_grade_opts_default();
    char cache[300];
    snprintf(cache, sizeof cache, "%s/cache", tmp);
    o.cache_dir = cache;
    o.threads = 2;
    lf_grade_ctx *g;
    lf_error err = {0};
    if (lf_grade_ctx_new("assignments/4-lightfield", &o, &g, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return;
    }
    const char *scene = "assignments/4-lightfield/scenes/lightfield.pbrt";
    char md[1024];
    lf_grade_result r;
    /* correct */
    char *ok = new_sub("l-correct");
    render_to(scene, NULL, 0, 16, NULL, ok, "lightfield.exr");
    student_synth(ok, "lightfield.exr", 0.1, "novel.png");
    const char *pscene = "assignments/4-lightfield/scenes/plenoptic.pbrt";
    render_to(pscene, NULL, 0, 8, NULL, ok, "plenoptic.exr");
    student_refocus(ok, "plenoptic.exr", a4_disparity(0.3), -1, "refocused.png");
    snprintf(md, sizeof md, md_lf, "0.1");
    write_text(ok, "Submission.md", md);
    if (!grade(g, ok, &r)) {
        EXPECT_PASS(r, "lightfield");
        EXPECT_PASS(r, "novel");
        EXPECT_PASS(r, "lensradius");
        EXPECT_PASS(r, "refocused");
        CHECK_MSG(r.score == r.max && r.max == 25, "correct submission: %d/%d", r.score, r.max);
        double z = looks_focused_at(check(&r, "refocused")->measurements);
        CHECK_MSG(fabs(z - 0.3) < 0.03, "estimated focus %g m, refocused at 0.3 m", z);
        lf_grade_result_free(&r);
    }
    /* Part 3 mutants, each refocused from the correct submission's raw:
     * not refocused (the plain mean of the views), refocused at the far card,
     * at +10 % of the asked depth, and with a pinhole aperture (one view) */
    struct {
        const char *name;
        double d, aperture;
        const char *reason, *reason2;
        double looks; /* expected focus estimate (m), 0: not asserted */
    } p3[] = {
        {"l-unrefocused", 0.0, -1, "the near card at 0.3 m is not in focus: sharpness 0.", "not refocused, the plain average", 0.5},
        {"l-far", a4_disparity(1.2), -1, "the near card at 0.3 m is not in focus", "looks focused at", 1.2},
        {"l-focus10", a4_disparity(0.33), -1, "focused near but not at the near card", "% in depth", 0.33},
        {"l-focus-10", a4_disparity(0.27), -1, "focused near but not at the near card", "% in depth", 0.27},
        {"l-pinhole-refocus", a4_disparity(0.3), 0, "more depth of field than asked", "sharper than any full-aperture", 0},
    };
    for (size_t k = 0; k < sizeof p3 / sizeof *p3; k++) {
        char *q = new_sub(p3[k].name), rel[600];
        snprintf(rel, sizeof rel, "../%s/refocused.png", p3[k].name);
        student_refocus(ok, "plenoptic.exr", p3[k].d, p3[k].aperture, rel);
        write_text(q, "Submission.md", md);
        if (!grade(g, q, &r)) {
            EXPECT_FAIL(r, "refocused", p3[k].reason);
            EXPECT_FAIL(r, "refocused", p3[k].reason2);
            if (p3[k].looks > 0) {
                double z = looks_focused_at(check(&r, "refocused")->reason);
                CHECK_MSG(fabs(z / p3[k].looks - 1) < 0.04, "%s: estimated focus %g m, refocused at %g m", p3[k].name,
                          z, p3[k].looks);
            }
            printf("  %-18s refocused: %s\n", p3[k].name, check(&r, "refocused")->reason);
            lf_grade_result_free(&r);
        }
    }
    /* tiles in the wrong order (the grid flipped left-right) */
    char *m = new_sub("l-flipped");
    render_to(scene, NULL, 0, 16, "flip_tiles:4:4:h", m, "lightfield.exr");
    student_synth(ok, "lightfield.exr", 0.1, "../l-flipped/novel.png");
    write_text(m, "Submission.md", md);
    if (!grade(g, m, &r)) {
        EXPECT_FAIL(r, "lightfield", "tiles in the wrong order: the camera grid is flipped left-right");
        EXPECT_PASS(r, "novel");
        lf_grade_result_free(&r);
    }
    /* FOV off by 2 degrees */
    m = new_sub("l-fov");
    lf_grade_edit e = {"\"float fov\" [30]", "\"float fov\" [32]"};
    render_to(scene, &e, 1, 16, NULL, m, "lightfield.exr");
    student_synth(ok, "lightfield.exr", 0.1, "../l-fov/novel.png");
    write_text(m, "Submission.md", md);
    if (!grade(g, m, &r)) {
        EXPECT_FAIL(r, "lightfield", "field of view off by +");
        EXPECT_FAIL(r, "lightfield", "matches fov 3");
        lf_grade_result_free(&r);
    }
    /* lens radius 0 where blur is required (declared and used) */
    m = new_sub("l-pinhole");
    render_to(scene, NULL, 0, 16, NULL, m, "lightfield.exr");
    student_synth(m, "lightfield.exr", 0, "novel.png");
    snprintf(md, sizeof md, md_lf, "0");
    write_text(m, "Submission.md", md);
    if (!grade(g, m, &r)) {
        EXPECT_FAIL(r, "lensradius", "the lens radius must be > 0 (--lensradius is 0");
        EXPECT_PASS(r, "novel");
        lf_grade_result_free(&r);
    }
    /* declared 0.02 but rendered as a pinhole */
    m = new_sub("l-pinhole-image");
    render_to(scene, NULL, 0, 16, NULL, m, "lightfield.exr");
    student_synth(m, "lightfield.exr", 0, "novel.png");
    snprintf(md, sizeof md, md_lf, "0.1");
    write_text(m, "Submission.md", md);
    if (!grade(g, m, &r)) {
        EXPECT_PASS(r, "lensradius");
        EXPECT_FAIL(r, "novel", "no depth of field");
        lf_grade_result_free(&r);
    }
    /* shell injection in the commands: read as data, never run */
    char pwned[512];
    snprintf(pwned, sizeof pwned, "%s/PWNED", tmp);
    const char *attacks[] = {"0.1; touch %s", "$(touch %s)", "`touch %s`", "0.1 | tee %s", "0.1 && touch %s"};
    for (size_t k = 0; k < sizeof attacks / sizeof *attacks; k++) {
        char arg[700], mdx[2048];
        snprintf(arg, sizeof arg, attacks[k], pwned);
        snprintf(mdx, sizeof mdx, md_lf, arg);
        m = new_sub("l-inject");
        write_text(m, "Submission.md", mdx);
        if (!grade(g, m, &r)) {
            EXPECT_FAIL(r, "lensradius", "shell syntax");
            EXPECT_FAIL(r, "novel", "never run");
            lf_grade_result_free(&r);
        }
        CHECK_MSG(access(pwned, F_OK) != 0, "attack %zu created %s", k, pwned);
    }
    lf_grade_ctx_release(g);
}

static void units(void)
{
    char **v;
    int n;
    lf_error why = {0};
    CHECK(lf_grade_tokenize("lftool synth a.exr 'b c.png' --lensradius 0.1", &v, &n, &why) == 0);
    if (n == 6) {
        CHECK(!strcmp(v[3], "b c.png") && !strcmp(v[4], "--lensradius"));
    } else {
        CHECK_MSG(0, "%d tokens", n);
    }
    lf_grade_free_argv(v, n);
    CHECK(lf_grade_tokenize("lftool synth a.exr > /etc/x", &v, &n, &why) == LF_ERR_PARSE && strstr(why.msg, "shell syntax '>'"));
    /* the tile flip is an involution and moves tile (0,0) to (nx-1,0) */
    lf_image img;
    lf_error err = {0};
    lf_image_alloc(&img, 8, 4, 1, &err);
    for (int i = 0; i < 32; i++)
        img.data[i] = (float)i;
    lf_grade_post("flip_tiles:4:2:h", &img, &err);
    CHECK(lf_image_px(&img, 6, 0)[0] == 0.0f && lf_image_px(&img, 7, 1)[0] == 9.0f);
    lf_grade_post("flip_tiles:4:2:h", &img, &err);
    CHECK(lf_image_px(&img, 7, 3)[0] == 31.0f);
    lf_image_free(&img);
}

/* The starter code builds against the public camera header alone, loads as
 * a plugin, renders, and (being a pinhole until the TODOs are done) loses
 * both image checks, named as what it is (test_grade_mistakes checks the
 * brightness factors). */
static void starter(void)
{
    if (system("cc --version > /dev/null 2>&1")) {
        printf("  (no cc: starter plugin build not tested)\n");
        return;
    }
    char so[400], cmd[1200], errbuf[256];
    snprintf(so, sizeof so, "%s/libmythinlens.so", tmp);
    snprintf(cmd, sizeof cmd, "cc -shared -fPIC -O2 -Wall -Wextra -Werror -I camera "
             "assignments/1-thinlens/starter/mythinlens.c -o %s -lm", so);
    CHECK(system(cmd) == 0);
    CHECK_MSG(lf_camera_load_plugin(so, errbuf, sizeof errbuf) == 0, "%s", errbuf);
    CHECK(lf_camera_find("mythinlens") != NULL);
    char *d = new_sub("s-starter");
    lf_grade_edit e = {"Camera \"thinlens\"", "Camera \"mythinlens\""};
    CHECK(render_to("assignments/1-thinlens/scenes/bokeh.pbrt", &e, 1, 64, NULL, d, "bokeh.png") == 0);
    CHECK(render_to("assignments/1-thinlens/scenes/flatfield.pbrt", &e, 1, 16, NULL, d, "flatfield.png") == 0);
    write_text(d, "Submission.md", md_ok);
    lf_grade_opts o = lf_grade_opts_default();
    char cache[300];
    snprintf(cache, sizeof cache, "%s/cache", tmp);
    o.cache_dir = cache;
    o.threads = 2;
    lf_grade_ctx *g;
    lf_error err = {0};
    lf_grade_result r;
    if (!lf_grade_ctx_new("assignments/1-thinlens", &o, &g, &err)) {
        if (!grade(g, d, &r)) {
            EXPECT_FAIL(r, "bokeh", "no defocus blur (a pinhole image");
            /* the 8-bit flat field is white all over (82x too bright) */
            EXPECT_FAIL(r, "flatfield", "over-exposed: 100% of the pixels clipped at white, at least ");
            lf_grade_result_free(&r);
        }
        lf_grade_ctx_release(g);
    }
}

int main(void)
{
    snprintf(tmp, sizeof tmp, "/tmp/lf_grade_XXXXXX");
    if (!mkdtemp(tmp))
        return 1;
    units();
    thinlens();
    lightfield();
    starter();
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
    if (system(cmd)) {
    }
    return lf_test_end();
}
