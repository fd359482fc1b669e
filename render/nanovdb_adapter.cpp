// NanoVDB grids behind a C interface (render/nanovdb_adapter.h).  Errors
// are returned as messages: nothing here prints, exits or throws past the
// interface.
#define NANOVDB_USE_ZIP 1
#define NANOVDB_USE_BLOSC 1
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridBuilder.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/SampleFromVoxels.h>

#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "render/nanovdb_adapter.h"

struct lf_nvdb {
    nanovdb::GridHandle<nanovdb::HostBuffer> handle;
    const nanovdb::FloatGrid *grid = nullptr;
    float vmax = 0;
};

static void set_err(char *err, size_t n, const char *what, const char *path)
{
    if (err && n)
        std::snprintf(err, n, "%s: %s", path, what);
}

extern "C" int lf_nvdb_open(const char *path, const char *name, lf_nvdb **out, char *err, size_t err_size)
{
    *out = nullptr;
    try {
        auto handle = nanovdb::io::readGrid<nanovdb::HostBuffer>(path, name, 0);
        if (!handle)
            return 0;
        const nanovdb::FloatGrid *grid = handle.grid<float>();
        if (!grid) {
            set_err(err, err_size, "the grid is not a float grid", path);
            return 1;
        }
        lf_nvdb *g = new lf_nvdb;
        g->handle = std::move(handle);
        g->grid = g->handle.grid<float>();
        float vmin = 0, vmax = 0;
        g->grid->tree().extrema(vmin, vmax);
        g->vmax = vmax > 0 ? vmax : 0;
        *out = g;
        return 0;
    } catch (const std::bad_alloc &) {
        set_err(err, err_size, "out of memory", path);
    } catch (const std::exception &e) {
        set_err(err, err_size, e.what(), path);
    }
    return 1;
}

extern "C" float lf_nvdb_sample(const lf_nvdb *g, const float p[3])
{
    nanovdb::Vec3f w(p[0], p[1], p[2]);
    nanovdb::Vec3f idx = g->grid->worldToIndexF(w);
    // Trilinear on the voxel values (pbrt-v4's SampleFromVoxels<..., 1, false>).
    auto sampler = nanovdb::createSampler<1, nanovdb::FloatGrid::TreeType, false>(g->grid->tree());
    return sampler(idx);
}

extern "C" void lf_nvdb_bounds(const lf_nvdb *g, double bmin[3], double bmax[3])
{
    const auto &b = g->grid->worldBBox();
    for (int i = 0; i < 3; i++)
        bmin[i] = b.min()[i], bmax[i] = b.max()[i];
}

extern "C" float lf_nvdb_max(const lf_nvdb *g) { return g->vmax; }

extern "C" void lf_nvdb_free(lf_nvdb *g) { delete g; }

extern "C" int lf_nvdb_write_dense(const char *path, const char *name, int nx, int ny, int nz, const float *values,
                                   double voxel, const double origin[3], char *err, size_t err_size)
{
    try {
        nanovdb::GridBuilder<float> builder(0.f, nanovdb::GridClass::FogVolume);
        auto acc = builder.getAccessor();
        for (int z = 0; z < nz; z++)
            for (int y = 0; y < ny; y++)
                for (int x = 0; x < nx; x++) {
                    float v = values[((size_t)z * ny + y) * nx + x];
                    if (v != 0.f)
                        acc.setValue(nanovdb::Coord(x, y, z), v);
                }
        auto handle = builder.getHandle<>(voxel, nanovdb::Vec3d(origin[0], origin[1], origin[2]), name);
        nanovdb::io::writeGrid(path, handle, nanovdb::io::Codec::NONE, 0);
        return 0;
    } catch (const std::exception &e) {
        set_err(err, err_size, e.what(), path);
    }
    return 1;
}
