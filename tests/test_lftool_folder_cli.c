/* Folders of views and ground-truth disparity as a user runs them:
 *   lfrender --aov disparity  ->  RAW.exr + RAW.disparity.exr
 *   lftool decode RAW.exr --layout hci -o DIR  ->  HCI views, parameters.cfg,
 *       gt_disp_lowres.pfm (the centre tile of the AOV)
 *   lftool info|refocus|view|decode DIR, and the errors (exit 1, file named). */
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

/* 3 x 3 cameras, tiles 24 x 16, a textured plane tilted in depth */
static const char *scene =
    "LookAt 0 0 0  0 0 1  0 1 0\n"
    "Camera \"lightfield\" \"float fov\" [40] \"integer camerasperdim\" [3 3]\n"
    "  \"float cameragridbounds\" [-0.05 0.05 -0.05 0.05]\n"
    "Film \"rgb\" \"integer xresolution\" [72] \"integer yresolution\" [48]\n"
    "Sampler \"independent\" \"integer pixelsamples\" [1]\n"
    "WorldBegin\n"
    "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
    "Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" [9] \"float vscale\" [9]\n"
    "  \"rgb tex1\" [0.8 0.3 0.2] \"rgb tex2\" [0.15 0.5 0.7]\n"
    "Material \"diffuse\" \"texture reflectance\" \"c\"\n"
    "Shape \"bilinearmesh\" \"point3 P\" [-3 -3 1.5  3 -3 3.3  -3 3 1.5  3 3 3.3]\n"
    "  \"point2 uv\" [0 0 1 0 0 1 1 1]\n";

int main(void)
{
    lf_test_run_setup(dir, 0, out_text, sizeof out_text);
    snprintf(dir, sizeof dir, "%s/test_lftool_folder.XXXXXX", P_tmpdir);
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    char path[800], hci[600], raw[600];
    snprintf(path, sizeof path, "%s/s.pbrt", dir);
    FILE *f = fopen(path, "w");
    fputs(scene, f);
    fclose(f);
    snprintf(raw, sizeof raw, "%s/raw.exr", dir);

    /* render with the disparity AOV */
    CHECK(run("%s %s -o %s --quiet --aov disparity", LF_LFRENDER, path, raw) == 0);
    snprintf(path, sizeof path, "%s/raw.disparity.exr", dir);
    CHECK(exists(path));
    lf_image aov, img;
    lf_attrs a = {0};
    lf_error err = {0};
    CHECK(lf_image_read(path, &aov, NULL, &err) == 0);
    CHECK(aov.width == 72 && aov.height == 48 && aov.channels == 1);
    CHECK(lf_image_read(raw, &img, &a, &err) == 0);
    const lf_attr *df = lf_attrs_get(&a, "lensfield:disparity_file");
    CHECK(df && df->type == LF_ATTR_STRING && !strcmp(df->s, "raw.disparity.exr"));
    lf_attrs_free(&a);
    /* non-light-field cameras and split renders are refused */
    CHECK(run("%s %s -o %s/x.exr --quiet --aov depth", LF_LFRENDER, path, dir) == 2);
    CHECK(run("%s %s/s.pbrt -o %s/x.png --quiet --aov disparity", LF_LFRENDER, dir, dir) == 2);

    /* decode to the HCI layout: views, cfg, the centre tile's disparity */
    snprintf(hci, sizeof hci, "%s/hci", dir);
    CHECK(run("%s decode %s --layout hci -o %s", LFTOOL, raw, hci) == 0);
    CHECK(strstr(out_text, "gt_disp_lowres.pfm") != NULL);
    lf_image gt;
    snprintf(path, sizeof path, "%s/gt_disp_lowres.pfm", hci);
    CHECK(lf_image_read(path, &gt, NULL, &err) == 0);
    CHECK(gt.width == 24 && gt.height == 16 && gt.channels == 1);
    if (gt.data && aov.data) {
        int same = 1;
        for (int y = 0; y < 16; y++)
            for (int x = 0; x < 24; x++)
                same &= gt.data[y * 24 + x] == aov.data[(16 + y) * 72 + 24 + x];
        CHECK(same);
        /* disparity F b / Z: F = 8 / tan(20 deg) px, b = 5 cm, Z in 1.5 .. 3.3 m */
        double F = 8 / tan(20 * M_PI / 180);
        for (int i = 0; i < 24 * 16; i++)
            CHECK_MSG(gt.data[i] > F * 0.05 / 3.31 && gt.data[i] < F * 0.05 / 1.49, "gt %g", gt.data[i]);
    }
    snprintf(path, sizeof path, "%s/input_Cam008.png", hci);
    CHECK(exists(path));

    /* the folder as input: info, refocus, view, decode */
    CHECK(run("%s info %s", LFTOOL, hci) == 0);
    CHECK(strstr(out_text, "folder of 3 x 3 views") && strstr(out_text, "HCI") &&
          strstr(out_text, "view resolution 24 x 16") && strstr(out_text, "disparity range"));
    CHECK(run("%s refocus %s --depth 2 -o %s/r.exr", LFTOOL, hci, dir) == 0);
    CHECK(run("%s view %s --u 0.5 --v 0 -o %s/v.exr", LFTOOL, hci, dir) == 0);
    char rc_dir[600];
    snprintf(rc_dir, sizeof rc_dir, "%s/rc", dir);
    CHECK(run("%s decode %s -o %s --format exr", LFTOOL, hci, rc_dir) == 0);
    CHECK(run("%s info %s", LFTOOL, rc_dir) == 0); /* view_RR_CC.exr read back */
    CHECK(strstr(out_text, "folder of 3 x 3 views") && strstr(out_text, "row/column"));
    /* row/column folders carry no geometry: the layout flags give it */
    CHECK(run("%s refocus %s --depth 2 -o %s/r3.exr", LFTOOL, rc_dir, dir) == 1);
    CHECK(strstr(out_text, "--griddim") != NULL);
    CHECK(run("%s info %s --griddim -0.05 0.05 -0.05 0.05 --inputfov 40", LFTOOL, rc_dir) == 0);
    {
        char want[64];
        snprintf(want, sizeof want, "0 + %.6g / depth", 8 / tan(20 * M_PI / 180) * 0.05);
        CHECK_MSG(strstr(out_text, want) != NULL, "%s lacks %s", out_text, want);
    }
    CHECK(run("%s info %s --camsperdim 2 2", LFTOOL, rc_dir) == 1);
    CHECK(strstr(out_text, "--camsperdim") != NULL);
    /* a disparity map written as PFM by the generic image path */
    CHECK(run("%s depth %s --from 0 --to 1 --steps 5 -o %s/d.pfm", LFTOOL, hci, dir) == 0);
    lf_image dm;
    snprintf(path, sizeof path, "%s/d.pfm", dir);
    CHECK(lf_image_read(path, &dm, NULL, &err) == 0 && dm.width == 24 && dm.height == 16 && dm.channels == 1);
    lf_image_free(&dm);

    /* a missing view and an unreadable one: exit 1, the file named */
    snprintf(path, sizeof path, "%s/input_Cam005.png", hci);
    char moved[700];
    snprintf(moved, sizeof moved, "%s/moved.png", dir);
    rename(path, moved);
    CHECK(run("%s info %s", LFTOOL, hci) == 1);
    CHECK(strstr(out_text, "input_Cam005.png") && strstr(out_text, "missing"));
    f = fopen(path, "w");
    fputs("garbage", f);
    fclose(f);
    CHECK(run("%s refocus %s --disparity 0 -o %s/r2.exr", LFTOOL, hci, dir) == 1);
    CHECK(strstr(out_text, "input_Cam005.png") != NULL);

    lf_image_free(&gt), lf_image_free(&aov), lf_image_free(&img);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd)) {
    }
    return lf_test_end();
}
