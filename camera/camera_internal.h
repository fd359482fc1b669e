/* Private helpers shared by the built-in cameras. */
#ifndef LF_CAMERA_INTERNAL_H
#define LF_CAMERA_INTERNAL_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/lf_error.h"
#include "base/lf_math.h"
#include "lf_camera.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Batch kernels (generate_rays) are compiled twice on x86-64 with GCC: for
 * CPUs with AVX2 (four doubles per instruction; FMA is not needed, as ISO C
 * does not contract) and for the baseline; the loader picks one at start-up
 * (GNU ifunc, by CPU feature: "arch=haswell" would dispatch by CPU model
 * and leave AMD processors on the baseline).  Kernels copy the
 * samples of a chunk into padded structure-of-arrays buffers and loop over
 * the whole fixed-size chunk, so the compiler vectorises the loops even at
 * -O2's cheap cost model. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(__SANITIZE_ADDRESS__)
#define LF_CAM_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LF_CAM_SIMD_CLONES
#endif
enum { LF_CAM_CHUNK = 32 }; /* rays per batch-kernel chunk */

/* A batch kernel's first step: the chunk's n samples as structure of
 * arrays, padded to LF_CAM_CHUNK by repeating the first sample. */
static inline __attribute__((always_inline)) void lf_cam_stage_samples(int n, const lf_camera_sample *restrict s, double *restrict fx,
                                        double *restrict fy, double *restrict lu, double *restrict lv)
{
    for (int i = 0; i < LF_CAM_CHUNK; i++) {
        int k = i < n ? i : 0;
        fx[i] = s[k].film_x, fy[i] = s[k].film_y, lu[i] = s[k].lens_u, lv[i] = s[k].lens_v;
    }
}

/* generate_rays for a camera whose kernel takes up to LF_CAM_CHUNK rays. */
typedef void (*lf_cam_chunk_fn)(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r, double *w);
static inline void lf_cam_chunks(lf_cam_chunk_fn chunk, const void *state, int n, const lf_camera_sample *s,
                                 lf_camera_ray *r, double *w)
{
    for (int i = 0; i < n; i += LF_CAM_CHUNK)
        chunk(state, n - i < LF_CAM_CHUNK ? n - i : LF_CAM_CHUNK, s + i, r + i, w + i);
}

/* A library's lf_error into a create call's message buffer: the one place
 * where the built-in cameras meet the plugin ABI's char buffers
 * (lf_camera.h); everything below create reports into an lf_error.
 * Returns rc. */
static inline int lf_cam_error(int rc, const lf_error *e, char *buf, size_t size)
{
    if (rc && buf && size)
        snprintf(buf, size, "%s", e->msg);
    return rc;
}

/* The ABI's create calls keep their warnings as text in a char buffer; a
 * library's lf_warnings (given without a place) reach it one message at a
 * time: copies the message at *t into msg without the "warning: " and the
 * newline of the channel's lines, and advances *t.  0 when none is left.
 *   for (const char *t = lf_warnings_text(&w); lf_cam_next_warning(&t, msg, sizeof msg);) ... */
static inline int lf_cam_next_warning(const char **t, char *msg, size_t size)
{
    static const char prefix[] = "warning: ";
    if (!*t || !**t)
        return 0;
    const char *nl = strchr(*t, '\n');
    size_t len = nl ? (size_t)(nl - *t) : strlen(*t);
    size_t skip = strncmp(*t, prefix, sizeof prefix - 1) == 0 ? sizeof prefix - 1 : 0;
    snprintf(msg, size, "%.*s", (int)(len - skip), *t + skip);
    *t += nl ? len + 1 : len;
    return 1;
}

/* "string sensor" (named format) or "float sensorsize" [w h] mm; default
 * full frame; name receives the format's name ("custom" for a size).
 * Returns 0, or LF_ERR_PARAM with the message in err. (camera/sensor.c) */
int lf_cam_read_sensor(const lf_camera_params *p, double *w_mm, double *h_mm, char *name, size_t name_size,
                       lf_error *err);

/* For describe(): appends to buf (size bytes) with snprintf semantics; the
 * caller's int n stays the would-be length. */
#define LF_CAM_APPEND(...)                                           \
    do {                                                             \
        size_t off_ = (size_t)n < size ? (size_t)n : size;           \
        int k_ = snprintf(buf + off_, size - off_, __VA_ARGS__);     \
        if (k_ > 0)                                                  \
            n += k_;                                                 \
    } while (0)

extern const lf_camera_type lf_camera_perspective;
extern const lf_camera_type lf_camera_orthographic;
extern const lf_camera_type lf_camera_thinlens;
extern const lf_camera_type lf_camera_realistic;
extern const lf_camera_type lf_camera_fisheye;
extern const lf_camera_type lf_camera_lightfield;
extern const lf_camera_type lf_camera_plenoptic;
extern const lf_camera_type lf_camera_spherical;

#endif
