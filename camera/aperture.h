/* aperture.h - aperture (bokeh) shapes shared by the lens cameras (private
 * to camera/).
 *
 * An aperture is a region of the lens plane in units of the aperture radius:
 * it fits in the unit disk (polygons have their corners on the unit circle,
 * images fill [-1,1]^2 and are cropped to nothing else), then x is scaled by
 * the anamorphic ratio.  Sampling is unbiased: points are uniform over the
 * open region (or distributed by image transmission), and the returned
 * weight makes E[weight * g(p)] equal the integral of g over the region
 * (times transmission) divided by lf_aperture_area(), so a camera multiplies
 * by the true area where it needs radiometry.
 *
 * Scene parameters (read by lf_aperture_parse, all optional):
 *   "string aperture"  "circular" (default) | "polygon" | "square" | "pentagon"
 *                      | "star" | an image file name (grayscale transmission)
 *   "integer blades"   polygon blade count (default 6; square 4, pentagon 5)
 *   "float aperturerotation"  degrees (default 0)
 *   "float anamorphic" horizontal stretch of the aperture (default 1)
 */
#ifndef LF_APERTURE_H
#define LF_APERTURE_H

#include <stddef.h>

#include "base/lf_distrib.h"
#include "camera_internal.h"
#include "lf_camera.h"

typedef enum lf_aperture_kind {
    LF_APERTURE_CIRCLE,
    LF_APERTURE_POLYGON,
    LF_APERTURE_STAR,
    LF_APERTURE_IMAGE
} lf_aperture_kind;

typedef struct lf_aperture {
    lf_aperture_kind kind;
    int blades;
    double rotation_rad;
    double anamorphic;
    /* image apertures */
    int img_w, img_h;
    float *img;
    lf_distrib2d distrib;
    double area; /* open area in radius^2 units, including anamorphic and transmission */
    /* polygons and stars: the outline's vertices (x, y), closed (the first
     * repeated at the end), so sampling needs no trigonometry */
    double (*corners)[2];
} lf_aperture;

/* Reads the parameters above.  Returns 0, or an LF_ERR_* status with the
 * message in err (e.g. an all-black image). */
int lf_aperture_parse(const lf_camera_params *p, lf_aperture *a, lf_error *err);
/* u, v in [0,1); returns the weight (0: no point), fills (x, y) in radius units. */
double lf_aperture_sample(const lf_aperture *a, double u, double v, double *x, double *y);
/* A batch kernel's lens points: lf_aperture_sample for the first n of a
 * padded chunk of N samples (the rest get weight 0).  The circle is
 * written branch-free over the whole chunk, so it vectorises when inlined
 * into a kernel; other shapes sample one by one. */
static inline __attribute__((always_inline)) void lf_aperture_sample_chunk(const lf_aperture *a, int n, int N, const double *restrict u,
                                            const double *restrict v, double *restrict x, double *restrict y,
                                            double *restrict w)
{
    if (a->kind == LF_APERTURE_CIRCLE) {
        const double ana = a->anamorphic;
        for (int i = 0; i < N; i++) {
            lf_concentric_disk(u[i], v[i], &x[i], &y[i]);
            x[i] *= ana;
            w[i] = 1.0;
        }
        return;
    }
    for (int i = 0; i < n; i++)
        w[i] = lf_aperture_sample(a, u[i], v[i], &x[i], &y[i]);
    for (int i = n; i < N; i++)
        w[i] = 0.0, x[i] = y[i] = 0.0;
}
/* Is (x, y) (radius units) inside the open region? Returns its transmission. */
double lf_aperture_transmission(const lf_aperture *a, double x, double y);
double lf_aperture_area(const lf_aperture *a);
/* "circular", "polygon", "star" or "image" (for --explain and metadata). */
const char *lf_aperture_name(const lf_aperture *a);
void lf_aperture_free(lf_aperture *a);

#endif
