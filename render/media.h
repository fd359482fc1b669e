/* media.h - participating media (render/ only): the homogeneous media of
 * MakeNamedMedium, read into the scene by render/media.c. */
#ifndef LF_RENDER_MEDIA_H
#define LF_RENDER_MEDIA_H

#include "render/scene.h"

/* A homogeneous participating medium (pbrt-v4 "homogeneous"), per RGB
 * channel, "scale" applied. */
struct lf_medium {
    lf_vec3 sigma_a, sigma_s, sigma_t;
    lf_vec3 Le;          /* emitted radiance, Lescale applied; emission is sigma_a Le per unit length */
    float g;             /* Henyey-Greenstein asymmetry */
    int scatters;        /* sigma_s > 0 in some channel */
    int emits;           /* sigma_a Le > 0 in some channel */
};

/* Reads the MakeNamedMedium directives into s->media (grid media are
 * refused with their location). */
int lf_media_build(lf_scene_desc *d, lf_scene *s, lf_error *err);
/* Index of a named medium: -1 for NULL or "" (vacuum); an unknown name is
 * an error naming loc. */
int lf_media_lookup(const lf_scene_desc *d, const char *name, const lf_loc *loc, const char *what, int *index,
                    lf_error *err);

#endif
