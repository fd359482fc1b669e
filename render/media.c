/* Homogeneous participating media, read from the scene (pbrt-v4
 * semantics; the integrator that renders them is render/volpath.c):
 * MakeNamedMedium "name" "string type"
 * "homogeneous" with "spectrum sigma_a" and "sigma_s" (per unit length,
 * default 1 each), "float scale" multiplying both, "float g" (Henyey-
 * Greenstein asymmetry), "spectrum Le" with "float Lescale" (emission
 * sigma_a Le per unit length).  MediumInterface "inside" "outside" binds
 * media to the shapes that follow (a ray crossing one leaves for the side
 * its direction points to: outside along the surface normal); the camera
 * starts its rays in the exterior medium current when Camera was declared.
 * Heterogeneous media ("uniformgrid", "rgbgrid", "cloud", "nanovdb") are
 * read by render/media_grid.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/media.h"

int lf_media_lookup(const lf_scene_desc *d, const char *name, const lf_loc *loc, const char *what, int *index,
                    lf_error *err)
{
    *index = -1;
    if (!name || !name[0])
        return 0;
    for (size_t i = 0; i < d->n_media; i++)
        if (!strcmp(d->media[i].name, name)) {
            *index = (int)i;
            return 0;
        }
    return lf_error_at(err, LF_ERR_PARAM, loc, "%s: no medium named \"%s\" (MakeNamedMedium)", what, name);
}

int lf_media_build(lf_scene_desc *d, lf_scene *s, lf_error *err)
{
    s->camera_medium = -1;
    if (!d->n_media)
        return 0;
    s->media = calloc(d->n_media, sizeof *s->media);
    if (!s->media)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    s->n_media = (int)d->n_media;
    for (size_t i = 0; i < d->n_media; i++) {
        lf_medium_desc *md = &d->media[i];
        lf_paramset *ps = &md->e.params;
        const lf_loc *l = &md->e.loc;
        const char *type = lf_params_string(ps, "type", "");
        if (!strcmp(type, "uniformgrid") || !strcmp(type, "rgbgrid") || !strcmp(type, "cloud") ||
            !strcmp(type, "nanovdb")) {
            if (lf_media_read_grid(d, md, &s->media[i], &s->warnings, err))
                return err->code;
            char ctx[300];
            snprintf(ctx, sizeof ctx, "MakeNamedMedium \"%s\"", md->name);
            if (lf_params_finish(ps, ctx, err))
                return err->code;
            continue;
        }
        if (strcmp(type, "homogeneous"))
            return lf_error_at(err, LF_ERR_PARAM, l,
                               "MakeNamedMedium \"%s\": unknown or missing \"string type\" \"%s\" (pbrt-v4 "
                               "has \"homogeneous\", \"uniformgrid\", \"rgbgrid\", \"cloud\", \"nanovdb\")",
                               md->name, type);
        if (lf_params_peek(ps, "preset"))
            return lf_error_at(err, LF_ERR_UNSUPPORTED, l,
                               "MakeNamedMedium \"%s\": \"string preset\" (measured scattering tables) is "
                               "not supported; give \"sigma_a\" and \"sigma_s\"",
                               md->name);
        lf_medium *m = &s->media[i];
        lf_vec3 sa, ss, Le;
        lf_params_rgb(ps, "sigma_a", LF_SPECTRUM_UNBOUNDED, lf_v3(1, 1, 1), &sa);
        lf_params_rgb(ps, "sigma_s", LF_SPECTRUM_UNBOUNDED, lf_v3(1, 1, 1), &ss);
        lf_params_rgb(ps, "Le", LF_SPECTRUM_ILLUMINANT, lf_v3(0, 0, 0), &Le);
        float scale = (float)lf_params_float(ps, "scale", 1.0);
        float lescale = (float)lf_params_float(ps, "Lescale", 1.0);
        m->g = (float)lf_params_float(ps, "g", 0.0);
        m->sigma_a = lf_scale(sa, scale);
        m->sigma_s = lf_scale(ss, scale);
        m->sigma_t = lf_add(m->sigma_a, m->sigma_s);
        m->Le = lf_scale(Le, lescale);
        float v[9] = {m->sigma_a.x, m->sigma_a.y, m->sigma_a.z, m->sigma_s.x, m->sigma_s.y,
                      m->sigma_s.z, m->Le.x,      m->Le.y,      m->Le.z};
        for (int k = 0; k < 9; k++)
            if (!(v[k] >= 0) || !isfinite(v[k]))
                return lf_error_at(err, LF_ERR_PARAM, l,
                                   "MakeNamedMedium \"%s\": sigma_a, sigma_s (times scale) and Le must be "
                                   "finite and >= 0",
                                   md->name);
        if (!(m->g > -1 && m->g < 1))
            return lf_error_at(err, LF_ERR_PARAM, l, "MakeNamedMedium \"%s\": \"g\" must be in (-1, 1), got %g",
                               md->name, m->g);
        m->scatters = lf_maxc(m->sigma_s) > 0;
        m->emits = lf_maxc(lf_mul(m->sigma_a, m->Le)) > 0;
        char ctx[300];
        snprintf(ctx, sizeof ctx, "MakeNamedMedium \"%s\"", md->name);
        if (lf_params_finish(ps, ctx, err))
            return err->code;
    }
    return 0;
}
