/* lf_camera.h - the camera plugin interface (versioned C ABI).
 *
 * A camera turns a sample (film position, lens position, time, wavelength)
 * into a ray in CAMERA space: pbrt's convention, camera at the origin looking
 * along +z, +y up, +x to the right of the image as pbrt defines it (pbrt
 * is left-handed).  The host owns everything every camera shares, read once:
 * the camera-to-world transform (possibly animated), the shutter interval
 * ("shutteropen"/"shutterclose"), and the film.  A camera reads only its own
 * parameters, through the `lf_camera_params` table, so a camera compiled
 * elsewhere needs nothing from lensfield but this header.
 *
 * Built-in cameras are rows of a static table (camera/registry.c); a user's
 * camera is a shared object exporting
 *
 *     const lf_camera_type *const *lf_camera_plugin_types(int *count);
 *
 * loaded with `lfrender --camera-plugin path.so` into the same table.  See
 * docs/cameras.md and tests/plugin/example_camera.c for a complete plugin.
 *
 * generate_ray returns the ray's weight: 0 means "no ray" (e.g. vignetted by
 * the aperture), which is not an error.  It must never return NaN or Inf.
 * `needs` reports which sample dimensions the camera uses, so the renderer
 * draws only those: a pinhole camera never pays for lens samples.
 */
#ifndef LF_CAMERA_H
#define LF_CAMERA_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Version 2 appended the optional batch entry `generate_rays`; plugins built
 * against version 1 (whose type struct ends at `metadata`) still load. */
#define LF_CAMERA_ABI_VERSION 2u

enum lf_camera_needs {
    LF_CAMERA_NEEDS_LENS = 1u,       /* lens_u, lens_v are used */
    LF_CAMERA_NEEDS_TIME = 2u,       /* time_u is used (beyond the host's shutter) */
    LF_CAMERA_NEEDS_WAVELENGTH = 4u  /* wavelength_u is used (dispersion) */
};

/* The wavelength range of spectral camera rays, nm (the host's spectral
 * range: the renderer checks at build time that the two agree). */
#define LF_CAMERA_LAMBDA_MIN_NM 360.0
#define LF_CAMERA_LAMBDA_MAX_NM 830.0

typedef struct lf_camera_sample {
    double film_x, film_y; /* raster position in pixels; (0,0) is the top-left corner of the full image */
    double lens_u, lens_v; /* in [0,1)^2; 0.5 when the camera does not need them */
    double time;           /* scene time chosen by the host within the shutter interval */
    double wavelength_u;   /* in [0,1); 0.5 when not needed */
} lf_camera_sample;

typedef struct lf_camera_ray {
    double origin[3];      /* camera space */
    double dir[3];         /* camera space, unit length */
    double time;           /* scene time; the host sets it from the sample before the call */
    double wavelength_nm;  /* 0 unless the camera needs wavelength; then a camera sets
                            * LF_CAMERA_LAMBDA_MIN_NM + wavelength_u (LF_CAMERA_LAMBDA_MAX_NM -
                            * LF_CAMERA_LAMBDA_MIN_NM) nm (360..830, uniform) and the host
                            * weights the ray's RGB radiance by that wavelength's sRGB
                            * response */
} lf_camera_ray;

/* Read access to the camera's own parameters in the scene file.  Every
 * lookup marks the parameter used; parameters no camera reads are errors
 * reported by the host with their file:line:column.  A lookup with the wrong
 * type (an "integer" read as float, say) is recorded as an error too. */
typedef struct lf_camera_params {
    void *ctx;
    double (*get_float)(void *ctx, const char *name, double def);
    int (*get_int)(void *ctx, const char *name, int def);
    int (*get_bool)(void *ctx, const char *name, int def);
    const char *(*get_string)(void *ctx, const char *name, const char *def);
    /* Array of floats (any numeric declared type): copies up to max values,
     * returns how many the parameter has (0 if absent). */
    int (*get_floats)(void *ctx, const char *name, double *out, int max);
    /* Loads an image (e.g. an aperture mask) as one linear grey channel (the
     * mean of its colour channels), row 0 at the top.  Relative paths are
     * resolved against the scene file's directory.  *pixels is malloc'ed;
     * the camera frees it with free().  Returns 0, or -1 with a message. */
    int (*load_image)(void *ctx, const char *path, int *width, int *height, float **pixels, char *err,
                      size_t err_size);
} lf_camera_params;

typedef struct lf_camera_create_args {
    uint32_t struct_size;           /* sizeof(lf_camera_create_args) of the host */
    const lf_camera_params *params;
    int image_width, image_height;  /* full film resolution in pixels */
    double film_diagonal_mm;        /* Film "diagonal" (pbrt default 35 mm) */
    double shutter_open, shutter_close;
    const char *scene_dir;          /* directory of the scene file, for lens files etc. */
    char *error;                    /* create writes its message here on failure */
    size_t error_size;
    char *warning;                  /* and non-fatal notes here (may stay empty) */
    size_t warning_size;
} lf_camera_create_args;

/* Where a camera writes the attributes that describe its image (the
 * renderer stores them in the EXR header).  Names should be
 * "lensfield:<key>"; light-field cameras describe their full layout here so
 * that lftool needs nothing else (docs/lightfield-format.md). */
typedef struct lf_camera_attr_sink {
    void *ctx;
    void (*set_string)(void *ctx, const char *name, const char *value);
    void (*set_int)(void *ctx, const char *name, int value);
    void (*set_double)(void *ctx, const char *name, double value);
    void (*set_doubles)(void *ctx, const char *name, const double *values, int n);
} lf_camera_attr_sink;

typedef struct lf_camera_type {
    uint32_t abi_version; /* LF_CAMERA_ABI_VERSION */
    const char *name;     /* the Camera "name" in scene files */
    /* Returns 0 and sets *state, or non-zero with args->error filled. */
    int (*create)(const lf_camera_create_args *args, void **state);
    /* Which sample dimensions this configured camera uses (LF_CAMERA_NEEDS_*). */
    uint32_t (*needs)(const void *state);
    /* Fills *ray (camera space) and returns its weight; 0 = no ray. */
    double (*generate_ray)(const void *state, const lf_camera_sample *sample, lf_camera_ray *ray);
    void (*destroy)(void *state);
    /* Optional (may be NULL): human-readable description for --explain,
     * one fact per line.  Returns the number of characters written. */
    int (*describe)(const void *state, char *buf, size_t size);
    /* Optional (may be NULL): attributes describing the image layout. */
    void (*metadata)(const void *state, const lf_camera_attr_sink *sink);
    /* ---- ABI version 2 ---- */
    /* Optional (may be NULL): n rays at once.  For every i it must give
     * exactly what weights[i] = generate_ray(state, &samples[i], &rays[i])
     * gives (the host presets rays[i].time and rays[i].wavelength_nm = 0).
     * n is any positive number; a camera chunks internally.  Cameras
     * implement it to generate independent rays side by side (structure of
     * arrays, SIMD), which hides the latency of each ray's serial chain of
     * square roots and divisions. */
    void (*generate_rays)(const void *state, int n, const lf_camera_sample *samples, lf_camera_ray *rays,
                          double *weights);
} lf_camera_type;

/* ---- registry (camera/registry.c) ----
 * Thread safety: lookups may run on any thread at any time; loading a
 * plugin is serialised internally and publishes its types atomically, so a
 * lookup sees the table before or after a load, never half of it.  Types,
 * once registered, stay registered for the life of the process. */

/* Finds a camera type by name among built-ins and loaded plugins. */
const lf_camera_type *lf_camera_find(const char *name);
/* Number of registered types and the i-th one (for tests that loop over all). */
int lf_camera_count(void);
const lf_camera_type *lf_camera_at(int i);
/* n rays through t's generate_rays, or generate_ray in a loop when the
 * camera has no batch entry (the host's one way to call a camera). */
void lf_camera_generate_rays(const lf_camera_type *t, const void *state, int n, const lf_camera_sample *samples,
                             lf_camera_ray *rays, double *weights);
/* Loads a plugin shared object and registers its types.  Returns 0, or -1
 * with a message in err (wrong ABI version, missing symbol, name clash).
 * Types of ABI version 1 are accepted (copied into a version-2 record
 * without the batch entry). */
int lf_camera_load_plugin(const char *path, char *err, size_t err_size);

#ifdef __cplusplus
}
#endif
#endif
