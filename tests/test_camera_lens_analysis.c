/* test_camera_lens_analysis.c - lflens's numbers (camera/lens_analysis.h)
 * against an independent computation: a singlet with its stop in front,
 * whose focal lengths follow from the thick-lens formula and whose spots
 * and distortion come from this file's own exact tracer (vector Snell's law
 * at spheres, written here, sharing no code with camera/lens.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lens_analysis.h"
#include "lf_test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The lens: stop (radius 10 mm), then a biconvex BK7-like singlet whose
 * elements are wide enough that the stop alone limits every beam. */
static const double R1 = 50.0, R2 = -50.0, T_GLASS = 6.0, N_GLASS = 1.5168, STOP_GAP = 5.0, STOP_R = 10.0;
static const char *prescription = "# stop, then a biconvex singlet\n"
                                  "0     5     1       20\n"
                                  "50    6     1.5168  60\n"
                                  "-50   45    1       60\n";

/* Refracts d at a surface with unit normal nrm (any orientation) from index
 * n1 into n2.  0, or -1 on total internal reflection. */
static int refract(double d[3], const double nrm[3], double n1, double n2)
{
    double N[3] = {nrm[0], nrm[1], nrm[2]};
    double c = -(d[0] * N[0] + d[1] * N[1] + d[2] * N[2]);
    if (c < 0) {
        for (int k = 0; k < 3; k++)
            N[k] = -N[k];
        c = -c;
    }
    double eta = n1 / n2, k2 = 1 - eta * eta * (1 - c * c);
    if (k2 < 0)
        return -1;
    for (int k = 0; k < 3; k++)
        d[k] = eta * d[k] + (eta * c - sqrt(k2)) * N[k];
    return 0;
}

/* Moves o along d to the sphere of radius R whose vertex is at z = zv (the
 * intersection on the vertex's side), refracting n1 -> n2.  0 or -1. */
static int through_sphere(double o[3], double d[3], double zv, double R, double n1, double n2)
{
    double c[3] = {0, 0, zv + R}, oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
    double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    double cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - R * R, disc = b * b - cc;
    if (disc < 0)
        return -1;
    double t = R > 0 ? -b - sqrt(disc) : -b + sqrt(disc);
    for (int k = 0; k < 3; k++)
        o[k] += t * d[k];
    double nrm[3] = {(o[0] - c[0]) / R, (o[1] - c[1]) / R, (o[2] - c[2]) / R};
    return refract(d, nrm, n1, n2);
}

/* A ray entering the stop plane at (x, y) with direction angle theta in the
 * y-z plane, traced to the film plane z = 0 with the rear vertex at
 * -film_mm.  Returns 0 and the film point, or -1. */
static int trace_to_film(double film_mm, double x, double y, double theta, double *fx, double *fy)
{
    double z2 = -film_mm, z1 = z2 - T_GLASS, zs = z1 - STOP_GAP;
    double o[3] = {x, y, zs}, d[3] = {0, sin(theta), cos(theta)};
    if (hypot(x, y) > STOP_R)
        return -1;
    if (through_sphere(o, d, z1, R1, 1.0, N_GLASS) || through_sphere(o, d, z2, R2, N_GLASS, 1.0))
        return -1;
    double t = -o[2] / d[2];
    *fx = o[0] + t * d[0];
    *fy = o[1] + t * d[1];
    return 0;
}

/* RMS spot radius about the centroid for a collimated beam at theta filling
 * the stop, by a fine polar quadrature over the stop disk (uniform in area:
 * the same measure as a uniform grid across the beam). */
static double reference_rms(double film_mm, double theta)
{
    enum { NR = 600, NA = 720 };
    double sw = 0, sx = 0, sy = 0, sxx = 0;
    for (int i = 0; i < NR; i++)
        for (int j = 0; j < NA; j++) {
            double r = STOP_R * (i + 0.5) / NR, a = 2 * M_PI * (j + 0.5) / NA, fx, fy;
            if (trace_to_film(film_mm, r * cos(a), r * sin(a), theta, &fx, &fy))
                continue;
            sw += r, sx += r * fx, sy += r * fy, sxx += r * (fx * fx + fy * fy);
        }
    double cx = sx / sw, cy = sy / sw;
    return sqrt(sxx / sw - cx * cx - cy * cy);
}

int main(void)
{
    lf_lens L;
    lf_error err = {0};
    CHECK(lf_lens_parse(prescription, "singlet.dat", &L, &err) == 0);
    lf_lens_report r;
    CHECK(lf_lens_report_compute(&L, 36, 24, INFINITY, &r, &err) == 0);

    /* First order from the thick-lens formulas. */
    double n = N_GLASS;
    double phi = (n - 1) * (1 / R1 - 1 / R2 + (n - 1) * T_GLASS / (n * R1 * R2));
    double efl = 1 / phi, bfl = efl * (1 - (n - 1) * T_GLASS / (n * R1));
    CHECK_NEAR(r.px.efl_mm, efl, 1e-9 * efl);
    CHECK_NEAR(r.px.bfl_mm, bfl, 1e-9 * efl);
    CHECK_NEAR(r.film_thick_mm, bfl, 1e-6); /* focused at infinity: the film at F' */
    CHECK_NEAR(r.fov_paraxial_deg[0], 2 * atan(18 / efl) * 180 / M_PI, 1e-9);
    CHECK_NEAR(r.fov_paraxial_deg[2], 2 * atan(hypot(18, 12) / efl) * 180 / M_PI, 1e-9);
    /* The stop is the first surface: the entrance pupil is the stop itself. */
    CHECK_NEAR(r.px.entrance_pupil_diameter_mm, 2 * STOP_R, 1e-9);
    CHECK_NEAR(r.px.fnumber, efl / (2 * STOP_R), 1e-9);

    /* Spot RMS on axis and at 8 degrees on the film at the paraxial focus:
     * a 61 x 61 grid against a fine quadrature (grid error ~ 1 %). */
    const double fields[2] = {0.0, 8.0 * M_PI / 180};
    for (int f = 0; f < 2; f++) {
        lf_lens_spot s;
        CHECK(lf_lens_spot_diagram(&L, fields[f], 61, &s, &err) == 0);
        double ref = reference_rms(r.film_thick_mm, fields[f]);
        CHECK_MSG(ref > 0.01, "the singlet's spherical aberration gives a visible spot (%g mm)", ref);
        CHECK_MSG(fabs(s.rms_mm - ref) <= 0.02 * ref, "field %d: rms %.6f mm, reference %.6f mm", f, s.rms_mm, ref);
        CHECK(s.n > 2000); /* ~ pi/4 of the 3721 grid points fill the round beam */
        double fx0, fy0;
        /* the centroid of the off-axis spot sits near the chief ray's film point */
        CHECK(trace_to_film(r.film_thick_mm, 0, 0, fields[f], &fx0, &fy0) == 0);
        CHECK_NEAR(s.cy, fy0, 0.5 * ref + 1e-9);
        lf_lens_spot_free(&s);
    }

    /* Distortion of the image of infinity: the chief ray (through the stop
     * centre) traced here from the field angle the library reports must
     * land at the film radius it reports (only round-off apart). */
    enum { ND = 12 };
    double th[ND], pct[ND];
    int nd = lf_lens_distortion_curve(&L, &r.px, r.image_circle_radius_mm, ND, th, pct);
    CHECK(nd >= ND - 1);
    for (int k = 0; k < nd; k++) {
        double fx, fy;
        CHECK(trace_to_film(bfl, 0, 0, th[k] * M_PI / 180, &fx, &fy) == 0);
        double expect = 100.0 * (fy / (efl * tan(th[k] * M_PI / 180)) - 1.0);
        CHECK_MSG(fabs(pct[k] - expect) < 1e-4, "theta %.3f deg: %.5f %% vs chief ray %.5f %%", th[k], pct[k], expect);
    }
    /* a stop in front of a positive lens gives barrel distortion (negative) */
    CHECK(nd > 0 && pct[nd - 1] < 0);

    /* The drawing holds the three panels and serialises. */
    lf_plot plot;
    CHECK(lf_lens_plot_build(&L, &r, &plot, &err) == 0);
    char *svg = lf_plot_svg(&plot);
    CHECK(svg && !strncmp(svg, "<svg", 4) && strstr(svg, "spot diagrams") && strstr(svg, "distortion"));
    /* its pixels, labels included, are image/'s (tests/test_image_plot.c) */
    free(svg);
    lf_plot_free(&plot);

    lf_lens_free(&L);
    return lf_test_end();
}
