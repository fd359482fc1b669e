/* media.h - participating media (render/ only): the homogeneous media of
 * MakeNamedMedium, read into the scene by render/media.c. */
#ifndef LF_RENDER_MEDIA_H
#define LF_RENDER_MEDIA_H

#include "render/scene.h"

#include <stdint.h>

enum { LF_MEDIUM_HOMOGENEOUS, LF_MEDIUM_UNIFORMGRID, LF_MEDIUM_RGBGRID, LF_MEDIUM_CLOUD, LF_MEDIUM_NANOVDB };

struct lf_nvdb;

/* A participating medium, per RGB channel, "scale" applied: homogeneous
 * (pbrt-v4 "homogeneous"), or heterogeneous inside its bounds
 * (render/media_grid.c: "uniformgrid", "rgbgrid", "cloud", "nanovdb"). */
struct lf_medium {
    int kind;            /* LF_MEDIUM_* */
    int hetero;          /* kind != homogeneous: null-collision tracking */
    lf_vec3 sigma_a, sigma_s, sigma_t; /* homogeneous; uniformgrid and cloud: at density 1 */
    lf_vec3 Le;          /* emitted radiance, Lescale applied; emission is sigma_a Le per unit length */
    float g;             /* Henyey-Greenstein asymmetry */
    int scatters;        /* sigma_s > 0 in some channel */
    int emits;           /* sigma_a Le > 0 in some channel (grids: Le given) */
    /* heterogeneous media */
    lf_transform world_to_unit; /* world -> the unit box of the bounds p0..p1 in medium space */
    int n[3];            /* grid samples nx, ny, nz */
    float *density;      /* uniformgrid: n[0] n[1] n[2] values */
    float *lescale;      /* uniformgrid: "Lescale" grid, or NULL (the constant Le) */
    float *rgb_a, *rgb_s, *rgb_le; /* rgbgrid: 3 per sample, NULL when not given (sigma: 1, Le: 0) */
    float sigma_scale, le_scale;   /* rgbgrid "scale", "Lescale" */
    float cloud_density, wispiness, frequency; /* cloud */
    struct lf_nvdb *nvdb;  /* nanovdb: the density grid (render/nanovdb_adapter.h) */
    lf_vec3 box0, box_size; /* nanovdb: the grid's bounds in medium space (unit box -> grid space) */
    float majorant;      /* the largest sigma_t of any channel anywhere in the medium */
};

/* Reads the MakeNamedMedium directives into s->media (grid media are
 * refused with their location). */
int lf_media_build(lf_scene_desc *d, lf_scene *s, lf_error *err);
/* Index of a named medium: -1 for NULL or "" (vacuum); an unknown name is
 * an error naming loc. */
int lf_media_lookup(const lf_scene_desc *d, const char *name, const lf_loc *loc, const char *what, int *index,
                    lf_error *err);

/* Heterogeneous media (render/media_grid.c). */
int lf_media_read_grid(const lf_scene_desc *d, lf_medium_desc *md, lf_medium *m, lf_warnings *w, lf_error *err);
void lf_media_free(lf_scene *s);
void lf_medium_noise_init(void);
/* sigma_a, sigma_s and Le at unit-box point u. */
void lf_medium_point(const lf_medium *m, lf_vec3 u, lf_vec3 *sa, lf_vec3 *ss, lf_vec3 *Le);
/* A seed for the tracking's random numbers along one segment. */
uint64_t lf_medium_seed(float u0, float u1, lf_vec3 o, lf_vec3 d);
/* Delta tracking from o along unit d up to t_s: -1 absorbed (the path
 * ends), 0 reached t_s, 1 scattered at *t_event; beta is weighted, the
 * emission met on the way is added to *L (may be NULL). */
int lf_medium_track(const lf_medium *m, lf_vec3 o, lf_vec3 d, float t_s, uint64_t seed, lf_vec3 *beta, lf_vec3 *L,
                    float *t_event);
/* Ratio-tracking transmittance from o along unit d over tmax. */
lf_vec3 lf_medium_tr(const lf_medium *m, lf_vec3 o, lf_vec3 d, float tmax, uint64_t seed);

/* A Henyey-Greenstein direction around the travel direction d (pbrt-v4's
 * SampleHenyeyGreenstein, render/volpath.c); the phase function is its own
 * pdf, so a walk that samples it carries weight 1. */
lf_vec3 lf_hg_direction(float g, lf_vec3 d, float u0, float u1);

#endif
