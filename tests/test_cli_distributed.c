/* Splitting renders, merging parts, checkpoints and resuming after SIGKILL:
 * every route must give the unsplit render's image bit for bit. */
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lf_test.h"
#include "lf_test_tools.h"

static char dir[256], log_text[8192];

/* Bit-identical float pixels? */
static int same_pixels(const char *a, const char *b)
{
    lf_image x, y;
    lf_error e = {0};
    if (lf_image_read(a, &x, NULL, &e)) {
        fprintf(stderr, "%s\n", e.msg);
        return 0;
    }
    if (lf_image_read(b, &y, NULL, &e)) {
        fprintf(stderr, "%s\n", e.msg);
        lf_image_free(&x);
        return 0;
    }
    int same = x.width == y.width && x.height == y.height && x.channels == y.channels &&
               memcmp(x.data, y.data, sizeof(float) * (size_t)x.width * x.height * x.channels) == 0;
    lf_image_free(&x);
    lf_image_free(&y);
    return same;
}

static const char *scene_text =
    "LookAt 0 1 -5 0 0.5 0 0 1 0\nCamera \"perspective\" \"float fov\" [40]\n"
    "Film \"rgb\" \"integer xresolution\" [96] \"integer yresolution\" [64] \"bool savefp16\" false\n"
    "Sampler \"zsobol\" \"integer pixelsamples\" [48]\nPixelFilter \"gaussian\"\n"
    "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.4 0.5 0.6]\n"
    "LightSource \"distant\" \"point3 from\" [1 4 -2] \"rgb L\" [2 2 2]\n"
    "Material \"diffuse\"\nShape \"bilinearmesh\" \"point3 P\" [-5 0 -5 5 0 -5 -5 0 5 5 0 5]\n"
    "Material \"dielectric\"\nAttributeBegin\nTranslate -0.6 0.5 0\nShape \"sphere\" \"float radius\" [0.5]\n"
    "AttributeEnd\nMaterial \"conductor\" \"float roughness\" [0.1]\nTranslate 0.7 0.5 0.3\n"
    "Shape \"sphere\" \"float radius\" [0.5]\n";

int main(void)
{
    lf_test_run_setup(dir, 0, log_text, sizeof log_text);
    snprintf(dir, sizeof dir, "/tmp/lf_dist_XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    char scene[512];
    snprintf(scene, sizeof scene, "%s/s.pbrt", dir);
    FILE *f = fopen(scene, "wb");
    fputs(scene_text, f);
    fclose(f);
    const char *R = LF_LFRENDER;

    CHECK(run("%s %s -o %s/ref.exr --seed 9 --quiet", R, scene, dir) == 0);

    /* split by rows and by samples, in any combination, merged */
    CHECK(run("%s %s -o %s/a.exr --seed 9 --quiet --tile 0/3 --spp-range 0 20", R, scene, dir) == 0);
    CHECK(run("%s %s -o %s/b.exr --seed 9 --quiet --tile 0/3 --spp-range 20 48", R, scene, dir) == 0);
    CHECK(run("%s %s -o %s/c.exr --seed 9 --quiet --tile 1/3", R, scene, dir) == 0);
    CHECK(run("%s %s -o %s/d.exr --seed 9 --quiet --tile 2/3 --spp-range 0 1", R, scene, dir) == 0);
    CHECK(run("%s %s -o %s/e.exr --seed 9 --quiet --tile 2/3 --spp-range 1 48 --threads 1", R, scene, dir) == 0);
    CHECK(run("%s merge %s/a.exr %s/b.exr %s/c.exr %s/d.exr %s/e.exr -o %s/merged.exr", R, dir, dir, dir, dir, dir,
              dir) == 0);
    char a[600], b[600];
    snprintf(a, sizeof a, "%s/ref.exr", dir);
    snprintf(b, sizeof b, "%s/merged.exr", dir);
    CHECK_MSG(same_pixels(a, b), "merged parts differ from the unsplit render");

    /* a missing part, an overlapping part, a part of another seed: errors */
    CHECK(run("%s merge %s/a.exr %s/c.exr %s/d.exr %s/e.exr -o %s/bad.exr", R, dir, dir, dir, dir, dir) == 1);
    CHECK_MSG(strstr(log_text, "of 48 samples"), "%s", log_text);
    CHECK(run("%s merge %s/a.exr %s/a.exr %s/b.exr %s/c.exr %s/d.exr %s/e.exr -o %s/bad.exr", R, dir, dir, dir, dir,
              dir, dir, dir) == 1);
    CHECK(run("%s %s -o %s/other.exr --seed 10 --quiet --tile 0/3 --spp-range 0 20", R, scene, dir) == 0);
    CHECK(run("%s merge %s/other.exr %s/b.exr %s/c.exr %s/d.exr %s/e.exr -o %s/bad.exr", R, dir, dir, dir, dir, dir,
              dir) == 1);
    CHECK_MSG(strstr(log_text, "different render"), "%s", log_text);
    CHECK(run("%s merge %s/ref.exr -o %s/bad.exr", R, dir, dir) == 1);
    CHECK(strstr(log_text, "not a render part") != NULL);
    struct stat st;
    snprintf(b, sizeof b, "%s/bad.exr", dir);
    CHECK(stat(b, &st) != 0); /* no output on failure */

    /* SIGKILL at several moments, then --resume: identical to uninterrupted.
     * Delays are fixed (deterministic test), spread over the render. */
    const int delays_ms[] = {60, 150, 300, 500};
    for (int k = 0; k < 4; k++) {
        char out[600];
        snprintf(out, sizeof out, "%s/k%d.exr", dir, k);
        pid_t pid = fork();
        if (pid == 0) {
            execl(R, R, scene, "-o", out, "--seed", "9", "--quiet", "--checkpoint-every", "0.05", (char *)NULL);
            _exit(127);
        }
        struct timespec ts = {0, delays_ms[k] * 1000000L};
        nanosleep(&ts, NULL);
        kill(pid, SIGKILL);
        int status;
        waitpid(pid, &status, 0);
        CHECK(run("%s %s -o %s --seed 9 --quiet --checkpoint-every 0.05 --resume", R, scene, out) == 0);
        CHECK_MSG(same_pixels(a, out), "resumed render %d (killed after %d ms) differs", k, delays_ms[k]);
        char ck[700];
        snprintf(ck, sizeof ck, "%s.checkpoint.exr", out);
        CHECK(stat(ck, &st) != 0); /* removed once finished */
    }
    /* SIGTERM: exit 130 with a checkpoint, and the resume completes it */
    {
        char out[600];
        snprintf(out, sizeof out, "%s/t.exr", dir);
        pid_t pid = fork();
        if (pid == 0) {
            execl(R, R, scene, "-o", out, "--seed", "9", "--quiet", "--checkpoint-every", "0.05", (char *)NULL);
            _exit(127);
        }
        /* wait until rendering runs (its first checkpoint exists): the signal
         * handler is installed by then, not during dynamic loading */
        char ckp[700];
        snprintf(ckp, sizeof ckp, "%s.checkpoint.exr", out);
        for (int i = 0; i < 2000 && stat(ckp, &st) != 0; i++) {
            struct timespec ts = {0, 5 * 1000000L};
            nanosleep(&ts, NULL);
        }
        kill(pid, SIGTERM);
        int status;
        waitpid(pid, &status, 0);
        int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        CHECK_MSG(code == 130 || code == 0, "exit %d after SIGTERM", code); /* 0 if it had finished */
        CHECK(run("%s %s -o %s --seed 9 --quiet --checkpoint-every 0.05 --resume", R, scene, out) == 0 || code == 0);
        CHECK(same_pixels(a, out));
    }
    /* resuming with other settings is refused */
    {
        char out[600];
        snprintf(out, sizeof out, "%s/r.exr", dir);
        CHECK(run("%s %s -o %s --seed 9 --quiet --tile 0/2 --checkpoint-every 60", R, scene, out) == 0);
        CHECK(run("cp %s/a.exr %s.checkpoint.exr", dir, out) == 0);
        CHECK(run("%s %s -o %s --seed 11 --quiet --resume", R, scene, out) == 1);
        CHECK_MSG(strstr(log_text, "cannot resume"), "%s", log_text);
    }
    /* an unwritable output is refused before rendering */
    CHECK(run("%s %s -o /proc/lensfield/x.exr --quiet", R, scene) == 1);
    CHECK(strstr(log_text, "/proc/lensfield/x.exr") != NULL);

    char rm[600];
    snprintf(rm, sizeof rm, "rm -rf %s", dir);
    if (system(rm) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return lf_test_end();
}
