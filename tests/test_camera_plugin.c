/* Loading a user's camera from a shared object into the registry. */
#include <string.h>

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
    return lf_test_end();
}
