/* integrator_params.h - the parameters of pbrt-v4's integrators that
 * lensfield renders with its path tracer (bdpt, mlt, sppm, lightpath,
 * randomwalk, simplepath, simplevolpath): read with pbrt-v4's names and
 * types, so a scene written for them is not refused for an unused
 * parameter, and a mistyped value is still an error. */
#ifndef LF_RENDER_INTEGRATOR_PARAMS_H
#define LF_RENDER_INTEGRATOR_PARAMS_H

#include "base/lf_params.h"

/* Marks type's own parameters (beyond maxdepth, regularize and
 * lightsampler, which the path tracer reads) as read.  Returns how many of
 * them the scene gave, for the note that says they are not used. */
int lf_integrator_accept_params(const char *type, lf_paramset *ps);

#endif
