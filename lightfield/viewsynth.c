/* Depth-based view synthesis (lf_depth.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_depth.h"
#include "parallel_internal.h"

lf_lf_view_opts lf_lf_view_defaults(void)
{
    lf_lf_view_opts o;
    memset(&o, 0, sizeof o);
    o.depth = lf_lf_depth_defaults();
    return o;
}

int lf_lf_view_depth(const lf_lightfield *lf, double u, double v, const lf_lf_view_opts *o, lf_image *out,
                     lf_error *err)
{
    return lf_lf_view_at(lf, u, v, o ? o->plane_disparity : 0, out, err);
}
