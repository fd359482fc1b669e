/* The microlens-array light-field camera "plenoptic" (Ng et al. 2005,
 * "Light Field Photography with a Hand-held Plenoptic Camera"; plenoptic
 * 2.0 with "sensoroffset", Lumsdaine & Georgiev 2009).  docs/lightfield.md is
 * the user's page; docs/lightfield-format.md fixes the EXR attributes.
 *
 * Geometry (camera space, metres; pbrt's: +z into the scene):
 *   - a thin main lens at the origin, focal length f, aperture radius
 *     R = f / 2N;
 *   - the microlens array (MLA) at z = -z_i, z_i the image distance of the
 *     focus plane (1/f = 1/z_i + 1/z_o; z_i = f focused at infinity);
 *   - the sensor at z = -(z_i + d), d = f_mla + sensoroffset behind the MLA.
 * Lateral geometry is done in "upright" sensor coordinates (x right, y up
 * as the image is viewed), which are camera space point-reflected through
 * the axis (the lens images the scene upside down and reversed, so reading
 * the sensor through the point reflection gives pbrt's orientation, as the
 * thinlens camera does).  Every map below is linear through the axis, so it
 * commutes with that reflection.
 *
 * Microlens images: the chief ray through a microlens centre c comes from
 * the main-lens centre, so microlens (i, j)'s image on the sensor is centred
 * on G = c (z_i + d)/z_i: the images are spaced P = p (z_i + d)/z_i, a little
 * more than the physical pitch p.  The layout attributes (pitch, offset)
 * describe these image centres, which is what a decoder needs; the physical
 * pitch is written too.  Matched f-numbers (the default microlens focal
 * length f_mla = p N_image, N_image = z_i / D the main lens's image-side
 * f-number, D = 2R): light through one microlens reaches the sensor (d =
 * f_mla) within the main aperture's image, D f_mla / z_i across, widened by
 * the microlens's own width p f_mla / z_i; along the grid axes that is
 * (D + p) f_mla / z_i = p (z_i + f_mla) / z_i = P, the spacing: images touch
 * and do not overlap (square grid: gaps at the corners only, hex: at the
 * three-lens junctions).  "overlap_ratio" is that width over the spacing.
 *
 * A camera ray for sensor point p_s:
 *   1. candidates: the microlenses through which some ray from p_s can pass
 *      the main aperture.  A ray from p_s through the point m of microlens
 *      c meets the main-lens plane at
 *        h(m) = m a + c z_i/f_mla - p_s z_i/d,   a = 1 + z_i/d - z_i/f_mla,
 *      the cell scaled by a about (G - p_s) z_i/d; so c is a candidate when
 *      |G - p_s| < (R + |a| r_cell) d / z_i (r_cell: the cell's circumradius).
 *      One candidate is chosen uniformly with lens_u (pdf 1/K).  Sampling a
 *      neighbourhood rather than only the nearest microlens is what lets
 *      crosstalk (overlapping images with a fast main lens) and the partial
 *      shadowing at image borders come out of the geometry; with matched
 *      f-numbers almost every pixel has one candidate, so it costs nothing.
 *   2. m uniform over the chosen microlens's cell (square, or hexagon as
 *      three rhombi), the microlenses fill their cells (100 % fill factor);
 *   3. ideal thin microlens: slopes (lateral per unit distance towards the
 *      scene) s_in = (m - p_s)/d, s_out = s_in - (m - c)/f_mla;
 *   4. h = m + s_out z_i on the main lens; |h| > R: vignetted, weight 0;
 *   5. thin main lens: s = s_out - h/f; the ray leaves h along (s, 1).
 * Radiometry (docs/physics.md "Exposure and radiometry"): the irradiance at p_s
 * is E = (1/d^2) \int_{microlenses} L cos^4(theta) dA over the MLA plane,
 * theta the angle of m - p_s to the axis (ideal thin lenses conserve
 * radiance), so the weight is K A_cell cos^4(theta) / d^2.  Like thinlens,
 * pixel values are exposure: with matched f-numbers the flux through one
 * microlens, spread over its image, equals what a thin lens of the same
 * f-number puts on the microlens's cell (tests/test_camera_lightfield.c).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_keys.h"
#include "camera_internal.h"
#include "lens.h"


/* Rays from one sensor point can reach the main aperture through at most
 * this many microlenses (plenoptic 2.0 designs see each point several
 * times; beyond this the design is rejected at create). */
enum { MAX_CANDIDATES = 256 };
/* 1 nm: below it the microlens's power (1/f) overflows the lattice's
 * arithmetic (1e-308 mm made NaN pixel indices); real microlenses are
 * tens of micrometres and more. */
#define MIN_FOCAL_MM 1e-6

typedef struct plenoptic {
    /* main lens (a compound lens: its equivalent thin lens, see below) */
    double focal_length, fstop, aperture_radius; /* f, N, R = f/2N (metres) */
    double focus_distance;                        /* z_o; INFINITY allowed */
    double mla_distance;                          /* z_i */
    /* where the lattice geometry sees the aperture: the main lens itself
     * (thin), or the exit pupil (compound); pupil_radius is the paraxial
     * radius, search_radius bounds every ray that gets through */
    double pupil_distance, pupil_radius, search_radius;
    /* compound main lens ("lensfile") */
    int compound;
    lf_lens lens;
    lf_lens_paraxial px;
    double working_fnumber;
    double principal_to_mla_mm;  /* front principal point H (camera origin) to the MLA */
    double focus_from_mla_m;     /* "focusdistance" as given: MLA to the plane in focus */
    /* sensor */
    int width, height;
    double sensor_w, sensor_h, pixel;            /* metres; pixel pitch */
    double nominal_w_mm, nominal_h_mm;
    char sensor_name[32];
    /* microlens array */
    int hex;
    double rotation_rad, cos_r, sin_r;
    double pitch;                 /* physical pitch p (metres) */
    double mla_focal;             /* f_mla */
    double sensor_offset;         /* d - f_mla */
    double mla_sensor;            /* d */
    double image_pitch_px;        /* P: spacing of microlens image centres, pixels */
    double row_px;                /* P, or P sqrt(3)/2 for hex */
    double origin_px[2];          /* image centre of microlens (0, 0), pixels */
    int nx, ny;                   /* microlenses per row, rows (partial ones included) */
    double phys_per_px;           /* metres on the MLA per pixel of the image lattice: pixel z_i/(z_i+d) */
    double cell_area;             /* physical cell area */
    double cell_radius;           /* physical circumradius */
    double search_px;             /* candidate radius around p_s, pixels */
    double weight_scale;          /* A_cell / d^2 */
    double overlap_ratio;         /* main aperture image diameter / image spacing (1 = matched) */
} plenoptic;

static void warn(const lf_camera_create_args *a, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void warn(const lf_camera_create_args *a, const char *fmt, ...)
{
    if (!a->warning || !a->warning_size)
        return;
    size_t n = strlen(a->warning);
    if (n + 2 >= a->warning_size)
        return;
    if (n)
        a->warning[n++] = '\n', a->warning[n] = '\0';
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(a->warning + n, a->warning_size - n, fmt, ap);
    va_end(ap);
}

/* Image centre of microlens (i, j), in pixels (docs/lightfield-format.md). */
static void lens_centre_px(const plenoptic *c, int i, int j, double *x, double *y)
{
    double a = i * c->image_pitch_px + (c->hex && (j & 1) ? 0.5 * c->image_pitch_px : 0.0);
    double b = j * c->row_px;
    *x = c->origin_px[0] + c->cos_r * a - c->sin_r * b;
    *y = c->origin_px[1] + c->sin_r * a + c->cos_r * b;
}

/* Pixel coordinates -> lattice frame (unrotated, relative to lens (0, 0)). */
static void to_lattice(const plenoptic *c, double x, double y, double *a, double *b)
{
    double dx = x - c->origin_px[0], dy = y - c->origin_px[1];
    *a = c->cos_r * dx + c->sin_r * dy;
    *b = -c->sin_r * dx + c->cos_r * dy;
}

/* Places the lattice: centred on the sensor, then the index range of every
 * microlens whose cell reaches the sensor, re-based so it starts at (0, 0)
 * with an even first row (the hex row shift keeps its parity). */
static void place_lattice(plenoptic *c)
{
    double P = c->image_pitch_px, Pr = c->row_px;
    int nx0 = (int)ceil(c->width / P - 1e-9), ny0 = (int)ceil(c->height / Pr - 1e-9);
    double la = 0.5 * (nx0 - 1) * P, lb = 0.5 * (ny0 - 1) * Pr;
    c->origin_px[0] = 0.5 * c->width - (c->cos_r * la - c->sin_r * lb);
    c->origin_px[1] = 0.5 * c->height - (c->sin_r * la + c->cos_r * lb);
    double amin = INFINITY, amax = -INFINITY, bmin = INFINITY, bmax = -INFINITY;
    for (int k = 0; k < 4; k++) {
        double a, b;
        to_lattice(c, k & 1 ? c->width : 0, k & 2 ? c->height : 0, &a, &b);
        amin = fmin(amin, a), amax = fmax(amax, a), bmin = fmin(bmin, b), bmax = fmax(bmax, b);
    }
    double ha = 0.5 * P, hb = c->hex ? P / sqrt(3.0) : 0.5 * P, shift = c->hex ? 0.5 * P : 0.0;
    double eps = 1e-7;
    int imin = (int)floor((amin - ha - shift) / P + eps) + 1, imax = (int)ceil((amax + ha) / P - eps) - 1;
    int jmin = (int)floor((bmin - hb) / Pr + eps) + 1, jmax = (int)ceil((bmax + hb) / Pr - eps) - 1;
    if (c->hex && (jmin & 1))
        jmin--;
    double ox, oy;
    lens_centre_px(c, imin, jmin, &ox, &oy);
    c->origin_px[0] = ox, c->origin_px[1] = oy;
    c->nx = imax - imin + 1;
    c->ny = jmax - jmin + 1;
}

/* A compound main lens (docs/lightfield.md, "Compound main lens"):
 * "lensfile" with "aperturediameter" as the realistic camera reads them;
 * "focusdistance" (metres, 0 = infinity) is measured from the MLA, the
 * lens's film plane, as realistic and pbrt-v4 measure it, and the MLA sits
 * where lf_lens_focus_thick puts the film.  Camera space has its origin at
 * the lens's front principal point H, so that with z from H and z_i from H'
 * the thin-lens relations the light-field library uses (1/z + 1/z_i = 1/f,
 * docs/physics.md) hold for the paraxial lens.  The lattice geometry sees the
 * aperture as the paraxial exit pupil; candidates are searched within a
 * radius there that bounds every ray that gets through (traced at create). */
static int main_lens_compound(const lf_camera_create_args *a, plenoptic *c, const char *lensfile, double zo,
                              lf_error *err)
{
    const lf_camera_params *p = a->params;
    double aperture_mm = p->get_float(p->ctx, "aperturediameter", 1.0); /* pbrt-v4's default, as realistic */
    if (!lensfile[0])
        return lf_error_set(err, LF_ERR_PARAM, "\"lensfile\" is empty (give a .dat prescription; see scenes/lenses/)");
    if (!(aperture_mm > 0.0) || !isfinite(aperture_mm))
        return lf_error_set(err, LF_ERR_PARAM, "\"aperturediameter\" must be > 0 mm, got %g", aperture_mm);
    if (!(zo >= 0.0))
        return lf_error_set(err, LF_ERR_PARAM, "\"focusdistance\" must be > 0 m (0 = infinity), got %g", zo);
    char path[4096];
    if (lensfile[0] == '/' || !a->scene_dir || !a->scene_dir[0])
        snprintf(path, sizeof path, "%s", lensfile);
    else
        snprintf(path, sizeof path, "%s/%s", a->scene_dir, lensfile);
    int rc = lf_lens_load(path, &c->lens, err);
    if (rc)
        return rc;
    lf_lens *L = &c->lens;
    if (L->stop < 0) {
        warn(a, "%s has no aperture stop (radius 0 row): \"aperturediameter\" is ignored", path);
    } else {
        lf_warnings lw = {0};
        char msg[1536];
        lf_lens_set_stop_diameter(L, aperture_mm, &lw);
        for (const char *t = lf_warnings_text(&lw); lf_cam_next_warning(&t, msg, sizeof msg);)
            warn(a, "%s", msg);
        lf_warnings_free(&lw);
    }
    if (lf_lens_paraxial_analyse(L, &c->px) || !(c->px.efl_mm > 0.0))
        return lf_error_set(err, LF_ERR_PARAM, "%s: the lens forms no real image (afocal or negative focal length)",
                            path);
    double focus_mm = zo == 0.0 || isinf(zo) ? INFINITY : zo * 1e3;
    rc = lf_lens_focus_thick(L, focus_mm, &L->film_distance_mm, err);
    if (rc)
        return rc;
    c->compound = 1;
    c->focus_from_mla_m = isinf(focus_mm) ? INFINITY : zo;
    c->working_fnumber = lf_lens_working_fnumber(L, &c->px, focus_mm, L->film_distance_mm);
    double f = c->px.efl_mm, zi = L->film_distance_mm - c->px.rear_principal_mm; /* H' -> MLA */
    c->principal_to_mla_mm = L->film_distance_mm + c->px.total_length_mm - c->px.front_principal_mm;
    if (!(zi > 0.0) || !isfinite(c->working_fnumber) || !(c->working_fnumber > 0.0))
        return lf_error_set(err, LF_ERR_PARAM, "%s: no usable image at %g mm behind the rear vertex", path,
                            L->film_distance_mm);
    /* the equivalent thin lens at H': same f, same z_i, same image-side cone */
    c->focal_length = f * 1e-3;
    c->mla_distance = zi * 1e-3;
    c->focus_distance = zi > f * (1.0 + 1e-12) ? f * zi / (zi - f) * 1e-3 : INFINITY;
    c->aperture_radius = 0.5 * c->mla_distance / c->working_fnumber;
    c->fstop = c->focal_length / (2.0 * c->aperture_radius);
    /* paraxial exit pupil, seen from the MLA */
    c->pupil_distance = (L->film_distance_mm - c->px.exit_pupil_mm) * 1e-3;
    c->pupil_radius = 0.5 * c->px.exit_pupil_diameter_mm * 1e-3;
    if (!(c->pupil_distance > 0.0) || !(c->pupil_radius > 0.0))
        return lf_error_set(err, LF_ERR_PARAM, "%s: the exit pupil (%g mm from the MLA) is not in front of the MLA",
                            path, c->pupil_distance * 1e3);
    /* search radius on the exit-pupil plane: every ray from an MLA point
     * within the sensor's half diagonal that gets through crosses the
     * rear-vertex plane inside lf_lens_rear_disk_radius; trace a grid of
     * them and keep the largest crossing of the pupil plane, plus the grid
     * step (scaled to that plane) as margin */
    double w_mm = c->nominal_w_mm, h_mm = w_mm * a->image_height / a->image_width;
    double r_max = 0.5 * hypot(w_mm, h_mm), Zr = L->film_distance_mm, Zp = c->pupil_distance * 1e3;
    double R_rear = lf_lens_rear_disk_radius(L, r_max), hmax = 0.0;
    enum { NR = 17, NG = 48 };
    double step = 2.0 * R_rear / NG;
    for (int k = 0; k < NR; k++) {
        double r = r_max * k / (NR - 1);
        for (int j = 0; j <= NG; j++)
            for (int i = 0; i <= NG; i++) {
                double x = -R_rear + i * step, y = -R_rear + j * step;
                if (x * x + y * y > R_rear * R_rear)
                    continue;
                lf_lens_ray in = {{r, 0, 0}, {x - r, y, -Zr}};
                if (lf_lens_trace_from_film(L, &in, NULL, NULL) != LF_LENS_PASSED)
                    continue;
                double hx = r + (x - r) * Zp / Zr, hy = y * Zp / Zr;
                hmax = fmax(hmax, hypot(hx, hy));
            }
    }
    if (!(hmax > 0.0))
        return lf_error_set(err, LF_ERR_PARAM, "%s admits no light at stop diameter %g mm", path, aperture_mm);
    c->search_radius = (hmax + 1.5 * step * Zp / Zr) * 1e-3;
    return 0;
}

/* A thin main lens ("focallength", "fstop"): the MLA sits where the lens
 * images the plane in focus (0 or inf: infinity, the focal plane). */
static int main_lens_thin(const lf_camera_params *p, plenoptic *c, double zo, lf_error *err)
{
    double f_mm = p->get_float(p->ctx, "focallength", 50.0);
    c->fstop = p->get_float(p->ctx, "fstop", 2.8);
    if (!(f_mm > 0.0) || !isfinite(f_mm))
        return lf_error_set(err, LF_ERR_PARAM, "\"focallength\" must be > 0 mm, got %g", f_mm);
    if (!(c->fstop > 0.0) || !isfinite(c->fstop))
        return lf_error_set(err, LF_ERR_PARAM, "\"fstop\" must be > 0, got %g", c->fstop);
    c->focal_length = f_mm * 1e-3;
    c->aperture_radius = c->focal_length / (2.0 * c->fstop);
    if (zo == 0.0 || zo == INFINITY) {
        c->focus_distance = INFINITY;
        c->mla_distance = c->focal_length;
    } else if (!(zo > c->focal_length) || !isfinite(zo)) {
        return lf_error_set(err, LF_ERR_PARAM,
                            "\"focusdistance\" %g m must exceed the focal length (%g mm) for a real image (or be 0 "
                            "for infinity)",
                            zo, f_mm);
    } else {
        c->focus_distance = zo;
        c->mla_distance = c->focal_length / (1.0 - c->focal_length / zo);
    }
    c->pupil_distance = c->mla_distance;
    c->pupil_radius = c->search_radius = c->aperture_radius;
    return LF_OK;
}

/* "grid" and "rotation" of the lattice. */
static int lattice_shape(plenoptic *c, const char *grid, double rot_deg, lf_error *err)
{
    if (!strcmp(grid, "square"))
        c->hex = 0;
    else if (!strcmp(grid, "hex"))
        c->hex = 1;
    else
        return lf_error_set(err, LF_ERR_PARAM, "unknown \"grid\" \"%s\" (square or hex)", grid);
    if (!isfinite(rot_deg))
        return lf_error_set(err, LF_ERR_PARAM, "\"rotation\" must be finite, got %g", rot_deg);
    /* reduced to one turn first: 1e308 degrees times pi overflows to inf */
    c->rotation_rad = fmod(rot_deg, 360.0) * M_PI / 180.0;
    c->cos_r = cos(c->rotation_rad);
    c->sin_r = sin(c->rotation_rad);
    return LF_OK;
}

/* The sensor: "float sensorsize" [w h] mm wins over "string sensor" (as
 * thinlens); its width maps to the image width, pixels are square. */
static int sensor(const lf_camera_create_args *a, plenoptic *c, lf_error *err)
{
    int rc = lf_cam_read_sensor(a->params, &c->nominal_w_mm, &c->nominal_h_mm, c->sensor_name,
                                sizeof c->sensor_name, err);
    if (rc)
        return rc;
    c->sensor_w = c->nominal_w_mm * 1e-3;
    c->sensor_h = c->sensor_w * c->height / c->width; /* square pixels */
    c->pixel = c->sensor_w / c->width;
    if (fabs(c->sensor_h * 1e3 - c->nominal_h_mm) > 0.01 * c->nominal_h_mm)
        warn(a,
             "the image is %dx%d, so the %s sensor (%g x %g mm) is used as %g x %.4g mm (its width maps to "
             "the image width, pixels are square)",
             c->width, c->height, c->sensor_name, c->nominal_w_mm, c->nominal_h_mm, c->nominal_w_mm, c->sensor_h * 1e3);
    return LF_OK;
}

/* The microlens array as asked for: "pitch" (um) or "microlenses" (count
 * across the width), "microlensfocallength", "sensoroffset". */
typedef struct mla_params {
    double pitch_um, fmla_mm, offset_mm;
    int count;
} mla_params;

/* Microlens pitch and focal length (matched to the main lens unless given),
 * the lattice in pixels and the candidate search (Ng 2005's geometry). */
static int microlens_array(plenoptic *c, mla_params m, lf_error *err)
{
    if (m.pitch_um != 0.0 && m.count != 0)
        return lf_error_set(err, LF_ERR_PARAM,
                            "give either \"pitch\" (um) or \"microlenses\" (count across the width), not both");
    if (m.pitch_um == 0.0 && m.count == 0)
        m.count = (int)lround(c->width / 14.0) > 0 ? (int)lround(c->width / 14.0) : 1; /* ~Ng 2005: 14 px per lens */
    if (m.count < 0 || m.count > c->width * 4)
        return lf_error_set(err, LF_ERR_PARAM, "\"microlenses\" must be in 1..%d (4 per pixel), got %d", c->width * 4,
                            m.count);
    if (m.pitch_um < 0.0 || !isfinite(m.pitch_um))
        return lf_error_set(err, LF_ERR_PARAM, "\"pitch\" must be > 0 um, got %g", m.pitch_um);
    if (!(m.fmla_mm >= 0.0) || !isfinite(m.fmla_mm))
        return lf_error_set(err, LF_ERR_PARAM, "\"microlensfocallength\" must be > 0 mm, got %g", m.fmla_mm);
    if (m.fmla_mm > 0.0 && m.fmla_mm < MIN_FOCAL_MM)
        return lf_error_set(err, LF_ERR_PARAM, "\"microlensfocallength\" %g mm is too small (at least %g mm)",
                            m.fmla_mm, MIN_FOCAL_MM);
    if (!isfinite(m.offset_mm))
        return lf_error_set(err, LF_ERR_PARAM, "\"sensoroffset\" must be finite, got %g", m.offset_mm);
    /* the lattice sees the aperture at the (exit) pupil: Z and D below are z_i and f/N for a thin lens */
    double zi = c->pupil_distance, D = 2.0 * c->pupil_radius, off = m.offset_mm * 1e-3;
    c->sensor_offset = off;
    if (m.count > 0) {
        /* the images tile the width: spacing P = W / count pixels = p (z_i + d) / z_i */
        double P = c->sensor_w / m.count; /* metres on the sensor */
        if (m.fmla_mm > 0.0) {
            c->mla_focal = m.fmla_mm * 1e-3;
            c->pitch = P * zi / (zi + c->mla_focal + off);
        } else {
            /* matched: f_mla = p z_i / D, so P = p (1 + off/z_i) + p^2 / D */
            double b = 1.0 + off / zi;
            c->pitch = 0.5 * D * (sqrt(b * b + 4.0 * P / D) - b);
            c->mla_focal = c->pitch * zi / D;
        }
    } else {
        c->pitch = m.pitch_um * 1e-6;
        c->mla_focal = m.fmla_mm > 0.0 ? m.fmla_mm * 1e-3 : c->pitch * zi / D;
    }
    c->mla_sensor = c->mla_focal + off;
    if (!(c->mla_sensor > 0.0))
        return lf_error_set(err, LF_ERR_PARAM,
                            "\"sensoroffset\" %g mm puts the sensor in front of the microlenses (f_mla = %g mm)",
                            m.offset_mm, c->mla_focal * 1e3);
    double d = c->mla_sensor, Zs = zi + d;
    c->phys_per_px = c->pixel * zi / Zs;
    c->image_pitch_px = c->pitch / c->phys_per_px;
    c->row_px = c->hex ? c->image_pitch_px * sqrt(3.0) / 2.0 : c->image_pitch_px;
    if (!(c->image_pitch_px >= 0.25) || !isfinite(c->image_pitch_px))
        return lf_error_set(err, LF_ERR_PARAM, "the microlens pitch is %g pixels: at least 0.25 pixel is needed",
                            c->image_pitch_px);
    if (c->image_pitch_px > 2.0 * c->width) /* one lens across the sensor (the most "microlenses" asks for) is ~1x */
        return lf_error_set(err, LF_ERR_PARAM,
                            "the microlens pitch is %g pixels, over twice the %d-pixel image width: not one microlens "
                            "image fits on the sensor, so there is no light field",
                            c->image_pitch_px, c->width);
    c->cell_area = c->hex ? sqrt(3.0) / 2.0 * c->pitch * c->pitch : c->pitch * c->pitch;
    c->cell_radius = c->hex ? c->pitch / sqrt(3.0) : c->pitch / sqrt(2.0);
    double alpha = 1.0 + zi / d - zi / c->mla_focal;
    c->search_px = (c->search_radius + fabs(alpha) * c->cell_radius) * d / zi / c->pixel;
    double cell_px = c->hex ? sqrt(3.0) / 2.0 * c->image_pitch_px * c->image_pitch_px
                            : c->image_pitch_px * c->image_pitch_px;
    double max_cand = M_PI * pow(c->search_px + c->image_pitch_px, 2.0) / cell_px;
    if (!(max_cand <= MAX_CANDIDATES)) /* also NaN */
        return lf_error_set(err, LF_ERR_PARAM,
                            "each sensor point would see the main lens through up to %.0f microlenses (limit %d): the "
                            "microlens focal length or sensor offset is too far from the matched design",
                            max_cand, MAX_CANDIDATES);
    c->weight_scale = c->cell_area / (d * d);
    place_lattice(c);
    return LF_OK;
}

/* f-number matching (plenoptic 1.0 geometry, d = f_mla): a main lens
 * faster or slower than the microlenses is allowed, with a warning. */
static void fnumber_warnings(const lf_camera_create_args *a, plenoptic *c)
{
    double zi = c->pupil_distance, D = 2.0 * c->pupil_radius;
    double Nimg = zi / D, Nmla = c->mla_focal / c->pitch;
    c->overlap_ratio = (D + c->pitch) * c->mla_focal / (c->pitch * (zi + c->mla_focal));
    if (c->overlap_ratio > 1.01)
        warn(a,
             "f-number mismatch: the main lens (image side f/%.3g) is faster than the microlenses (f/%.3g): "
             "microlens images overlap (each is %.1f%% of their spacing; neighbours cross-talk)",
             Nimg, Nmla, 100.0 * c->overlap_ratio);
    else if (c->overlap_ratio < 0.99)
        warn(a,
             "f-number mismatch: the main lens (image side f/%.3g) is slower than the microlenses (f/%.3g): "
             "microlens images leave gaps (each is %.1f%% of their spacing; pixels between them stay dark)",
             Nimg, Nmla, 100.0 * c->overlap_ratio);
}

static int plenoptic_create(const lf_camera_create_args *a, void **state)
{
    const lf_camera_params *p = a->params;
    plenoptic *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    c->width = a->image_width;
    c->height = a->image_height;
    const char *lensfile = p->get_string(p->ctx, "lensfile", NULL);
    double zo = p->get_float(p->ctx, "focusdistance", 1.0);
    const char *grid = p->get_string(p->ctx, "grid", "square");
    mla_params m;
    m.pitch_um = p->get_float(p->ctx, "pitch", 0.0);
    m.count = p->get_int(p->ctx, "microlenses", 0);
    m.fmla_mm = p->get_float(p->ctx, "microlensfocallength", 0.0);
    double rot_deg = p->get_float(p->ctx, "rotation", 0.0);
    m.offset_mm = p->get_float(p->ctx, "sensoroffset", 0.0);

    lf_error err = {0};
    int rc = lensfile ? LF_OK : main_lens_thin(p, c, zo, &err);
    if (!rc)
        rc = lattice_shape(c, grid, rot_deg, &err);
    if (!rc)
        rc = sensor(a, c, &err);
    /* a compound main lens needs the sensor size for its pupil search */
    if (!rc && lensfile)
        rc = main_lens_compound(a, c, lensfile, zo, &err);
    if (!rc)
        rc = microlens_array(c, m, &err);
    if (lf_cam_error(rc, &err, a->error, a->error_size)) {
        lf_lens_free(&c->lens);
        free(c);
        return -1;
    }
    fnumber_warnings(a, c);
    *state = c;
    return 0;
}

static uint32_t plenoptic_needs(const void *state)
{
    (void)state;
    return LF_CAMERA_NEEDS_LENS;
}

/* Counts (pick < 0) or finds the pick-th candidate microlens for a sensor
 * point given in pixels; see the header comment, step 1. */
static int candidates(const plenoptic *c, double x, double y, int pick, int *ci, int *cj)
{
    double a, b;
    to_lattice(c, x, y, &a, &b);
    double r = c->search_px, r2 = r * r, P = c->image_pitch_px, Pr = c->row_px;
    int j0 = (int)ceil((b - r) / Pr), j1 = (int)floor((b + r) / Pr);
    if (j0 < 0)
        j0 = 0;
    if (j1 > c->ny - 1)
        j1 = c->ny - 1;
    int k = 0;
    for (int j = j0; j <= j1; j++) {
        double sh = c->hex && (j & 1) ? 0.5 * P : 0.0, db = b - j * Pr;
        int i0 = (int)ceil((a - sh - r) / P), i1 = (int)floor((a - sh + r) / P);
        if (i0 < 0)
            i0 = 0;
        if (i1 > c->nx - 1)
            i1 = c->nx - 1;
        for (int i = i0; i <= i1; i++) {
            double da = a - (i * P + sh);
            if (da * da + db * db >= r2)
                continue;
            if (k == pick) {
                *ci = i, *cj = j;
                return k + 1;
            }
            k++;
        }
    }
    return k;
}

/* A camera ray up to the main lens: its weight (0: no ray) and, with a
 * compound main lens, the ray to trace through it (lens space) in *in;
 * with the thin main lens, the finished ray in *r. */
static double plenoptic_front(const plenoptic *c, const lf_camera_sample *s, lf_camera_ray *r, lf_lens_ray *in)
{
    int K = candidates(c, s->film_x, s->film_y, -1, NULL, NULL);
    if (K <= 0)
        return 0.0;
    double uk = s->lens_u * K;
    int k = (int)uk;
    if (k > K - 1)
        k = K - 1;
    double u = uk - k, v = s->lens_v;
    int i = 0, j = 0;
    candidates(c, s->film_x, s->film_y, k, &i, &j);

    /* a point of the cell, lattice frame, in image-lattice pixels */
    double la, lb;
    double P = c->image_pitch_px;
    if (!c->hex) {
        la = (u - 0.5) * P, lb = (v - 0.5) * P;
    } else {
        /* hexagon (flat sides left and right) = three rhombi on vertices 30 + 60 m degrees */
        double u3 = u * 3.0;
        int q = (int)u3;
        if (q > 2)
            q = 2;
        double t = u3 - q, rad = P / sqrt(3.0);
        double a0 = (30.0 + 120.0 * q) * M_PI / 180.0, a1 = a0 + 120.0 * M_PI / 180.0;
        la = rad * (t * cos(a0) + v * cos(a1));
        lb = rad * (t * sin(a0) + v * sin(a1));
    }
    double gx, gy;
    lens_centre_px(c, i, j, &gx, &gy);
    double mx_px = gx + c->cos_r * la - c->sin_r * lb, my_px = gy + c->sin_r * la + c->cos_r * lb;
    /* to upright metres: image-lattice pixels -> the MLA scales by z_i/(z_i+d) */
    double cx = (gx - 0.5 * c->width) * c->phys_per_px, cy = (0.5 * c->height - gy) * c->phys_per_px;
    double mx = (mx_px - 0.5 * c->width) * c->phys_per_px, my = (0.5 * c->height - my_px) * c->phys_per_px;
    double psx = (s->film_x - 0.5 * c->width) * c->pixel, psy = (0.5 * c->height - s->film_y) * c->pixel;

    double d = c->mla_sensor, zi = c->pupil_distance;
    double dx = mx - psx, dy = my - psy;
    double cos2 = d * d / (d * d + dx * dx + dy * dy);
    /* ideal thin microlens, then on to the main lens (thin) or its exit pupil (compound) */
    double sx = dx / d - (mx - cx) / c->mla_focal, sy = dy / d - (my - cy) / c->mla_focal;
    double hx = mx + sx * zi, hy = my + sy * zi;
    if (hx * hx + hy * hy > c->search_radius * c->search_radius)
        return 0.0; /* vignetted by the main aperture (thin), or surely by the lens (compound) */
    double w = K * c->weight_scale * cos2 * cos2;
    if (c->compound) {
        /* lens space (mm; film = MLA at z = 0, light towards +z) is camera
         * space mirrored in z, laterally the camera's: upright -> negate */
        *in = (lf_lens_ray){{-mx * 1e3, -my * 1e3, 0.0}, {-sx, -sy, -1.0}};
        return isfinite(w) ? w : 0.0;
    }
    sx -= hx / c->focal_length, sy -= hy / c->focal_length;
    /* upright -> camera space: point reflection of the lateral coordinates */
    double dir[3] = {-sx, -sy, 1.0};
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + 1.0);
    if (!isfinite(len) || !isfinite(w))
        return 0.0;
    r->origin[0] = -hx, r->origin[1] = -hy, r->origin[2] = 0.0;
    r->dir[0] = dir[0] / len, r->dir[1] = dir[1] / len, r->dir[2] = dir[2] / len;
    return w;
}

/* The ray out of the compound main lens -> the camera ray; w or 0. */
static double plenoptic_back(const plenoptic *c, const lf_lens_ray *out, double w, lf_camera_ray *r)
{
    double len = sqrt(out->d[0] * out->d[0] + out->d[1] * out->d[1] + out->d[2] * out->d[2]);
    if (!(len > 0.0) || !isfinite(len))
        return 0.0;
    r->origin[0] = out->o[0] * 1e-3, r->origin[1] = out->o[1] * 1e-3;
    r->origin[2] = -(out->o[2] + c->principal_to_mla_mm) * 1e-3; /* camera origin at H */
    r->dir[0] = out->d[0] / len, r->dir[1] = out->d[1] / len, r->dir[2] = -out->d[2] / len;
    return w;
}

static double plenoptic_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const plenoptic *c = state;
    lf_lens_ray in, out;
    double w = plenoptic_front(c, s, r, &in);
    if (!(w > 0.0) || !c->compound)
        return w;
    if (lf_lens_trace_from_film(&c->lens, &in, &out, NULL) != LF_LENS_PASSED)
        return 0.0;
    return plenoptic_back(c, &out, w, r);
}

/* generate_rays: with a compound main lens, the rays that reach it are
 * traced side by side (lf_lens_trace_rays_from_film); the thin main lens
 * one ray at a time. */
static void plenoptic_generate_rays(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r,
                                    double *weights)
{
    const plenoptic *c = state;
    if (!c->compound) {
        for (int i = 0; i < n; i++)
            weights[i] = plenoptic_generate_ray(state, &s[i], &r[i]);
        return;
    }
    enum { CHUNK = 64 };
    lf_lens_ray in[CHUNK], out[CHUNK];
    unsigned char passed[CHUNK];
    int idx[CHUNK];
    for (int i0 = 0; i0 < n; i0 += CHUNK) {
        int m = n - i0 < CHUNK ? n - i0 : CHUNK, k = 0;
        for (int i = i0; i < i0 + m; i++) {
            weights[i] = plenoptic_front(c, &s[i], &r[i], &in[k]);
            if (weights[i] > 0.0)
                idx[k++] = i;
        }
        lf_lens_trace_rays_from_film(&c->lens, k, in, out, passed);
        for (int q = 0; q < k; q++) {
            int i = idx[q];
            weights[i] = passed[q] ? plenoptic_back(c, &out[q], weights[i], &r[i]) : 0.0;
        }
    }
}

static void plenoptic_destroy(void *state)
{
    plenoptic *c = state;
    if (c)
        lf_lens_free(&c->lens);
    free(c);
}

static int plenoptic_describe(const void *state, char *buf, size_t size)
{
    const plenoptic *c = state;
    int n = 0;
    char scratch[1];
    if (size == 0)
        buf = scratch, size = 1;
    double D = 2.0 * c->aperture_radius, zi = c->mla_distance;
    if (c->compound) {
        const lf_lens *L = &c->lens;
        LF_CAM_APPEND("model: plenoptic camera (Ng 2005): compound main lens %s (%d surfaces, traced exactly), microlens "
               "array at its image plane, sensor behind\n",
               L->path, L->n);
        LF_CAM_APPEND("main lens: EFL %.6g mm (paraxial), stop %.4g mm, working f/%.4g; focused at %.6g m from the microlens "
               "array (%.6g m from the front principal point, the camera origin)\n",
               c->px.efl_mm, L->stop >= 0 ? 2.0 * L->s[L->stop].aperture_radius_mm : 0.0, c->working_fnumber,
               c->focus_from_mla_m, c->focus_distance);
        LF_CAM_APPEND("rear vertex to microlens array: %.6g mm; exit pupil %.6g mm wide, %.6g mm in front of the array "
               "(candidate search radius there %.6g mm)\n",
               L->film_distance_mm, 2e3 * c->pupil_radius, c->pupil_distance * 1e3, c->search_radius * 1e3);
        LF_CAM_APPEND("equivalent thin lens (metadata): f %.6g mm, f/%.6g, H' to microlens array z_i %.6g mm\n",
               c->focal_length * 1e3, c->fstop, zi * 1e3);
    } else {
        LF_CAM_APPEND("model: plenoptic camera (Ng 2005): thin main lens, microlens array at its image plane, sensor behind\n");
        LF_CAM_APPEND("main lens: f %g mm, f/%g (aperture %.6g mm), focused at %.6g m\n", c->focal_length * 1e3, c->fstop,
               D * 1e3, c->focus_distance);
        LF_CAM_APPEND("main lens to microlens array z_i: %.6g mm (image-side f-number z_i/D = %.4g)\n", zi * 1e3, zi / D);
    }
    LF_CAM_APPEND("microlenses: %s grid, pitch %.6g um, focal length %.6g mm (f/%.4g), rotation %g deg\n",
           c->hex ? "hex" : "square", c->pitch * 1e6, c->mla_focal * 1e3, c->mla_focal / c->pitch,
           c->rotation_rad * 180.0 / M_PI);
    LF_CAM_APPEND("microlens images: %.6g px apart, %d x %d lenses (partial border lenses included), lens (0,0) at (%.6g, "
           "%.6g) px\n",
           c->image_pitch_px, c->nx, c->ny, c->origin_px[0], c->origin_px[1]);
    LF_CAM_APPEND("aperture image / image spacing: %.4g (%s)\n", c->overlap_ratio,
           c->overlap_ratio > 1.01   ? "overlap: crosstalk"
           : c->overlap_ratio < 0.99 ? "gaps between images"
                                     : "matched");
    LF_CAM_APPEND("sensor: %s %g x %g mm as %g x %.6g mm, %.6g um pixels, %.6g mm behind the microlenses (offset %g mm%s)\n",
           c->sensor_name, c->nominal_w_mm, c->nominal_h_mm, c->sensor_w * 1e3, c->sensor_h * 1e3, c->pixel * 1e6,
           c->mla_sensor * 1e3, c->sensor_offset * 1e3, c->sensor_offset == 0.0 ? ": plenoptic 1.0" : ": focused plenoptic 2.0");
    LF_CAM_APPEND("sub-aperture views: %d x %d pixels, %.4g x %.4g views\n", c->nx, c->ny, c->image_pitch_px,
           c->image_pitch_px);
    {
        /* Ng 2005's range of exact refocusing (docs/lightfield.md, "Refocusable
         * range"): a sub-aperture view sees the aperture through a slice
         * (D + p)/P wide (the P pixels under a microlens span its image of the
         * aperture, p (z_i + d_s)/z_i on the sensor), so a point imaged at
         * alpha z_i blurs on the MLA by |1 - 1/alpha| (D + p)/P; it stays
         * within one microlens (one view pixel) while
         * |1 - 1/alpha| <= P p / (D + p) (Ng's P p / D for p << D).  In
         * disparity: |d| <= 1 px/view. */
        double b = c->image_pitch_px * c->pitch / (D + c->pitch), zo = c->focus_distance;
        double inv_near = (isinf(zo) ? 0.0 : 1.0 / zo) + b / zi, inv_far = (isinf(zo) ? 0.0 : 1.0 / zo) - b / zi;
        char far[64];
        if (inv_far > 0.0)
            snprintf(far, sizeof far, "%.4g m", 1.0 / inv_far);
        else
            snprintf(far, sizeof far, "infinity");
        char amax[64];
        if (b < 1.0)
            snprintf(amax, sizeof amax, "%.6g", 1.0 / (1.0 - b));
        else
            snprintf(amax, sizeof amax, "infinity");
        LF_CAM_APPEND("refocusable range (Ng 2005, |1 - 1/alpha| <= P p / (D + p) = %.4g; disparity within +-1 px/view): "
               "alpha %.6g .. %s, depths %.4g m .. %s; each sub-aperture view has the depth of field of f/%.3g "
               "(f/N x %.4g views)%s\n",
               b, 1.0 / (1.0 + b), amax, 1.0 / inv_near, far, c->fstop * c->image_pitch_px, c->image_pitch_px,
               c->sensor_offset != 0.0 ? " [plenoptic 1.0 formula; this is a focused 2.0 design]" : "");
    }
    LF_CAM_APPEND("pixel values are exposure: (1/d^2) int L cos^4 dA over the microlenses x shutter x ISO/100\n");
    return n;
}

/* docs/lightfield-format.md, "plenoptic" */
static void plenoptic_metadata(const void *state, const lf_camera_attr_sink *sink)
{
    const plenoptic *c = state;
    sink->set_string(sink->ctx, LF_KEY_KIND, "plenoptic");
    sink->set_string(sink->ctx, LF_KEY_GRID, c->hex ? "hex" : "square");
    sink->set_double(sink->ctx, LF_KEY_MICROLENS_PITCH_PX, c->image_pitch_px);
    sink->set_double(sink->ctx, LF_KEY_MICROLENS_ROTATION_RAD, c->rotation_rad);
    sink->set_doubles(sink->ctx, LF_KEY_MICROLENS_OFFSET_PX, c->origin_px, 2);
    double count[2] = {c->nx, c->ny};
    sink->set_doubles(sink->ctx, LF_KEY_MICROLENS_COUNT, count, 2);
    sink->set_double(sink->ctx, LF_KEY_MICROLENS_PITCH_UM, c->pitch * 1e6);
    sink->set_double(sink->ctx, LF_KEY_MICROLENS_FOCAL_MM, c->mla_focal * 1e3);
    sink->set_double(sink->ctx, LF_KEY_MAIN_FOCAL_MM, c->focal_length * 1e3);
    sink->set_double(sink->ctx, LF_KEY_MAIN_FSTOP, c->fstop);
    sink->set_double(sink->ctx, LF_KEY_FOCUS_DISTANCE_M, c->focus_distance);
    sink->set_double(sink->ctx, LF_KEY_MLA_DISTANCE_MM, c->mla_distance * 1e3);
    double wh[2] = {c->sensor_w * 1e3, c->sensor_h * 1e3};
    sink->set_doubles(sink->ctx, LF_KEY_SENSOR_SIZE_MM, wh, 2);
    sink->set_double(sink->ctx, LF_KEY_SENSOR_OFFSET_MM, c->sensor_offset * 1e3);
    if (c->compound) {
        sink->set_string(sink->ctx, LF_KEY_LENS_FILE, c->lens.path);
        sink->set_double(sink->ctx, LF_KEY_LENS_EFL_MM, c->px.efl_mm);
        sink->set_double(sink->ctx, LF_KEY_LENS_WORKING_FNUMBER, c->working_fnumber);
        sink->set_double(sink->ctx, LF_KEY_LENS_FILM_DISTANCE_MM, c->lens.film_distance_mm);
    }
}

const lf_camera_type lf_camera_plenoptic = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "plenoptic",
    .create = plenoptic_create,
    .needs = plenoptic_needs,
    .generate_ray = plenoptic_generate_ray,
    .generate_rays = plenoptic_generate_rays,
    .destroy = plenoptic_destroy,
    .describe = plenoptic_describe,
    .metadata = plenoptic_metadata,
};
