/* render_internal.h - the renderer's private headers at once (render/scene.h,
 * lights.h, media.h, integrator.h, disparity.h). */
#ifndef LF_RENDER_INTERNAL_H
#define LF_RENDER_INTERNAL_H

#include <stdint.h>

#include "base/lf_filter.h"
#include "camera/lf_camera.h"
#include "render/lf_render.h"
#include "render/integrator.h"
#include "render/lights.h"
#include "render/media.h"
#include "render/scene.h"
#include "render/disparity.h"

#endif
