/* lfrender as a user runs it: exit codes, messages, atomic outputs,
 * metadata, --explain, --crop, --camera-plugin. */
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

static char dir[256];
static char out_text[65536];

static int exists(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0;
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    fputs(text, f);
    fclose(f);
}

static int count_lines(const char *s)
{
    int n = 0;
    for (; *s; s++)
        n += *s == '\n';
    return n;
}

/* A usage error is the message and one line saying where help is (issue 33):
 * exit 2, two lines, the second naming --help. */
static int usage_error_shape(void)
{
    const char *nl = strchr(out_text, '\n');
    return count_lines(out_text) == 2 && nl && strstr(nl, "--help` for usage.") != NULL;
}

static const char *scene_ok =
    "LookAt 0 0 -3 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" [40]\n"
    "Film \"rgb\" \"integer xresolution\" [32] \"integer yresolution\" [24] \"bool savefp16\" false\n"
    "Sampler \"zsobol\" \"integer pixelsamples\" [4]\n"
    "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\nShape \"sphere\"\n";

int main(void)
{
    lf_test_run_setup(dir, 0, out_text, sizeof out_text);
    snprintf(dir, sizeof dir, "/tmp/lf_cli_XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    char scene[512], bad[512], out[512], png[512];
    snprintf(scene, sizeof scene, "%s/ok.pbrt", dir);
    snprintf(bad, sizeof bad, "%s/bad.pbrt", dir);
    snprintf(out, sizeof out, "%s/o.exr", dir);
    snprintf(png, sizeof png, "%s/o.png", dir);
    write_file(scene, scene_ok);

    CHECK(run("%s --help", LF_LFRENDER) == 0);
    CHECK(strstr(out_text, "usage: lfrender") != NULL);
    CHECK(run("%s", LF_LFRENDER) == 2);
    CHECK(run("%s %s --spp abc", LF_LFRENDER, scene) == 2);
    CHECK(strstr(out_text, "--spp") != NULL);
    CHECK(run("%s %s --bogus", LF_LFRENDER, scene) == 2);
    CHECK_MSG(usage_error_shape(), "message: %s", out_text);
    CHECK(run("%s %s --spp 0", LF_LFRENDER, scene) == 2);
    CHECK_MSG(usage_error_shape() && strstr(out_text, "--spp"), "message: %s", out_text);
    CHECK(run("%s merge a.exr", LF_LFRENDER) == 2); /* -o missing: the subcommand's help is named */
    CHECK_MSG(usage_error_shape() && strstr(out_text, "lfrender merge --help"), "message: %s", out_text);
    CHECK(run("%s %s --sped 4", LF_LFRENDER, scene) == 2); /* one edit from --seed */
    CHECK_MSG(usage_error_shape() && strstr(out_text, "did you mean --seed?"), "message: %s", out_text);
    CHECK(run("%s %s --zzzzzz 4", LF_LFRENDER, scene) == 2); /* nothing near: no guess */
    CHECK_MSG(!strstr(out_text, "did you mean"), "message: %s", out_text);
    /* --man: raw roff when stdout is not a terminal; every help names it */
    CHECK(run("%s --man", LF_LFRENDER) == 0 && strncmp(out_text, ".TH lfrender 1", 14) == 0);
    CHECK(run("%s merge --man", LF_LFRENDER) == 0 && strncmp(out_text, ".TH lfrender 1", 14) == 0);
    CHECK(run("%s merge --help", LF_LFRENDER) == 0 && strstr(out_text, "--man"));
    /* --threads 0 means all cores, as in lftool and lfgrade */
    CHECK(run("%s %s --threads 0 --explain", LF_LFRENDER, scene) == 0);

    /* a good render: EXR with metadata, PNG */
    CHECK(run("%s %s -o %s --seed 7 --threads 2 --quiet", LF_LFRENDER, scene, out) == 0);
    lf_image img;
    lf_attrs a = {0};
    lf_error err = {0};
    CHECK_MSG(lf_image_read(out, &img, &a, &err) == 0, "%s", err.msg);
    if (!err.code) {
        CHECK(img.width == 32 && img.height == 24);
        const lf_attr *spp = lf_attrs_get(&a, "lensfield:spp"), *seed = lf_attrs_get(&a, "lensfield:seed");
        const lf_attr *cam = lf_attrs_get(&a, "lensfield:camera"), *t = lf_attrs_get(&a, "lensfield:render_time_s");
        CHECK(spp && spp->type == LF_ATTR_INT && spp->i == 4);
        CHECK(seed && seed->type == LF_ATTR_INT && seed->i == 7);
        CHECK(cam && cam->type == LF_ATTR_STRING && strcmp(cam->s, "perspective") == 0);
        CHECK(t && t->d >= 0);
        /* the background is the environment: exactly 0.5 */
        CHECK_NEAR(lf_image_px(&img, 0, 0)[0], 0.5, 1e-6);
        lf_image_free(&img);
    }
    lf_attrs_free(&a);
    CHECK(run("%s %s -o %s --quiet", LF_LFRENDER, scene, png) == 0);
    CHECK(exists(png));

    /* --crop: only the requested pixels, same values as the full render */
    char crop[512];
    snprintf(crop, sizeof crop, "%s/crop.exr", dir);
    CHECK(run("%s %s -o %s --seed 7 --crop 8 20 4 16 --quiet", LF_LFRENDER, scene, crop) == 0);
    lf_image full, part;
    if (lf_image_read(out, &full, NULL, &err) == 0 && lf_image_read(crop, &part, NULL, &err) == 0) {
        CHECK(part.width == 12 && part.height == 12);
        int same = 1;
        for (int y = 0; y < 12; y++)
            for (int x = 0; x < 12; x++)
                for (int c = 0; c < 3; c++)
                    same &= lf_image_px(&part, x, y)[c] == lf_image_px(&full, x + 8, y + 4)[c];
        CHECK(same);
        lf_image_free(&full);
        lf_image_free(&part);
    }

    /* --explain prints the plan and writes nothing */
    char none[512];
    snprintf(none, sizeof none, "%s/none.exr", dir);
    CHECK(run("%s %s --explain -o %s", LF_LFRENDER, scene, none) == 0);
    CHECK(strstr(out_text, "camera: \"perspective\"") != NULL);
    CHECK(strstr(out_text, "defocus: off") != NULL);
    CHECK(strstr(out_text, "motion blur: off") != NULL);
    CHECK(!exists(none));

    /* a bad scene: exit 1, file:line:col, the existing output untouched */
    write_file(bad, "LookAt 0 0 -3 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" [40\n");
    struct stat before, after;
    stat(out, &before);
    CHECK(run("%s %s -o %s", LF_LFRENDER, bad, out) == 1);
    CHECK_MSG(strstr(out_text, "bad.pbrt:") != NULL, "message: %s", out_text);
    stat(out, &after);
    CHECK(before.st_size == after.st_size && before.st_mtime == after.st_mtime);
    write_file(bad, "WorldBegin\nShape \"sphere\" \"float radius\" [1] \"float radus\" [2]\n");
    CHECK(run("%s %s -o %s/never.exr", LF_LFRENDER, bad, dir) == 1);
    CHECK_MSG(strstr(out_text, "bad.pbrt:2:") && strstr(out_text, "radus"), "message: %s", out_text);
    /* did you mean: a parameter among those the type looked up */
    write_file(bad, "WorldBegin\nShape \"sphere\" \"float radus\" [2]\n");
    CHECK(run("%s %s -o %s/never.exr", LF_LFRENDER, bad, dir) == 1);
    CHECK_MSG(strstr(out_text, "(did you mean \"float radius\"?)"), "message: %s", out_text);
    /* a misspelt type is unknown, with the nearest, even with --allow-unsupported */
    write_file(bad, "WorldBegin\nMaterial \"difuse\"\nShape \"sphere\"\n");
    CHECK(run("%s %s -o %s/never.exr --allow-unsupported", LF_LFRENDER, bad, dir) == 1);
    CHECK_MSG(strstr(out_text, "bad.pbrt:2:1: Material: unknown material \"difuse\" (did you mean \"diffuse\"?)") &&
                  !strstr(out_text, "allow-unsupported"), "message: %s", out_text);
    /* a misspelt WorldBegin: one error, no cascade (scenefile/parser.c's rule) */
    write_file(bad, "Camera \"perspective\"\nWorldBgin\nLightSource \"point\"\nMaterial \"diffuse\"\n"
                    "Shape \"sphere\"\nAttributeBegin\nShape \"sphere\"\nAttributeEnd\n");
    CHECK(run("%s %s -o %s/never.exr", LF_LFRENDER, bad, dir) == 1);
    CHECK_MSG(count_lines(out_text) == 1 && strstr(out_text, "bad.pbrt:2:1: unknown directive \"WorldBgin\" (did you "
                                                              "mean WorldBegin?)"), "message: %s", out_text);
    char never[512];
    snprintf(never, sizeof never, "%s/never.exr", dir);
    CHECK(!exists(never));
    CHECK(run("%s %s/missing.pbrt", LF_LFRENDER, dir) == 1);
    CHECK(strstr(out_text, "missing.pbrt") != NULL);

    /* a camera from a plugin */
    char pano[512];
    snprintf(pano, sizeof pano, "%s/pano.pbrt", dir);
    write_file(pano, "Camera \"panorama\"\nFilm \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [8]\n"
                     "Sampler \"independent\" \"integer pixelsamples\" [1]\n"
                     "WorldBegin\nLightSource \"infinite\"\n");
    CHECK(run("%s %s -o %s/pano.exr --quiet", LF_LFRENDER, pano, dir) == 1); /* not registered */
    CHECK(strstr(out_text, "panorama") != NULL);
    CHECK(run("%s --camera-plugin %s %s -o %s/pano.exr --quiet", LF_LFRENDER, LF_PLUGIN_PATH, pano, dir) == 0);

    /* no temporary files left behind */
    CHECK(run("ls -A %s | grep -c tmp", dir) != 0 || strncmp(out_text, "0", 1) == 0);
    char rm[600];
    snprintf(rm, sizeof rm, "rm -rf %s", dir);
    if (system(rm) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return lf_test_end();
}
