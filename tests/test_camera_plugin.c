/* Loading a user's camera from a shared object into the registry. */
#include <math.h>
#include <string.h>

#include "base/lf_color.h"
#include "camera/lf_camera.h"
#include "lf_test.h"

int main(void)
{
    char err[1024] = "";
    int before = lf_camera_count();
    CHECK(lf_camera_find("panorama") == NULL);
    CHECK(lf_camera_load_plugin("/nonexistent/libnothing.so", err, sizeof err) != 0);
    CHECK(strstr(err, "/nonexistent/libnothing.so") != NULL);
    CHECK(lf_camera_load_plugin(LF_PLUGIN_PATH, err, sizeof err) == 0);
    CHECK(lf_camera_count() == before + 1);
    const lf_camera_type *t = lf_camera_find("panorama");
    CHECK(t != NULL && t->abi_version == LF_CAMERA_ABI_VERSION);
    /* loading it twice is a name clash, not a silent duplicate */
    CHECK(lf_camera_load_plugin(LF_PLUGIN_PATH, err, sizeof err) != 0);
    CHECK(strstr(err, "already registered") != NULL);
    CHECK(lf_camera_count() == before + 1);

    /* A version-1 plugin (its type record ends before generate_rays) loads,
     * has no batch entry, and the host's batch call falls back to single
     * rays: the pinhole's rays for pixel centres, from projection. */
    CHECK_MSG(lf_camera_load_plugin(LF_LEGACY_PLUGIN_PATH, err, sizeof err) == 0, "%s", err);
    const lf_camera_type *lt = lf_camera_find("legacy_pinhole");
    CHECK(lt != NULL);
    if (lt) {
        CHECK(lt->abi_version == 1u && lt->generate_rays == NULL && lt->describe == NULL && lt->metadata == NULL);
        lf_camera_create_args a = {sizeof a, NULL, 64, 32, 35.0, 0, 1, ".", err, sizeof err, NULL, 0};
        void *state = NULL;
        CHECK(lt->create(&a, &state) == 0);
        lf_camera_sample s[3] = {{32, 16, .5, .5, 0, .5}, {0, 0, .5, .5, 0, .5}, {64, 32, .5, .5, 0, .5}};
        lf_camera_ray r[3];
        double w[3];
        lf_camera_generate_rays(lt, state, 3, s, r, w);
        /* film (x, y) -> direction (2x/W - 1, (1 - 2y/H) H/W, 1), normalised */
        CHECK(w[0] == 1 && w[1] == 1 && w[2] == 1);
        CHECK_NEAR(r[0].dir[2], 1.0, 1e-15);
        CHECK_NEAR(r[1].dir[0], -1.0 / sqrt(2.25), 1e-15);
        CHECK_NEAR(r[1].dir[1], 0.5 / sqrt(2.25), 1e-15);
        CHECK_NEAR(r[2].dir[0], 1.0 / sqrt(2.25), 1e-15);
        lt->destroy(state);
    }
    /* the plugin header states the spectral range on its own: the host's */
    CHECK(LF_CAMERA_LAMBDA_MIN_NM == LF_LAMBDA_MIN && LF_CAMERA_LAMBDA_MAX_NM == LF_LAMBDA_MAX);
    return lf_test_end();
}
