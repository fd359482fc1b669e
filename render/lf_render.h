/* lf_render.h - the host renderer: scene description in, image out.
 *
 *   lf_scene_desc desc;               // from lf_scene_parse_file()
 *   lf_render_opts o = lf_render_opts_default();
 *   lf_renderer *r;
 *   if (lf_renderer_create(&desc, &o, &r, &err)) ...   // builds everything, checks every parameter
 *   char *plan = lf_renderer_explain(r);               // the effect plan (--explain)
 *   lf_image img; lf_attrs meta = {0};
 *   lf_renderer_render(r, &img, &meta, &err);          // linear radiance + lensfield:* metadata
 *   lf_renderer_free(r);
 *
 * Rendering is deterministic for a seed: every sample is a function of
 * (seed, pixel, sample index) and every pixel is accumulated by one thread in
 * sample order, so the thread count never changes a bit of the result.
 */
#ifndef LF_RENDER_H
#define LF_RENDER_H

#include <stdint.h>

#include "base/lf_error.h"
#include "image/lf_image.h"
#include "scenefile/lf_scene_desc.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef void (*lf_progress_fn)(void *ctx, long done, long total);

typedef struct lf_render_opts {
    int spp;              /* 0: the Sampler's "pixelsamples" */
    int threads;          /* 0: all cores */
    uint32_t seed;        /* used when has_seed; otherwise the Sampler's "seed" */
    int has_seed;
    int crop[4];          /* pixel bounds x0 x1 y0 y1 (half-open); crop[1] <= crop[0]: none */
    lf_progress_fn progress;
    void *progress_ctx;
    const char *scene_path; /* for metadata and the camera's scene_dir */
    /* Splitting and fault tolerance (docs/distributed.md) */
    int spp_begin, spp_end; /* render only sample indices [begin, end); end 0: all */
    int tile_index, tile_count; /* render only row band tile_index of tile_count; count 0: all */
    int part;             /* output a mergeable part: RGB preview + exact accumulator channels */
    const char *checkpoint_path; /* write the film here atomically every checkpoint_every s */
    double checkpoint_every;
    int resume;           /* continue from checkpoint_path (same scene and settings) */
    volatile int *stop;   /* set non-zero (e.g. from a signal handler) to stop after the tiles
                           * in flight, write a final checkpoint and return LF_ERR_INTERRUPTED */
    int white;            /* render the white image: the camera and film of the scene looking at
                           * a uniform environment of radiance 1 and nothing else (flat field for
                           * devignetting and light-field calibration) */
} lf_render_opts;

lf_render_opts lf_render_opts_default(void);

typedef struct lf_renderer lf_renderer;

/* Builds the camera, film, sampler, materials, lights and the Embree scene.
 * Every parameter the scene wrote must be read by someone, or this fails
 * with the file:line:col of the first unused one. */
int lf_renderer_create(lf_scene_desc *desc, const lf_render_opts *opts, lf_renderer **out, lf_error *err);
/* Replaces the run-time options (checkpointing, stop flag, progress) before
 * rendering; scene-shaping options (crop, tiles, sample range, spp, seed,
 * white) keep the values given at create. */
void lf_renderer_set_opts(lf_renderer *r, const lf_render_opts *opts);
/* Non-fatal notes gathered while building ("file:line:col: warning: ..."), or NULL. */
const char *lf_renderer_warnings(const lf_renderer *r);
/* The effect plan: camera model, which effects are simulated and why.
 * malloc'ed; NULL when memory runs out. */
char *lf_renderer_explain(const lf_renderer *r);
/* Renders into *img (allocated here; the crop window's size) and fills meta
 * with lensfield:* attributes.  Samples whose radiance is NaN/Inf are
 * dropped and counted (lensfield:nonfinite_samples, lf_renderer_stats). */
int lf_renderer_render(lf_renderer *r, lf_image *img, lf_attrs *meta, lf_error *err);
/* Ground-truth disparity AOV of a light-field camera (docs/lightfield-format.md,
 * "Disparity AOV"): one channel, the crop window's size; per pixel the
 * disparity (px per view step) of the first surface hit by the centre-view
 * ray of the pixel's view (camera array: its data camera's ray through the
 * pixel centre; plenoptic: the chief ray of the pixel's microlens), at the
 * shutter's opening.  No hit: the disparity at infinity.  LF_ERR_PARAM for
 * cameras that are not light-field cameras. */
int lf_renderer_disparity(lf_renderer *r, lf_image *out, lf_error *err);
/* Merges part files written with opts.part (sample ranges and/or row bands
 * of the same scene and settings) into the image an unsplit render gives,
 * bit for bit: parts carry exact fixed-point sums.  Checks that the parts
 * agree and that every pixel gets every sample exactly once. */
int lf_render_merge(const char *const *paths, int n, lf_image *out, lf_attrs *meta, lf_error *err);

/* The disparity AOV (lf_renderer_disparity) as OUT.disparity.exr beside
 * OUT.exr (path ends in ".exr"): 1 channel, 32-bit float, meta's
 * attributes plus lensfield:aov.  meta (OUT's header) gets
 * lensfield:disparity_file naming it and lensfield:disparity_range.
 * written (may be NULL, path_size bytes) gets the file's path, range[2]
 * the values' range. */
int lf_render_write_disparity(lf_renderer *r, const char *path, lf_attrs *meta, char *written, size_t written_size,
                              float range[2], lf_error *err);

/* Output path requested by the Film's "filename" (pbrt default "pbrt.exr"). */
const char *lf_renderer_film_filename(const lf_renderer *r);
/* Film "raw": the sensor that turns the rendered film into a mosaic
 * (render/lf_sensor.h; lfrender applies it after the render, and merge
 * after summing the parts); NULL for Film "rgb". */
struct lf_sensor;
const struct lf_sensor *lf_renderer_sensor(const lf_renderer *r);
/* Film "savefp16" (pbrt default true): store EXR channels as half floats. */
int lf_renderer_film_half(const lf_renderer *r);

typedef struct lf_render_stats {
    long long camera_paths;      /* samples traced */
    long long rays;              /* all rays (camera, bounce, shadow) */
    long long nonfinite_samples; /* dropped NaN/Inf samples */
    long long zero_weight_camera_rays;
    double seconds;
} lf_render_stats;
lf_render_stats lf_renderer_stats(const lf_renderer *r);
void lf_renderer_free(lf_renderer *r);

#ifdef __cplusplus
}
#endif
#endif
