/* pbrt-v4's heterogeneous media: "uniformgrid" (a density grid scaling
 * the sigma_a and sigma_s spectra, optional "Lescale" grid scaling "Le"),
 * "rgbgrid" (per-voxel RGB sigma_a, sigma_s and Le) and "cloud" (pbrt-v4's
 * procedural cloud of Perlin-noise octaves in the unit box), each inside
 * its bounds p0..p1 in the medium's space (the CTM at MakeNamedMedium).
 *
 * Grids are pbrt-v4's SampledGrid: sample (i, j, k) sits at the centre of
 * voxel (i, j, k) of the bounds, values between samples are trilinear, and
 * samples outside the grid count as 0 (so a grid fades out over the last
 * half voxel).  Rendering is null-collision tracking against one majorant
 * per medium, the largest sigma_t of any channel anywhere (pbrt-v4 uses a
 * 16^3 majorant grid; one majorant is unbiased too, only slower in sparse
 * media): delta tracking for paths (render/volpath.c) and ratio tracking
 * for shadow rays (Novak et al. 2014, pbrt-v4 section 14.2). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/media.h"
#include "render/nanovdb_adapter.h"

/* ---- grids ---- */
static float grid_at(const float *g, int stride, int c, const int n[3], int x, int y, int z)
{
    if (x < 0 || y < 0 || z < 0 || x >= n[0] || y >= n[1] || z >= n[2])
        return 0.f;
    return g[((size_t)(z * n[1] + y) * n[0] + x) * stride + c];
}

/* Trilinear lookup of channel c of grid g at unit-box point u. */
static float grid_lookup(const float *g, int stride, int c, const int n[3], lf_vec3 u)
{
    float px = u.x * n[0] - 0.5f, py = u.y * n[1] - 0.5f, pz = u.z * n[2] - 0.5f;
    int ix = (int)floorf(px), iy = (int)floorf(py), iz = (int)floorf(pz);
    float dx = px - ix, dy = py - iy, dz = pz - iz;
    float v = 0;
    for (int k = 0; k < 8; k++) {
        int ox = k & 1, oy = (k >> 1) & 1, oz = k >> 2;
        float w = (ox ? dx : 1 - dx) * (oy ? dy : 1 - dy) * (oz ? dz : 1 - dz);
        if (w > 0)
            v += w * grid_at(g, stride, c, n, ix + ox, iy + oy, iz + oz);
    }
    return v;
}

/* ---- Perlin noise for the cloud (Perlin 2002's gradient noise, as
 * pbrt-v4's Noise; the permutation is a fixed shuffle of 0..255 rather
 * than Perlin's published table, so the cloud has pbrt's statistics but
 * not its exact shape) ---- */
static unsigned char noise_perm[512];
static int noise_ready;

/* Called while the scene is built (one thread), before any lookup. */
void lf_medium_noise_init(void)
{
    if (noise_ready)
        return;
    noise_ready = 1;
    unsigned char p[256];
    for (int i = 0; i < 256; i++)
        p[i] = (unsigned char)i;
    uint64_t s = 0x2545F4914F6CDD1DULL;
    for (int i = 255; i > 0; i--) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        int j = (int)(s % (uint64_t)(i + 1));
        unsigned char t = p[i];
        p[i] = p[j], p[j] = t;
    }
    for (int i = 0; i < 512; i++)
        noise_perm[i] = p[i & 255];
}

static float grad(int x, int y, int z, float dx, float dy, float dz)
{
    int h = noise_perm[noise_perm[noise_perm[x] + y] + z] & 15;
    float u = h < 8 || h == 12 || h == 13 ? dx : dy;
    float v = h < 4 || h == 12 || h == 13 ? dy : dz;
    return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

static float fade(float t) { return t * t * t * (t * (t * 6 - 15) + 10); }

static float noise3(float x, float y, float z)
{
    int ix = (int)floorf(x), iy = (int)floorf(y), iz = (int)floorf(z);
    float dx = x - ix, dy = y - iy, dz = z - iz;
    ix &= 255, iy &= 255, iz &= 255;
    float w[8];
    for (int k = 0; k < 8; k++) {
        int ox = k & 1, oy = (k >> 1) & 1, oz = k >> 2;
        w[k] = grad(ix + ox, iy + oy, iz + oz, dx - ox, dy - oy, dz - oz);
    }
    float fx = fade(dx), fy = fade(dy), fz = fade(dz);
    float x00 = lf_lerpf(fx, w[0], w[1]), x10 = lf_lerpf(fx, w[2], w[3]);
    float x01 = lf_lerpf(fx, w[4], w[5]), x11 = lf_lerpf(fx, w[6], w[7]);
    return lf_lerpf(fz, lf_lerpf(fy, x00, x10), lf_lerpf(fy, x01, x11));
}

/* pbrt's DNoise: the noise at three offset points, a cheap vector field. */
static lf_vec3 dnoise(lf_vec3 p)
{
    return lf_v3(noise3(p.x + 0.5f, p.y, p.z), noise3(p.x, p.y + 0.5f, p.z), noise3(p.x, p.y, p.z + 0.5f));
}

/* pbrt-v4's CloudMedium::Density at unit-box point p. */
static float cloud_density(const lf_medium *m, lf_vec3 p)
{
    lf_vec3 pp = lf_scale(p, m->frequency);
    if (m->wispiness > 0) {
        float vomega = 0.05f * m->wispiness, vlambda = 10.f;
        for (int i = 0; i < 2; i++) {
            pp = lf_add(pp, lf_scale(dnoise(lf_scale(pp, vlambda)), vomega));
            vomega *= 0.5f, vlambda *= 1.99f;
        }
    }
    float d = 0, omega = 0.5f, lambda = 1.f;
    for (int i = 0; i < 5; i++) {
        d += omega * noise3(lambda * pp.x, lambda * pp.y, lambda * pp.z);
        omega *= 0.5f, lambda *= 1.99f;
    }
    d = lf_clampf((1 - p.y) * 4.5f * m->cloud_density * d, 0, 1);
    d += 2 * fmaxf(0.f, 0.5f - p.y);
    return lf_clampf(d, 0, 1);
}

void lf_medium_point(const lf_medium *m, lf_vec3 u, lf_vec3 *sa, lf_vec3 *ss, lf_vec3 *Le)
{
    *Le = lf_v3(0, 0, 0);
    if (u.x < 0 || u.y < 0 || u.z < 0 || u.x > 1 || u.y > 1 || u.z > 1) {
        *sa = *ss = lf_v3(0, 0, 0);
        return;
    }
    if (m->kind == LF_MEDIUM_RGBGRID) {
        float a[3] = {1, 1, 1}, s[3] = {1, 1, 1};
        for (int c = 0; c < 3; c++) {
            if (m->rgb_a)
                a[c] = grid_lookup(m->rgb_a, 3, c, m->n, u);
            if (m->rgb_s)
                s[c] = grid_lookup(m->rgb_s, 3, c, m->n, u);
        }
        *sa = lf_scale(lf_v3(a[0], a[1], a[2]), m->sigma_scale);
        *ss = lf_scale(lf_v3(s[0], s[1], s[2]), m->sigma_scale);
        if (m->rgb_le)
            *Le = lf_scale(lf_v3(grid_lookup(m->rgb_le, 3, 0, m->n, u), grid_lookup(m->rgb_le, 3, 1, m->n, u),
                                 grid_lookup(m->rgb_le, 3, 2, m->n, u)),
                           m->le_scale);
        return;
    }
    float d;
    if (m->kind == LF_MEDIUM_NANOVDB) {
        float p[3] = {m->box0.x + u.x * m->box_size.x, m->box0.y + u.y * m->box_size.y, m->box0.z + u.z * m->box_size.z};
        d = fmaxf(0.f, lf_nvdb_sample(m->nvdb, p));
    } else {
        d = m->kind == LF_MEDIUM_CLOUD ? cloud_density(m, u) : grid_lookup(m->density, 1, 0, m->n, u);
    }
    *sa = lf_scale(m->sigma_a, d);
    *ss = lf_scale(m->sigma_s, d);
    if (m->emits) {
        float k = m->lescale ? grid_lookup(m->lescale, 1, 0, m->n, u) : 1.f;
        *Le = lf_scale(m->Le, k);
    }
}

/* The ray's parameter interval inside the medium's bounds, clipped to
 * [0, tmax]: 0 if it misses.  *om, *dm: the ray in unit-box coordinates
 * (same t). */
static int clip_to_bounds(const lf_medium *m, lf_vec3 o, lf_vec3 d, float tmax, float *t0, float *t1, lf_vec3 *om,
                          lf_vec3 *dm)
{
    lf_vec3 a = lf_xform_point(&m->world_to_unit, o), b = lf_xform_vector(&m->world_to_unit, d);
    float lo = 0, hi = tmax;
    float oa[3] = {a.x, a.y, a.z}, db[3] = {b.x, b.y, b.z};
    for (int i = 0; i < 3; i++) {
        if (db[i] == 0) {
            if (oa[i] < 0 || oa[i] > 1)
                return 0;
            continue;
        }
        float ta = (0 - oa[i]) / db[i], tb = (1 - oa[i]) / db[i];
        if (ta > tb) {
            float t = ta;
            ta = tb, tb = t;
        }
        lo = fmaxf(lo, ta), hi = fminf(hi, tb);
    }
    *t0 = lo, *t1 = hi, *om = a, *dm = b;
    return lo < hi;
}

/* splitmix64: the tracking's own random numbers, seeded per segment */
static float rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (float)(z >> 40) * 0x1p-24f;
}

uint64_t lf_medium_seed(float u0, float u1, lf_vec3 o, lf_vec3 d)
{
    float v[8] = {u0, u1, o.x, o.y, o.z, d.x, d.y, d.z};
    uint64_t h = 0x243f6a8885a308d3ULL;
    for (int i = 0; i < 8; i++) {
        uint32_t b;
        memcpy(&b, &v[i], 4);
        h = (h ^ b) * 0x100000001b3ULL;
        h ^= h >> 29;
    }
    return h;
}

/* Tentative collisions with the majorant stop after this many: a segment
 * that long would be a runaway (a majorant far above the medium). */
enum { MAX_COLLISIONS = 1 << 20 };

int lf_medium_track(const lf_medium *m, lf_vec3 o, lf_vec3 d, float t_s, uint64_t seed, lf_vec3 *beta, lf_vec3 *L,
                    float *t_event)
{
    float t0, t1, maj = m->majorant;
    lf_vec3 om, dm;
    if (!(maj > 0) || !clip_to_bounds(m, o, d, t_s, &t0, &t1, &om, &dm))
        return 0;
    float t = t0;
    for (int i = 0; i < MAX_COLLISIONS; i++) {
        t -= logf(1.f - rng_next(&seed)) / maj;
        if (!(t < t1))
            return 0;
        lf_vec3 sa, ss, Le;
        lf_medium_point(m, lf_madd(om, dm, t), &sa, &ss, &Le);
        /* emission at every tentative collision, weighted 1 / majorant */
        if (L && !lf_is_black(Le))
            *L = lf_add(*L, lf_mul(*beta, lf_scale(lf_mul(sa, Le), 1.f / maj)));
        float pa = (sa.x + sa.y + sa.z) / (3 * maj), ps = (ss.x + ss.y + ss.z) / (3 * maj);
        float pn = fmaxf(0.f, 1.f - pa - ps), u = rng_next(&seed);
        if (u < pa)
            return -1; /* absorbed */
        if (u < pa + ps) {
            *beta = lf_mul(*beta, lf_scale(ss, 1.f / (maj * ps)));
            *t_event = t;
            return 1;
        }
        if (!(pn > 0))
            return -1;
        lf_vec3 sn = lf_v3(maj - sa.x - ss.x, maj - sa.y - ss.y, maj - sa.z - ss.z);
        *beta = lf_mul(*beta, lf_scale(sn, 1.f / (maj * pn)));
        if (!(lf_maxc(*beta) > 0))
            return -1;
    }
    return -1;
}

lf_vec3 lf_medium_tr(const lf_medium *m, lf_vec3 o, lf_vec3 d, float tmax, uint64_t seed)
{
    float t0, t1, maj = m->majorant;
    lf_vec3 om, dm, T = lf_v3(1, 1, 1);
    if (!(maj > 0) || !clip_to_bounds(m, o, d, tmax, &t0, &t1, &om, &dm))
        return T;
    float t = t0;
    for (int i = 0; i < MAX_COLLISIONS; i++) {
        t -= logf(1.f - rng_next(&seed)) / maj;
        if (!(t < t1))
            return T;
        lf_vec3 sa, ss, Le;
        lf_medium_point(m, lf_madd(om, dm, t), &sa, &ss, &Le);
        /* ratio tracking: the null fraction per channel */
        T = lf_mul(T, lf_v3(1 - (sa.x + ss.x) / maj, 1 - (sa.y + ss.y) / maj, 1 - (sa.z + ss.z) / maj));
        if (!(lf_maxc(T) > 1e-6f)) {
            /* Russian roulette on a vanishing transmittance (pbrt-v4 does the same) */
            if (rng_next(&seed) < 0.75f)
                return lf_v3(0, 0, 0);
            T = lf_scale(T, 4.f);
        }
    }
    return lf_v3(0, 0, 0);
}

/* ---- reading ---- */

void lf_media_free(lf_scene *s)
{
    for (int i = 0; s->media && i < s->n_media; i++) {
        lf_medium *m = &s->media[i];
        free(m->density), free(m->lescale), free(m->rgb_a), free(m->rgb_s), free(m->rgb_le);
        lf_nvdb_free(m->nvdb);
    }
    free(s->media);
    s->media = NULL;
    s->n_media = 0;
}

/* A float copy of array parameter name with `per` values per grid sample
 * (n samples), or NULL when absent (*bad set on a wrong count). */
static float *read_grid(lf_paramset *ps, const char *name, lf_param_type type, int per, size_t n, int *bad)
{
    size_t cnt = 0;
    const double *v = lf_params_nums(ps, name, type, &cnt);
    if (!v)
        return NULL;
    if (cnt != n * (size_t)per) {
        *bad = 1;
        return NULL;
    }
    float *f = malloc(sizeof(float) * cnt);
    if (!f) {
        *bad = 2;
        return NULL;
    }
    for (size_t i = 0; i < cnt; i++) {
        f[i] = (float)v[i];
        if (!(f[i] >= 0) || !isfinite(f[i]))
            *bad = 3;
    }
    return f;
}

static float grid_max(const float *g, size_t n, int per, int c)
{
    float m = 0;
    for (size_t i = 0; g && i < n; i++)
        m = fmaxf(m, g[i * (size_t)per + c]);
    return m;
}

/* world -> the unit box of bounds p0..p1 in the medium's space */
static void set_unit_box(const lf_medium_desc *md, lf_medium *m, const double p0[3], const double p1[3])
{
    lf_transform t = lf_transform_translate(-p0[0], -p0[1], -p0[2]);
    lf_transform sc = lf_transform_scale(1 / (p1[0] - p0[0]), 1 / (p1[1] - p0[1]), 1 / (p1[2] - p0[2]));
    lf_transform unit_from_medium = lf_transform_compose(&sc, &t);
    lf_transform medium_from_world = lf_transform_inverse(&md->medium_to_world);
    m->world_to_unit = lf_transform_compose(&unit_from_medium, &medium_from_world);
    m->box0 = lf_v3((float)p0[0], (float)p0[1], (float)p0[2]);
    m->box_size = lf_v3((float)(p1[0] - p0[0]), (float)(p1[1] - p0[1]), (float)(p1[2] - p0[2]));
    m->hetero = 1;
}

/* The bounds, the grid size, g: what every heterogeneous medium has. */
static int read_common(lf_medium_desc *md, lf_medium *m, lf_error *err)
{
    lf_paramset *ps = &md->e.params;
    double p0[3] = {0, 0, 0}, p1[3] = {1, 1, 1};
    lf_params_point3(ps, "p0", p0);
    lf_params_point3(ps, "p1", p1);
    m->g = (float)lf_params_float(ps, "g", 0.0);
    if (!(m->g > -1 && m->g < 1))
        return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": \"g\" must be in (-1, 1)", md->name);
    for (int i = 0; i < 3; i++)
        if (!(p1[i] > p0[i]))
            return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": need p0 < p1 on every axis",
                               md->name);
    set_unit_box(md, m, p0, p1);
    return 0;
}

/* "uniformgrid" and "cloud": spectra sigma_a, sigma_s scaled by a density. */
static int read_density_medium(lf_medium_desc *md, lf_medium *m, int allow, lf_warnings *w, lf_error *err)
{
    lf_paramset *ps = &md->e.params;
    lf_vec3 sa, ss;
    lf_params_rgb(ps, "sigma_a", LF_SPECTRUM_UNBOUNDED, lf_v3(1, 1, 1), &sa);
    lf_params_rgb(ps, "sigma_s", LF_SPECTRUM_UNBOUNDED, lf_v3(1, 1, 1), &ss);
    float scale = m->kind == LF_MEDIUM_CLOUD ? 1.f : (float)lf_params_float(ps, "scale", 1.0);
    m->sigma_a = lf_scale(sa, scale), m->sigma_s = lf_scale(ss, scale);
    m->sigma_t = lf_add(m->sigma_a, m->sigma_s);
    float dmax = 1; /* the cloud's density is clamped to [0, 1] */
    if (m->kind == LF_MEDIUM_CLOUD) {
        m->cloud_density = (float)lf_params_float(ps, "density", 1.0);
        m->wispiness = (float)lf_params_float(ps, "wispiness", 1.0);
        m->frequency = (float)lf_params_float(ps, "frequency", 5.0);
        lf_medium_noise_init();
    } else {
        m->n[0] = lf_params_int(ps, "nx", 1), m->n[1] = lf_params_int(ps, "ny", 1), m->n[2] = lf_params_int(ps, "nz", 1);
        size_t n = (size_t)m->n[0] * m->n[1] * m->n[2];
        int bad = 0;
        if (m->n[0] < 1 || m->n[1] < 1 || m->n[2] < 1)
            return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": nx, ny, nz must be >= 1",
                               md->name);
        m->density = read_grid(ps, "density", LF_PT_FLOAT, 1, n, &bad);
        if (!m->density || bad)
            return lf_error_at(err, LF_ERR_PARAM, &md->e.loc,
                               "MakeNamedMedium \"%s\": \"float density\" needs nx*ny*nz = %zu finite values >= 0",
                               md->name, n);
        m->lescale = read_grid(ps, "Lescale", LF_PT_FLOAT, 1, n, &bad);
        if (bad)
            return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": \"Lescale\" needs %zu values",
                               md->name, n);
        dmax = grid_max(m->density, n, 1, 0);
        if (lf_params_peek(ps, "temperature")) {
            lf_params_find(ps, "temperature");
            lf_params_find(ps, "temperaturescale"), lf_params_find(ps, "temperatureoffset"),
                lf_params_find(ps, "temperaturecutoff");
            if (!allow)
                return lf_error_at(err, LF_ERR_UNSUPPORTED, &md->e.loc,
                                   "MakeNamedMedium \"%s\": blackbody \"temperature\" emission is not supported "
                                   "(--allow-unsupported renders the medium without it)",
                                   md->name);
            lf_warn_at(w, &md->e.loc, "MakeNamedMedium \"%s\": \"temperature\" emission is not supported; left out",
                       md->name);
        }
        lf_params_rgb(ps, "Le", LF_SPECTRUM_ILLUMINANT, lf_v3(0, 0, 0), &m->Le);
        m->emits = lf_maxc(m->Le) > 0;
    }
    m->majorant = dmax * lf_maxc(m->sigma_t);
    m->scatters = lf_maxc(m->sigma_s) > 0;
    return 0;
}

/* "rgbgrid": per-sample RGB sigma_a, sigma_s (default 1) and Le. */
static int read_rgb_medium(lf_medium_desc *md, lf_medium *m, lf_error *err)
{
    lf_paramset *ps = &md->e.params;
    m->n[0] = lf_params_int(ps, "nx", 1), m->n[1] = lf_params_int(ps, "ny", 1), m->n[2] = lf_params_int(ps, "nz", 1);
    if (m->n[0] < 1 || m->n[1] < 1 || m->n[2] < 1)
        return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": nx, ny, nz must be >= 1", md->name);
    size_t n = (size_t)m->n[0] * m->n[1] * m->n[2];
    int bad = 0;
    m->rgb_a = read_grid(ps, "sigma_a", LF_PT_RGB, 3, n, &bad);
    m->rgb_s = read_grid(ps, "sigma_s", LF_PT_RGB, 3, n, &bad);
    m->rgb_le = read_grid(ps, "Le", LF_PT_RGB, 3, n, &bad);
    if (bad || (!m->rgb_a && !m->rgb_s) || (m->rgb_le && !m->rgb_a))
        return lf_error_at(err, LF_ERR_PARAM, &md->e.loc,
                           "MakeNamedMedium \"%s\": \"rgbgrid\" needs \"rgb sigma_a\" and/or \"rgb sigma_s\" (and "
                           "sigma_a with \"rgb Le\"), nx*ny*nz = %zu finite values >= 0 each",
                           md->name, n);
    m->sigma_scale = (float)lf_params_float(ps, "scale", 1.0);
    m->le_scale = (float)lf_params_float(ps, "Lescale", 1.0);
    float maj = 0;
    for (int c = 0; c < 3; c++)
        maj = fmaxf(maj, (m->rgb_a ? grid_max(m->rgb_a, n, 3, c) : 1.f) + (m->rgb_s ? grid_max(m->rgb_s, n, 3, c) : 1.f));
    m->majorant = m->sigma_scale * maj;
    m->emits = m->rgb_le != NULL;
    m->scatters = 1;
    return 0;
}

/* "nanovdb": pbrt-v4's NanoVDBMedium: the float grid "gridname" (default
 * "density") of "filename" scales sigma_a and sigma_s (times "scale");
 * the bounds are the grid's.  A "temperature" grid's blackbody emission is
 * refused as for "uniformgrid". */
static int read_nanovdb_medium(const lf_scene_desc *d, lf_medium_desc *md, lf_medium *m, lf_warnings *w,
                               lf_error *err)
{
    lf_paramset *ps = &md->e.params;
    const char *fn = lf_params_string(ps, "filename", "");
    const char *gridname = lf_params_string(ps, "gridname", "density");
    const char *tname = lf_params_string(ps, "temperaturename", "temperature");
    lf_params_float(ps, "Lescale", 1.0);
    lf_params_float(ps, "temperatureoffset", 0.0), lf_params_float(ps, "temperaturecutoff", 0.0);
    lf_params_float(ps, "temperaturescale", 1.0);
    m->g = (float)lf_params_float(ps, "g", 0.0);
    lf_vec3 sa, ss;
    lf_params_rgb(ps, "sigma_a", LF_SPECTRUM_UNBOUNDED, lf_v3(1, 1, 1), &sa);
    lf_params_rgb(ps, "sigma_s", LF_SPECTRUM_UNBOUNDED, lf_v3(1, 1, 1), &ss);
    float scale = (float)lf_params_float(ps, "scale", 1.0);
    m->sigma_a = lf_scale(sa, scale), m->sigma_s = lf_scale(ss, scale), m->sigma_t = lf_add(m->sigma_a, m->sigma_s);
    if (!fn[0])
        return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": \"nanovdb\" needs \"string filename\"",
                           md->name);
    char path[4096], msg[512] = "";
    if (fn[0] == '/' || !d->scene_dir || !d->scene_dir[0])
        snprintf(path, sizeof path, "%s", fn);
    else
        snprintf(path, sizeof path, "%s/%s", d->scene_dir, fn);
    lf_nvdb *temp = NULL;
    if (lf_nvdb_open(path, gridname, &m->nvdb, msg, sizeof msg) || lf_nvdb_open(path, tname, &temp, msg, sizeof msg))
        return lf_error_at(err, LF_ERR_IO, &md->e.loc, "MakeNamedMedium \"%s\": %s", md->name, msg);
    if (!m->nvdb) {
        lf_nvdb_free(temp);
        return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": %s has no grid \"%s\"", md->name,
                           path, gridname);
    }
    if (temp) {
        lf_nvdb_free(temp);
        if (!d->allow_unsupported)
            return lf_error_at(err, LF_ERR_UNSUPPORTED, &md->e.loc,
                               "MakeNamedMedium \"%s\": blackbody \"temperature\" emission is not supported "
                               "(--allow-unsupported renders the medium without it)",
                               md->name);
        lf_warn_at(w, &md->e.loc, "MakeNamedMedium \"%s\": \"temperature\" emission is not supported; left out",
                   md->name);
    }
    double b0[3], b1[3];
    lf_nvdb_bounds(m->nvdb, b0, b1);
    for (int i = 0; i < 3; i++)
        if (!(b1[i] > b0[i])) /* an empty grid: a medium that does nothing */
            b0[i] = 0, b1[i] = 1;
    if (!(m->g > -1 && m->g < 1))
        return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": \"g\" must be in (-1, 1)", md->name);
    set_unit_box(md, m, b0, b1);
    m->majorant = lf_nvdb_max(m->nvdb) * lf_maxc(m->sigma_t);
    m->scatters = lf_maxc(m->sigma_s) > 0;
    return 0;
}

int lf_media_read_grid(const lf_scene_desc *d, lf_medium_desc *md, lf_medium *m, lf_warnings *w, lf_error *err)
{
    lf_paramset *ps = &md->e.params;
    const char *type = lf_params_string(ps, "type", "");
    if (!strcmp(type, "nanovdb")) {
        m->kind = LF_MEDIUM_NANOVDB;
        if (read_nanovdb_medium(d, md, m, w, err))
            return err->code;
        return ps->error.code ? lf_params_finish(ps, "MakeNamedMedium", err) : 0;
    }
    m->kind = !strcmp(type, "rgbgrid") ? LF_MEDIUM_RGBGRID : !strcmp(type, "cloud") ? LF_MEDIUM_CLOUD
                                                                                     : LF_MEDIUM_UNIFORMGRID;
    if (read_common(md, m, err))
        return err->code;
    int rc = m->kind == LF_MEDIUM_RGBGRID ? read_rgb_medium(md, m, err)
                                          : read_density_medium(md, m, d->allow_unsupported, w, err);
    if (rc)
        return rc;
    if (ps->error.code)
        return lf_params_finish(ps, "MakeNamedMedium", err);
    if (!isfinite(m->majorant) || m->majorant < 0)
        return lf_error_at(err, LF_ERR_PARAM, &md->e.loc, "MakeNamedMedium \"%s\": coefficients must be finite",
                           md->name);
    return 0;
}
