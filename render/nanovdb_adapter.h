/* nanovdb_adapter.h - NanoVDB volumes for MakeNamedMedium "nanovdb"
 * (render/ only; render/nanovdb_adapter.cpp, C++ behind a C interface as
 * image/oiio_adapter.cpp, on Debian's libnanovdb-dev headers).
 * A grid is a float FogVolume read from a .nvdb file (uncompressed, zip
 * or Blosc), sampled trilinearly in its world space (the medium's space,
 * as pbrt-v4's NanoVDBMedium). */
#ifndef LF_RENDER_NANOVDB_ADAPTER_H
#define LF_RENDER_NANOVDB_ADAPTER_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lf_nvdb lf_nvdb;

/* Grid `name` of the file; 0, or non-zero with a message in err.  A
 * missing grid (not found in the file) returns 0 with *out NULL. */
int lf_nvdb_open(const char *path, const char *name, lf_nvdb **out, char *err, size_t err_size);
/* The grid's value at world point p, trilinear between voxel centres. */
float lf_nvdb_sample(const lf_nvdb *g, const float p[3]);
/* World bounding box of the active voxels and the largest value. */
void lf_nvdb_bounds(const lf_nvdb *g, double bmin[3], double bmax[3]);
float lf_nvdb_max(const lf_nvdb *g);
void lf_nvdb_free(lf_nvdb *g);
/* Writes a dense nx x ny x nz float grid (x fastest) named `name` with
 * voxel size `voxel` and index (0,0,0) at world `origin` as an
 * uncompressed .nvdb file (for tests and examples). */
int lf_nvdb_write_dense(const char *path, const char *name, int nx, int ny, int nz, const float *values, double voxel,
                        const double origin[3], char *err, size_t err_size);

#ifdef __cplusplus
}
#endif

#endif
