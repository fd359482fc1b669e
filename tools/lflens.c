/* lflens - analyse and draw real lens prescriptions (pbrt .dat files).
 * A thin CLI over camera/lens_analysis.h; `lflens --help` and
 * `lflens COMMAND --help` list the flags (the tables below), docs/realistic.md
 * explains the numbers.  Exit codes: 0 success; 1 bad lens file or an
 * impossible request (the message names file:line); 2 bad command line.
 * Outputs are written atomically. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_file_write.h"
#include "camera/lens_analysis.h"
#include "cli.h"
#include "image/lf_image.h"

typedef struct flags {
    double aperture_mm, focus_m, diagonal_mm;
    const char *sensor, *out;
    int json;
} flags;

#define LENS_FLAGS                                                                                                 \
    {"--aperture", NULL, LF_ARG_DOUBLE, &f.aperture_mm, "MM", "stop diameter (default: the file's full stop)",     \
     .min = 0, .flags = LF_ARG_MIN_OPEN},                                                                          \
        {"--focus", NULL, LF_ARG_DOUBLE, &f.focus_m, "M", "focus distance from the film in metres (default inf)",  \
         .min = 0, .flags = LF_ARG_MIN_OPEN | LF_ARG_INF_OK},                                                      \
        {"--sensor", NULL, LF_ARG_STRING, &f.sensor, "NAME",                                                       \
         "fullframe, apsc, apsh, mediumformat, fourthirds, 1inch, 1/1.63in, 1/2.3in, 1/3.2in (default fullframe)"}, \
        {"--diagonal", NULL, LF_ARG_DOUBLE, &f.diagonal_mm, "MM", "a film of this diagonal with a 3:2 aspect",     \
         .min = 0, .flags = LF_ARG_MIN_OPEN }

/* Loads the lens and analyses it for the flags' sensor and focus. */
static int analyse(const flags *f, const char *path, lf_lens *L, lf_lens_report *r)
{
    lf_error err = {0};
    double w, h;
    if (f->sensor && f->diagonal_mm > 0)
        return lf_cli_usage_error("lflens", NULL, "give --sensor or --diagonal, not both");
    if (f->sensor && lf_lens_sensor_size(f->sensor, &w, &h))
        return lf_cli_usage_error("lflens", NULL, "unknown sensor \"%s\" (known: %s)", f->sensor,
                                  lf_lens_sensor_names());
    if (!f->sensor && f->diagonal_mm > 0)
        w = f->diagonal_mm * 3.0 / sqrt(13.0), h = f->diagonal_mm * 2.0 / sqrt(13.0);
    else if (!f->sensor)
        lf_lens_sensor_size("fullframe", &w, &h);
    if (lf_lens_load(path, L, &err)) {
        fprintf(stderr, "lflens: %s\n", err.msg);
        return LF_EXIT_FAIL;
    }
    if (f->aperture_mm > 0) {
        lf_warnings warn = {0};
        if (lf_lens_set_stop_diameter(L, f->aperture_mm, &warn)) /* "warning: ...\n" */
            fprintf(stderr, "lflens: %s", lf_warnings_text(&warn)), lf_warnings_free(&warn);
        if (L->stop < 0)
            fprintf(stderr, "lflens: warning: %s has no aperture stop row; --aperture ignored\n", path);
    }
    if (lf_lens_report_compute(L, w, h, f->focus_m, r, &err)) {
        fprintf(stderr, "lflens: %s\n", err.msg);
        lf_lens_free(L);
        return LF_EXIT_FAIL;
    }
    return LF_EXIT_OK;
}

static void print_json(const lf_lens *L, const lf_lens_report *r)
{
    const lf_lens_paraxial *p = &r->px;
    char focus[64];
    snprintf(focus, sizeof focus, isinf(r->focus_m) ? "\"inf\"" : "%.6g", r->focus_m);
    printf("{\"lens\": \"%s\", \"surfaces\": %d, \"efl_mm\": %.6g, \"bfl_mm\": %.6g, \"ffl_mm\": %.6g, "
           "\"front_principal_mm\": %.6g, \"rear_principal_mm\": %.6g, \"total_length_mm\": %.6g, "
           "\"stop_diameter_mm\": %.6g, \"fnumber\": %.6g, \"working_fnumber\": %.6g, "
           "\"entrance_pupil_mm\": %.6g, \"entrance_pupil_z_mm\": %.6g, \"exit_pupil_mm\": %.6g, "
           "\"exit_pupil_z_mm\": %.6g, \"sensor_mm\": [%.6g, %.6g], \"fov_deg\": %.6g, "
           "\"fov_traced_deg\": [%.6g, %.6g, %.6g], \"fov_paraxial_deg\": [%.6g, %.6g, %.6g], "
           "\"image_circle_mm\": %.6g, \"focus_m\": %s, \"film_distance_thick_mm\": %.6g, "
           "\"film_distance_search_mm\": %.6g, \"closest_focus_m\": %.6g, \"abbe\": %s}\n",
           L->path, L->n, p->efl_mm, p->bfl_mm, p->ffl_mm, p->front_principal_mm, p->rear_principal_mm,
           p->total_length_mm, 2.0 * L->s[p->stop].aperture_radius_mm, p->fnumber, r->working_fnumber,
           p->entrance_pupil_diameter_mm, p->entrance_pupil_mm, p->exit_pupil_diameter_mm, p->exit_pupil_mm,
           r->sensor_w_mm, r->sensor_h_mm, r->fov_traced_deg[2], r->fov_traced_deg[0], r->fov_traced_deg[1],
           r->fov_traced_deg[2], r->fov_paraxial_deg[0], r->fov_paraxial_deg[1], r->fov_paraxial_deg[2],
           2.0 * r->image_circle_radius_mm, focus, r->film_thick_mm,
           isfinite(r->film_search_mm) ? r->film_search_mm : -1.0, r->closest_focus_m, L->has_abbe ? "true" : "false");
}

static void print_text(const flags *f, const lf_lens *L, const lf_lens_report *r)
{
    const lf_lens_paraxial *p = &r->px;
    printf("lens:                  %s (%d surfaces, stop on line %d)%s\n", L->path, L->n, L->s[p->stop].line,
           L->has_abbe ? ", Abbe numbers present" : "");
    printf("effective focal length %.4f mm\n", p->efl_mm);
    printf("back focal distance    %.4f mm (rear vertex to F')\n", p->bfl_mm);
    printf("front focal distance   %.4f mm (F to front vertex; > 0: F in front of the lens)\n", p->ffl_mm);
    printf("principal planes       H %.4f mm from the front vertex, H' %.4f mm from the rear vertex\n",
           p->front_principal_mm, p->rear_principal_mm);
    printf("total length           %.4f mm (front vertex to rear vertex)\n", p->total_length_mm);
    printf("aperture stop          %.4g mm diameter (file: %.4g mm)\n", 2.0 * L->s[p->stop].aperture_radius_mm,
           2.0 * (L->stop >= 0 ? L->stop_max_radius_mm : L->s[p->stop].aperture_radius_mm));
    printf("entrance pupil         %.4f mm diameter, %.4f mm from the front vertex\n", p->entrance_pupil_diameter_mm,
           p->entrance_pupil_mm);
    printf("exit pupil             %.4f mm diameter, %.4f mm from the rear vertex\n", p->exit_pupil_diameter_mm,
           p->exit_pupil_mm);
    printf("f-number               f/%.3f at infinity; working f/%.3f at the focus distance\n", p->fnumber,
           r->working_fnumber);
    printf("sensor                 %.4g x %.4g mm (diagonal %.4g mm)%s%s\n", r->sensor_w_mm, r->sensor_h_mm,
           r->diagonal_mm, f->sensor ? ", " : "", f->sensor ? f->sensor : "");
    printf("field of view          paraxial %.2f x %.2f deg (diagonal %.2f); traced %.2f x %.2f deg (diagonal %.2f)\n",
           r->fov_paraxial_deg[0], r->fov_paraxial_deg[1], r->fov_paraxial_deg[2], r->fov_traced_deg[0],
           r->fov_traced_deg[1], r->fov_traced_deg[2]);
    if (r->image_circle_radius_mm < 0.5 * r->diagonal_mm)
        printf("image circle           %.3f mm diameter: smaller than the sensor diagonal\n",
               2.0 * r->image_circle_radius_mm);
    char label[64] = "focus at infinity";
    if (!isinf(r->focus_m))
        snprintf(label, sizeof label, "focus at %.4g m", r->focus_m);
    printf("%-23sfilm %.4f mm behind the rear vertex (%s); exact best-focus search %.4f mm\n", label, r->film_thick_mm,
           isinf(r->focus_m) ? "thick lens = BFL" : "thick-lens estimate", r->film_search_mm);
    printf("closest focus          %.4f m from the film (unit magnification, thick-lens model)\n", r->closest_focus_m);
}

static int run_info(void *ctx, int n, char **pos)
{
    (void)n;
    const flags *f = ctx;
    lf_lens L;
    lf_lens_report r;
    int rc = analyse(f, pos[0], &L, &r);
    if (rc)
        return rc;
    if (f->json)
        print_json(&L, &r);
    else
        print_text(f, &L, &r);
    lf_lens_free(&L);
    return LF_EXIT_OK;
}

static int write_plot(const lf_plot *plot, const char *path, lf_error *err)
{
    const char *dot = strrchr(path, '.');
    if (dot && !strcmp(dot, ".svg")) {
        char *svg = lf_plot_svg(plot);
        if (!svg)
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory writing %s", path);
        int rc = lf_file_write_atomic(path, svg, strlen(svg), err);
        free(svg);
        return rc;
    }
    lf_image img;
    if (lf_image_from_plot(plot, &img, err))
        return err->code;
    int rc = lf_image_write(path, &img, NULL, NULL, err);
    lf_image_free(&img);
    return rc;
}

static int run_plot(void *ctx, int n, char **pos)
{
    (void)n;
    const flags *f = ctx;
    const char *dot = strrchr(f->out, '.');
    if (!dot || (strcmp(dot, ".svg") && strcmp(dot, ".png")))
        return lf_cli_usage_error("lflens", "plot", "-o wants OUT.svg or OUT.png, got \"%s\"", f->out);
    lf_error err = {0};
    if (lf_output_is_input(f->out, (const char *const *)pos, 1, &err))
        return fprintf(stderr, "lflens: %s\n", err.msg), LF_EXIT_FAIL;
    lf_lens L;
    lf_lens_report r;
    int rc = analyse(f, pos[0], &L, &r);
    if (rc)
        return rc;
    lf_plot plot;
    rc = lf_lens_plot_build(&L, &r, &plot, &err) || write_plot(&plot, f->out, &err);
    if (rc)
        fprintf(stderr, "lflens: %s\n", err.msg);
    lf_plot_free(&plot);
    lf_lens_free(&L);
    return rc ? LF_EXIT_FAIL : LF_EXIT_OK;
}

/* The flag tables (and LENS_FLAGS) point into f, the options the command gets. */
int main(int argc, char **argv)
{
    flags f = {.focus_m = INFINITY};
    const lf_arg info_args[] = {
        LENS_FLAGS,
        {"--json", NULL, LF_ARG_FLAG, &f.json, NULL, "one JSON object (efl_mm, bfl_mm, fnumber, pupils, fov_deg, ...)"},
    };
    const lf_arg plot_args[] = {
        LENS_FLAGS,
        {"--output", "-o", LF_ARG_STRING, &f.out, "OUT.svg|OUT.png", "the drawing (SVG, or PNG with the same labels)",
         .flags = LF_ARG_REQUIRED},
    };
    const lf_command commands[] = {
        {"info", "LENS.dat [--aperture MM] [--focus M] [--sensor NAME|--diagonal MM] [--json]",
         "paraxial analysis: focal lengths, principal planes, pupils, f-numbers, field of view, focus", info_args,
         LF_ARRAY_LEN(info_args), 1, 1, run_info,
         "Focal lengths and principal planes from a paraxial y-nu trace; the film position that focuses at --focus "
         "(thick-lens estimate and exact best-focus search); the field of view of the sensor, paraxial and traced."},
        {"plot", "LENS.dat -o OUT.svg|OUT.png [--aperture MM] [--focus M] [--sensor NAME|--diagonal MM]",
         "cross-section with traced ray fans, spot diagrams and the distortion curve", plot_args,
         LF_ARRAY_LEN(plot_args), 1, 1, run_plot, NULL},
    };
    const lf_tool tool = {"lflens", "analyse and draw real lens prescriptions (pbrt .dat files)", LF_VERSION,
                          commands, LF_ARRAY_LEN(commands),
                          "Exit status: 0 success; 1 bad lens file or impossible request; 2 bad command line."};
    return lf_cli_main(&tool, &f, argc, argv);
}
