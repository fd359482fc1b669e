/* bench/pbrt_v4_stub_nvdb OUT.nvdb: the stub volume bench/pbrt_v4_scenes.sh
 * puts where a scene names a .nvdb file the scene copy lacks: a 2x2x2
 * "density" grid of 0.5 in the unit cube, so a nanovdb medium is judged on
 * its parameters rather than failing on an empty file.  Not a benchmark. */
#include <stdio.h>

#include "render/nanovdb_adapter.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: pbrt_v4_stub_nvdb OUT.nvdb\n");
        return 2;
    }
    const float vals[8] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    const double origin[3] = {0, 0, 0};
    char err[256] = "";
    if (lf_nvdb_write_dense(argv[1], "density", 2, 2, 2, vals, 0.5, origin, err, sizeof err)) {
        fprintf(stderr, "pbrt_v4_stub_nvdb: %s\n", err);
        return 1;
    }
    return 0;
}
