/* noise.c - Perlin's improved gradient noise and its fractal sums, as
 * pbrt-v4 defines them (util/noise.cpp; Perlin, "Improving Noise",
 * SIGGRAPH 2002): the textures fbm, wrinkled, windy, marble and dots are
 * built on these, so their patterns match pbrt's for the same scene.
 *
 * Without ray differentials a lookup has no filter footprint, so the
 * octave count is always the texture's maximum (pbrt's n = octaves when
 * dp/dx = dp/dy = 0). */
#include "lf_shading.h"

#include <math.h>

/* Perlin's reference permutation of 0..255 (from the 2002 paper's Java
 * code), indexed modulo 256 through a doubled lookup. */
static const unsigned char perm[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,  69,  142,
    8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,  94,  252, 219, 203,
    117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165,
    71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,
    55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,
    18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250,
    124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189,
    28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,
    129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,
    242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,
    181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114,
    67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180};

static int P(int i) { return perm[i & 255]; }

/* The dot product of lattice point (x, y, z)'s gradient, one of the 12
 * cube-edge directions picked by the hash's low 4 bits, with (dx, dy, dz). */
static float grad(int x, int y, int z, float dx, float dy, float dz)
{
    int h = P(P(P(x) + y) + z) & 15;
    float u = (h < 8 || h == 12 || h == 13) ? dx : dy;
    float v = (h < 4 || h == 12 || h == 13) ? dy : dz;
    return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

/* 6t^5 - 15t^4 + 10t^3: C2 at the lattice, Perlin's improvement over 3t^2 - 2t^3. */
static float fade(float t) { return t * t * t * (t * (t * 6.f - 15.f) + 10.f); }

float lf_noise3(lf_vec3 p)
{
    /* Keep the cell index within int range (pbrt reduces modulo 2^30). */
    float x = fmodf(p.x, 1073741824.f), y = fmodf(p.y, 1073741824.f), z = fmodf(p.z, 1073741824.f);
    float fx = floorf(x), fy = floorf(y), fz = floorf(z);
    int ix = (int)fx & 255, iy = (int)fy & 255, iz = (int)fz & 255;
    float dx = x - fx, dy = y - fy, dz = z - fz;
    float w[8];
    for (int c = 0; c < 8; c++) {
        int ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
        w[c] = grad(ix + ox, iy + oy, iz + oz, dx - (float)ox, dy - (float)oy, dz - (float)oz);
    }
    float wx = fade(dx), wy = fade(dy), wz = fade(dz);
    float x00 = lf_lerpf(wx, w[0], w[1]), x10 = lf_lerpf(wx, w[2], w[3]);
    float x01 = lf_lerpf(wx, w[4], w[5]), x11 = lf_lerpf(wx, w[6], w[7]);
    return lf_lerpf(wz, lf_lerpf(wy, x00, x10), lf_lerpf(wy, x01, x11));
}

/* Octave i samples noise at 1.99^i p (pbrt's lacunarity, just under 2 so
 * octaves' lattices do not line up) with weight omega^i. */
float lf_fbm(lf_vec3 p, float omega, int octaves)
{
    float sum = 0.f, lambda = 1.f, o = 1.f;
    for (int i = 0; i < octaves; i++) {
        sum += o * lf_noise3(lf_scale(p, lambda));
        lambda *= 1.99f;
        o *= omega;
    }
    return sum;
}

/* |noise| summed as fbm, plus pbrt's 0.2 omega^octaves for the clamped
 * partial octave (its average |noise|). */
float lf_turbulence(lf_vec3 p, float omega, int octaves)
{
    float sum = 0.f, lambda = 1.f, o = 1.f;
    for (int i = 0; i < octaves; i++) {
        sum += o * fabsf(lf_noise3(lf_scale(p, lambda)));
        lambda *= 1.99f;
        o *= omega;
    }
    return sum + o * 0.2f;
}
