/* lftool as a user runs it: exit codes, messages naming the file and what is
 * missing, outputs of every subcommand, flags vs attributes. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "image/lf_image.h"
#include "lf_test.h"
#include "lf_test_tools.h"

#define LFTOOL LF_BINARY_DIR "/bin/lftool"

static char dir[256];
static char out_text[65536];

static int exists(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0;
}

/* 3 x 3 camera array, 32 x 24 tiles, 4 cm baseline, plane at 1.5 m */
enum { NC = 3, TW = 32, TH = 24 };
static const double FOV = 40, B = 0.04, Z = 1.5;

static void make_raw(lf_image *raw)
{
    lf_error err = {0};
    lf_image_alloc(raw, NC * TW, NC * TH, 3, &err);
    double t = tan(FOV * M_PI / 360), half = 0.5 * TH;
    for (int j = 0; j < NC; j++)
        for (int i = 0; i < NC; i++) {
            double cx = -B + i * B, cy = B - j * B;
            for (int y = 0; y < TH; y++)
                for (int x = 0; x < TW; x++) {
                    double X = cx + (x + 0.5 - TW / 2.0) / half * t * Z, Y = cy - (y + 0.5 - TH / 2.0) / half * t * Z;
                    float *p = lf_image_px(raw, i * TW + x, j * TH + y);
                    p[0] = (float)(0.5 + 0.3 * sin(2 * M_PI * 2.1 * X));
                    p[1] = (float)(0.5 + 0.3 * cos(2 * M_PI * 1.7 * Y));
                    p[2] = 0.25f;
                }
        }
}

int main(void)
{
    lf_test_run_setup(dir, 0, out_text, sizeof out_text);
    snprintf(dir, sizeof dir, "/tmp/lf_lftool_XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    char raw_path[512], plain_path[512], nan_path[512], out[512], path[600];
    snprintf(raw_path, sizeof raw_path, "%s/array.exr", dir);
    snprintf(plain_path, sizeof plain_path, "%s/plain.exr", dir);
    snprintf(nan_path, sizeof nan_path, "%s/nan.exr", dir);
    lf_image raw;
    lf_error err = {0};
    make_raw(&raw);
    lf_attrs a = {0};
    float cams[2] = {NC, NC}, bounds[4] = {(float)-B, (float)B, (float)-B, (float)B};
    lf_attrs_set_string(&a, "lensfield:kind", "camera-array", NULL);
    lf_attrs_set_floats(&a, "lensfield:cameras_per_dim", cams, 2, NULL);
    lf_attrs_set_floats(&a, "lensfield:camera_grid_bounds", bounds, 4, NULL);
    lf_attrs_set_double(&a, "lensfield:fov_deg", FOV, NULL);
    CHECK_MSG(lf_image_write(raw_path, &raw, &a, NULL, &err) == 0, "%s", err.msg);
    CHECK(lf_image_write(plain_path, &raw, NULL, NULL, &err) == 0);

    /* usage */
    CHECK(run("%s --help", LFTOOL) == 0);
    CHECK(strstr(out_text, "usage: lftool") != NULL);
    CHECK(run("%s", LFTOOL) == 2);
    CHECK(run("%s frobnicate %s", LFTOOL, raw_path) == 2);
    CHECK(run("%s info %s --bogus", LFTOOL, raw_path) == 2);
    CHECK(strstr(out_text, "--bogus") != NULL);
    CHECK(run("%s refocus %s -o %s/r.exr", LFTOOL, raw_path, dir) == 2); /* no focus given */
    CHECK(run("%s refocus %s --alpha 1 --disparity 1 -o %s/r.exr", LFTOOL, raw_path, dir) == 2);
    CHECK(run("%s refocus %s --disparity abc -o %s/r.exr", LFTOOL, raw_path, dir) == 2);
    /* a usage error is two lines: the message and where help is; a typo gets the nearest name */
    CHECK(run("%s refocus %s --dpth 1 -o %s/r.exr", LFTOOL, raw_path, dir) == 2);
    CHECK_MSG(!strcmp(out_text, "lftool refocus: unknown flag --dpth (did you mean --depth?)\n"
                                "Run `lftool refocus --help` for usage.\n"), "%s", out_text);
    CHECK(run("%s refocus %s -o %s/r.exr", LFTOOL, raw_path, dir) == 2);
    CHECK_MSG(strstr(out_text, "Run `lftool refocus --help` for usage.\n") && !strstr(out_text, "options:"), "%s",
              out_text);
    CHECK(run("%s refocsu %s", LFTOOL, raw_path) == 2);
    CHECK_MSG(!strcmp(out_text, "lftool: unknown command \"refocsu\" (did you mean refocus?)\n"
                                "Run `lftool --help` for usage.\n"), "%s", out_text);

    /* info */
    CHECK(run("%s info %s", LFTOOL, raw_path) == 0);
    CHECK(strstr(out_text, "camera-array") && strstr(out_text, "3 x 3") && strstr(out_text, "32 x 24"));
    /* missing file, missing attributes: exit 1, the file and what is missing named */
    CHECK(run("%s info %s/none.exr", LFTOOL, dir) == 1);
    CHECK(strstr(out_text, "none.exr") != NULL);
    CHECK(run("%s info %s", LFTOOL, plain_path) == 1);
    CHECK(strstr(out_text, "plain.exr") && strstr(out_text, "lensfield:kind") && strstr(out_text, "--camsperdim"));
    /* flags supply the layout; contradicting flags fail */
    CHECK(run("%s info %s --camsperdim 3 3", LFTOOL, plain_path) == 0);
    CHECK(run("%s info %s --camsperdim 3 3", LFTOOL, raw_path) == 0);
    CHECK(run("%s info %s --camsperdim 4 4", LFTOOL, raw_path) == 1);
    CHECK(strstr(out_text, "--camsperdim") && strstr(out_text, "lensfield:cameras_per_dim"));

    /* decode: one file per view plus a mosaic; png; HCI layout */
    snprintf(out, sizeof out, "%s/views", dir);
    CHECK(run("%s decode %s -o %s", LFTOOL, raw_path, out) == 0);
    snprintf(path, sizeof path, "%s/view_01_02.exr", out); /* row 1, column 2 */
    lf_image v;
    CHECK(lf_image_read(path, &v, NULL, &err) == 0);
    CHECK(v.width == TW && v.height == TH);
    CHECK(v.data && v.data[0] == lf_image_px(&raw, 2 * TW, TH)[0]);
    lf_image_free(&v);
    snprintf(path, sizeof path, "%s/mosaic.exr", out);
    CHECK(exists(path));
    CHECK(run("%s decode %s -o %s --format png", LFTOOL, raw_path, out) == 0);
    snprintf(path, sizeof path, "%s/view_00_00.png", out);
    CHECK(exists(path));
    snprintf(out, sizeof out, "%s/hci", dir);
    CHECK(run("%s decode %s -o %s --layout hci", LFTOOL, raw_path, out) == 0);
    snprintf(path, sizeof path, "%s/input_Cam008.png", out);
    CHECK(exists(path));
    snprintf(path, sizeof path, "%s/parameters.cfg", out);
    CHECK(exists(path));

    /* refocus by disparity and by depth agree; alpha needs a main lens */
    double d = 0.5 * TH / tan(FOV * M_PI / 360) * B / Z;
    CHECK(run("%s refocus %s --disparity %.17g -o %s/rd.exr", LFTOOL, raw_path, d, dir) == 0);
    CHECK(run("%s refocus %s --depth %.17g -o %s/rz.exr", LFTOOL, raw_path, Z, dir) == 0);
    lf_image r1, r2;
    snprintf(path, sizeof path, "%s/rd.exr", dir);
    CHECK(lf_image_read(path, &r1, NULL, &err) == 0);
    snprintf(path, sizeof path, "%s/rz.exr", dir);
    CHECK(lf_image_read(path, &r2, NULL, &err) == 0);
    double psnr = 0;
    CHECK(lf_image_psnr(&r1, &r2, &psnr, &err) == 0 && psnr > 100);
    lf_image_free(&r1), lf_image_free(&r2);
    CHECK(run("%s refocus %s --alpha 1.1 -o %s/ra.exr", LFTOOL, raw_path, dir) == 1);
    CHECK(strstr(out_text, "array.exr") && strstr(out_text, "alpha"));
    CHECK(run("%s refocus %s --disparity 0.5 --aperture 0 -o %s/rap.exr", LFTOOL, raw_path, dir) == 0);
    CHECK(run("%s refocus %s --disparity 0.5 --views 0 1 0 1 -o %s/rv.exr", LFTOOL, raw_path, dir) == 0);
    CHECK(run("%s refocus %s --disparity 0.5 --method fourier -o %s/rf.exr", LFTOOL, raw_path, dir) == 0);
    CHECK(run("%s stack %s --from 0 --to 1 --steps 3 -o %s/stack", LFTOOL, raw_path, dir) == 0);
    snprintf(path, sizeof path, "%s/stack/stack_002.exr", dir);
    CHECK(exists(path));
    CHECK(run("%s allfocus %s --from 0 --to 1 --steps 3 -o %s/af.exr", LFTOOL, raw_path, dir) == 0);
    CHECK(run("%s depth %s --from 0 --to 1 --steps 3 -o %s/dm.exr", LFTOOL, raw_path, dir) == 0);
    CHECK(run("%s view %s --u 0.5 --v -0.5 -o %s/view.exr", LFTOOL, raw_path, dir) == 0);
    CHECK_MSG(strstr(out_text, "view at u 0.5, v -0.5 (depth) -> ") && strstr(out_text, "/view.exr\n"), "%s",
              out_text); /* says what it wrote, as the other commands do */
    /* depth with no range (estimated), confidence beside it */
    CHECK(run("%s depth %s -o %s/dm2.exr --confidence %s/conf.exr", LFTOOL, raw_path, dir, dir) == 0);
    CHECK(strstr(out_text, "estimated") != NULL);
    snprintf(path, sizeof path, "%s/conf.exr", dir);
    CHECK(exists(path));
    CHECK(run("%s depth %s --from 0 -o %s/dm3.exr", LFTOOL, raw_path, dir) == 2); /* --to missing */
    CHECK(run("%s depth %s --method stack --from 0 --to 1 --steps 3 -o %s/dm4.exr", LFTOOL, raw_path, dir) == 0);
    /* view: the plane blend on request, a given disparity map, a map of the wrong size */
    CHECK(run("%s view %s --u 0.5 --v -0.5 --geometry plane --disparity 0.5 -o %s/viewp.exr", LFTOOL, raw_path, dir) == 0);
    CHECK(run("%s view %s --u 0.5 --v -0.5 --disparity-map %s/dm2.exr -o %s/viewd.exr", LFTOOL, raw_path, dir, dir) == 0);
    CHECK(run("%s view %s --u 0.5 --v -0.5 --disparity-map %s -o %s/viewd.exr", LFTOOL, raw_path, raw_path, dir) == 1);
    CHECK(strstr(out_text, "views are") != NULL);
    CHECK(run("%s view %s --u 0.5 --v 0 --geometry plane --disparity-map %s/dm2.exr -o %s/v.exr", LFTOOL, raw_path, dir,
              dir) == 2);
    /* self-calibrated view positions: depth, and a view from a given map */
    CHECK(run("%s depth %s --calibrate-views -o %s/dmc.exr", LFTOOL, raw_path, dir) == 0);
    snprintf(path, sizeof path, "%s/dmc.exr", dir);
    CHECK(exists(path));
    CHECK(run("%s view %s --u 0.5 --v -0.5 --calibrate-views --disparity-map %s/dm2.exr -o %s/viewc.exr", LFTOOL,
              raw_path, dir, dir) == 0);
    CHECK(run("%s view %s --u 0.5 --v -0.5 --geometry plane --calibrate-views -o %s/viewc.exr", LFTOOL, raw_path, dir) ==
          0);
    CHECK(run("%s view %s --u 3 --v 0 -o %s/view.exr", LFTOOL, raw_path, dir) == 1);
    CHECK(strstr(out_text, "outside") != NULL);

    /* synth: at camera (1,1) (grid centre, the default position) a pinhole gives its tile */
    CHECK(run("%s synth %s %s/syn.exr --samplesperpixel 1 --coverage %s/cov.exr", LFTOOL, raw_path, dir, dir) == 0);
    snprintf(path, sizeof path, "%s/syn.exr", dir);
    CHECK(lf_image_read(path, &v, NULL, &err) == 0);
    double maxd = 0;
    for (int y = 0; y < TH; y++)
        for (int x = 0; x < TW; x++)
            for (int c = 0; c < 3; c++)
                maxd = fmax(maxd, fabs(lf_image_px(&v, x, y)[c] - lf_image_px(&raw, TW + x, TH + y)[c]));
    CHECK_MSG(maxd < 1e-5, "synth at the centre camera differs from its tile by %g", maxd);
    lf_image_free(&v);
    /* synth with per-pixel geometry (estimated, or a given map) */
    CHECK(run("%s synth %s %s/synd.exr --geometry depth --camerapos 0.01 0.01 0", LFTOOL, raw_path, dir) == 0);
    CHECK(run("%s synth %s %s/synd.exr --geometry depth --disparity-map %s/dm2.exr", LFTOOL, raw_path, dir, dir) == 0);
    CHECK(run("%s synth %s %s/synd.exr --disparity-map %s/dm2.exr", LFTOOL, raw_path, dir, dir) == 2);
    /* all the CS348B flags, on a raw without attributes */
    CHECK(run("%s synth %s %s/syn2.exr --camsperdim 3 3 --griddim -0.04 0.04 -0.04 0.04 --inputfov 40 --outputfov 30 "
              "--outputdim 40 30 --camerapos 0.01 0.02 -0.1 --camerarot 0 5 0 --lensradius 0.01 --focaldistance 1.5 "
              "--samplesperpixel 4",
              LFTOOL, plain_path, dir) == 0);
    snprintf(path, sizeof path, "%s/syn2.exr", dir);
    CHECK(lf_image_read(path, &v, NULL, &err) == 0 && v.width == 40 && v.height == 30);
    lf_image_free(&v);
    CHECK(run("%s synth %s %s/syn3.exr --camsperdim 3 3", LFTOOL, plain_path, dir) == 1);
    CHECK(strstr(out_text, "plain.exr") && strstr(out_text, "--griddim") && strstr(out_text, "--inputfov"));
    CHECK(run("%s synth %s %s/syn3.exr --inputfov 50", LFTOOL, raw_path, dir) == 1);
    CHECK(strstr(out_text, "--inputfov") && strstr(out_text, "contradicts"));
    CHECK(run("%s synth %s %s/syn3.exr --camerapos 1 0 0", LFTOOL, raw_path, dir) == 0); /* reported, not fatal */
    CHECK(strstr(out_text, "captured aperture") != NULL);

    /* non-finite pixels: refused with their count, or excluded on request */
    lf_image_px(&raw, 5, 5)[0] = NAN;
    lf_image_px(&raw, 40, 30)[2] = INFINITY;
    lf_write_opts wo = {0};
    wo.allow_nonfinite = 1;
    CHECK(lf_image_write(nan_path, &raw, &a, &wo, &err) == 0);
    CHECK(run("%s refocus %s --disparity 0 -o %s/n.exr", LFTOOL, nan_path, dir) == 1);
    CHECK(strstr(out_text, "nan.exr") && strstr(out_text, "2 non-finite"));
    CHECK(run("%s refocus %s --disparity 0 --allow-nonfinite -o %s/n.exr", LFTOOL, nan_path, dir) == 0);
    CHECK(strstr(out_text, "2 non-finite") != NULL);
    snprintf(path, sizeof path, "%s/n.exr", dir);
    CHECK(lf_image_read(path, &v, NULL, &err) == 0 && lf_image_count_nonfinite(&v) == 0);
    lf_image_free(&v);
    CHECK(run("%s info %s", LFTOOL, nan_path) == 0);
    CHECK(strstr(out_text, "non-finite pixel values: 2") != NULL);

    lf_attrs_free(&a);
    lf_image_free(&raw);
    if (lf_test_failed == 0) {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", dir);
    }
    return lf_test_end();
}
