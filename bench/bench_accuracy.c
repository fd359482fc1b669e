/* bench_accuracy - the helper of bench/accuracy.sh: renders with CPU timing,
 * compares images, and turns the CSV into the plot and the tables of
 * docs/accuracy.md.
 *
 *   bench_accuracy render SCENE.pbrt [--as PATH] --spp N --seed S [--threads T] -o OUT.exr
 *       prints "setup_cpu_s render_cpu_s render_wall_s" (process CPU time:
 *       every render thread counts; --as: parse SCENE as if it were PATH, so
 *       relative lens files and Includes resolve from there)
 *   bench_accuracy compare A.exr REF.exr [--normalise]
 *       prints the relative RMS error sqrt(mean (a - b)^2) / mean(b) over all
 *       pixels and channels; --normalise first scales A to REF's mean
 *       (exposure normalisation)
 *   bench_accuracy attr FILE.exr NAME       prints a header attribute
 *   bench_accuracy report CSV OUT.svg       writes the log-log plot (one panel
 *       per group, one curve per model) and prints the markdown tables
 *
 * CSV columns: group,curve,setting,spp,setup_cpu_s,render_cpu_s,rel_rmse.
 * Exit codes: 0 ok, 1 failure, 2 bad command line.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "image/lf_image.h"
#include "render/lf_render.h"
#include "scenefile/lf_scene_desc.h"

static double clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = 0;
    fclose(f);
    return s;
}

static int cmd_render(int argc, char **argv)
{
    const char *scene = NULL, *as = NULL, *out = NULL;
    int spp = 0, threads = 0;
    long seed = 0;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--as") && i + 1 < argc)
            as = argv[++i];
        else if (!strcmp(argv[i], "--spp") && i + 1 < argc)
            spp = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seed") && i + 1 < argc)
            seed = atol(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "-o") && i + 1 < argc)
            out = argv[++i];
        else if (!scene)
            scene = argv[i];
        else
            return 2;
    }
    if (!scene || !out || spp <= 0)
        return 2;
    char *text = read_text(scene);
    if (!text) {
        fprintf(stderr, "bench_accuracy: cannot read %s\n", scene);
        return 1;
    }
    lf_error err = {0};
    lf_scene_desc desc;
    double c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    int rc = lf_scene_parse_string(text, as ? as : scene, &desc, &err);
    free(text);
    if (rc) {
        fprintf(stderr, "bench_accuracy: %s\n", err.msg);
        return 1;
    }
    lf_render_opts o = lf_render_opts_default();
    o.spp = spp;
    o.threads = threads;
    o.seed = (uint32_t)seed;
    o.has_seed = 1;
    o.scene_path = as ? as : scene;
    lf_renderer *r;
    if (lf_renderer_create(&desc, &o, &r, &err)) {
        fprintf(stderr, "bench_accuracy: %s\n", err.msg);
        lf_scene_desc_free(&desc);
        return 1;
    }
    double c1 = clock_s(CLOCK_PROCESS_CPUTIME_ID), w1 = clock_s(CLOCK_MONOTONIC);
    lf_image img = {0};
    lf_attrs meta = {0};
    rc = lf_renderer_render(r, &img, &meta, &err);
    double c2 = clock_s(CLOCK_PROCESS_CPUTIME_ID), w2 = clock_s(CLOCK_MONOTONIC);
    lf_write_opts wo = {0}; /* full float: references must not be quantised */
    if (!rc)
        rc = lf_image_write(out, &img, &meta, &wo, &err);
    if (rc)
        fprintf(stderr, "bench_accuracy: %s\n", err.msg);
    else
        printf("%.4f %.4f %.4f\n", c1 - c0, c2 - c1, w2 - w1);
    lf_image_free(&img);
    lf_attrs_free(&meta);
    lf_renderer_free(r);
    lf_scene_desc_free(&desc);
    return rc ? 1 : 0;
}

static int cmd_compare(int argc, char **argv)
{
    if (argc < 2)
        return 2;
    int normalise = argc > 2 && !strcmp(argv[2], "--normalise");
    lf_image a = {0}, b = {0};
    lf_error err = {0};
    if (lf_image_read(argv[0], &a, NULL, &err) || lf_image_read(argv[1], &b, NULL, &err)) {
        fprintf(stderr, "bench_accuracy: %s\n", err.msg);
        return 1;
    }
    if (a.width != b.width || a.height != b.height) {
        fprintf(stderr, "bench_accuracy: %s and %s differ in size\n", argv[0], argv[1]);
        return 1;
    }
    int ch = a.channels < b.channels ? a.channels : b.channels;
    if (ch > 3)
        ch = 3; /* colour only */
    size_t np = (size_t)a.width * a.height;
    double sa = 0, sb = 0;
    for (size_t p = 0; p < np; p++)
        for (int c = 0; c < ch; c++)
            sa += a.data[p * a.channels + c], sb += b.data[p * b.channels + c];
    double scale = normalise && sa > 0 ? sb / sa : 1.0, se = 0;
    for (size_t p = 0; p < np; p++)
        for (int c = 0; c < ch; c++) {
            double d = scale * a.data[p * a.channels + c] - b.data[p * b.channels + c];
            se += d * d;
        }
    double n = (double)np * ch;
    printf("%.6g\n", sb > 0 ? sqrt(se / n) / (sb / n) : INFINITY);
    lf_image_free(&a);
    lf_image_free(&b);
    return 0;
}

static int cmd_attr(int argc, char **argv)
{
    if (argc < 2)
        return 2;
    lf_image img = {0};
    lf_attrs at = {0};
    lf_error err = {0};
    if (lf_image_read(argv[0], &img, &at, &err)) {
        fprintf(stderr, "bench_accuracy: %s\n", err.msg);
        return 1;
    }
    int found = 0;
    for (size_t i = 0; i < at.count && !found; i++)
        if (!strcmp(at.items[i].name, argv[1])) {
            const lf_attr *x = &at.items[i];
            found = 1;
            if (x->type == LF_ATTR_STRING)
                printf("%s\n", x->s);
            else if (x->type == LF_ATTR_INT)
                printf("%d\n", x->i);
            else
                printf("%.10g\n", x->d);
        }
    lf_image_free(&img);
    lf_attrs_free(&at);
    if (!found)
        fprintf(stderr, "bench_accuracy: %s has no attribute %s\n", argv[0], argv[1]);
    return found ? 0 : 1;
}

/* ------------------------------------------------------------ report */

typedef struct row {
    char group[64], curve[64], setting[64];
    int spp;
    double setup, time, err;
} row;

typedef struct curve {
    char group[64], name[64];
    int n;
    double t[64], e[64];
} curve;

/* log-log interpolation of y(x) along a curve sorted by x; NAN outside */
static double interp(const double *x, const double *y, int n, double at)
{
    for (int i = 0; i + 1 < n; i++) {
        double x0 = x[i], x1 = x[i + 1];
        if ((at >= x0 && at <= x1) || (at <= x0 && at >= x1)) {
            if (x0 == x1)
                return y[i];
            double f = (log(at) - log(x0)) / (log(x1) - log(x0));
            return exp(log(y[i]) + f * (log(y[i + 1]) - log(y[i])));
        }
    }
    return NAN;
}

static const char *const colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2",
                                      "#17becf"};

static int cmd_report(int argc, char **argv)
{
    if (argc < 2)
        return 2;
    FILE *f = fopen(argv[0], "r");
    if (!f) {
        fprintf(stderr, "bench_accuracy: cannot read %s\n", argv[0]);
        return 1;
    }
    static curve cv[128];
    int nc = 0;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        row r;
        if (sscanf(line, "%63[^,],%63[^,],%63[^,],%d,%lf,%lf,%lf", r.group, r.curve, r.setting, &r.spp, &r.setup,
                   &r.time, &r.err) != 7)
            continue; /* header */
        int c = 0;
        while (c < nc && (strcmp(cv[c].group, r.group) || strcmp(cv[c].name, r.curve)))
            c++;
        if (c == nc) {
            if (nc == 128)
                continue;
            snprintf(cv[c].group, sizeof cv[c].group, "%s", r.group);
            snprintf(cv[c].name, sizeof cv[c].name, "%s", r.curve);
            cv[c].n = 0;
            nc++;
        }
        if (cv[c].n < 64 && r.time > 0 && r.err > 0) {
            cv[c].t[cv[c].n] = r.time;
            cv[c].e[cv[c].n] = r.err;
            cv[c].n++;
        }
    }
    fclose(f);
    /* groups in order of appearance */
    char groups[32][64];
    int ng = 0;
    for (int c = 0; c < nc; c++) {
        int g = 0;
        while (g < ng && strcmp(groups[g], cv[c].group))
            g++;
        if (g == ng && ng < 32) {
            memcpy(groups[ng], cv[c].group, sizeof groups[ng]);
            groups[ng][sizeof groups[ng] - 1] = 0;
            ng++;
        }
    }
    /* ---- SVG: panels in two columns ---- */
    FILE *s = fopen(argv[1], "w");
    if (!s) {
        fprintf(stderr, "bench_accuracy: cannot write %s\n", argv[1]);
        return 1;
    }
    const int pw = 420, ph = 300, ml = 60, mr = 10, mt = 30, mb = 45, cols = 2;
    int rows = (ng + cols - 1) / cols;
    fprintf(s, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" font-family=\"sans-serif\" "
               "font-size=\"11\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            cols * pw, rows * ph);
    for (int g = 0; g < ng; g++) {
        int ox = (g % cols) * pw, oy = (g / cols) * ph;
        double tmin = INFINITY, tmax = 0, emin = INFINITY, emax = 0;
        for (int c = 0; c < nc; c++)
            if (!strcmp(cv[c].group, groups[g]))
                for (int i = 0; i < cv[c].n; i++) {
                    tmin = fmin(tmin, cv[c].t[i]), tmax = fmax(tmax, cv[c].t[i]);
                    emin = fmin(emin, cv[c].e[i]), emax = fmax(emax, cv[c].e[i]);
                }
        if (!(tmax > 0))
            continue;
        double lt0 = floor(log10(tmin)), lt1 = ceil(log10(tmax)), le0 = floor(log10(emin)), le1 = ceil(log10(emax));
        if (lt1 == lt0)
            lt1 += 1;
        if (le1 == le0)
            le1 += 1;
        int x0 = ox + ml, x1 = ox + pw - mr, y0 = oy + mt, y1 = oy + ph - mb;
#define PX(t) (x0 + (log10(t) - lt0) / (lt1 - lt0) * (x1 - x0))
#define PY(e) (y1 - (log10(e) - le0) / (le1 - le0) * (y1 - y0))
        fprintf(s, "<text x=\"%d\" y=\"%d\" font-size=\"13\" font-weight=\"bold\">%s</text>\n", ox + ml, oy + 18,
                groups[g]);
        fprintf(s, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"#444\"/>\n", x0, y0,
                x1 - x0, y1 - y0);
        for (double k = lt0; k <= lt1 + 1e-9; k += 1) {
            double x = x0 + (k - lt0) / (lt1 - lt0) * (x1 - x0);
            fprintf(s, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#ddd\"/>", x, y0, x, y1);
            fprintf(s, "<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%g</text>\n", x, y1 + 14, pow(10, k));
        }
        for (double k = le0; k <= le1 + 1e-9; k += 1) {
            double y = y1 - (k - le0) / (le1 - le0) * (y1 - y0);
            fprintf(s, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/>", x0, y, x1, y);
            fprintf(s, "<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">%g</text>\n", x0 - 4, y + 4, pow(10, k));
        }
        fprintf(s, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">render CPU time (s)</text>\n", (x0 + x1) / 2,
                y1 + 32);
        fprintf(s,
                "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\" transform=\"rotate(-90 %d %d)\">relative RMS "
                "error</text>\n",
                ox + 14, (y0 + y1) / 2, ox + 14, (y0 + y1) / 2);
        int k = 0;
        for (int c = 0; c < nc; c++) {
            if (strcmp(cv[c].group, groups[g]))
                continue;
            const char *col = colours[k % 8];
            fprintf(s, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.8\" points=\"", col);
            for (int i = 0; i < cv[c].n; i++)
                fprintf(s, "%.1f,%.1f ", PX(cv[c].t[i]), PY(cv[c].e[i]));
            fprintf(s, "\"/>\n");
            for (int i = 0; i < cv[c].n; i++)
                fprintf(s, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.5\" fill=\"%s\"/>", PX(cv[c].t[i]),
                        PY(cv[c].e[i]), col);
            fprintf(s, "\n<text x=\"%d\" y=\"%d\" fill=\"%s\">%s</text>\n", x1 - 150, y0 + 14 + 13 * k, col,
                    cv[c].name);
            k++;
        }
#undef PX
#undef PY
    }
    fprintf(s, "</svg>\n");
    fclose(s);
    /* ---- tables: each curve against the group's first ---- */
    printf("| group | curve | points | lowest error | CPU s at that error: curve / %s | time ratio (equal error) | "
           "error at equal time: curve / first | error ratio (equal time) |\n",
           "first");
    printf("|---|---|---|---|---|---|---|---|\n");
    for (int g = 0; g < ng; g++) {
        const curve *base = NULL;
        for (int c = 0; c < nc; c++) {
            if (strcmp(cv[c].group, groups[g]))
                continue;
            const curve *C = &cv[c];
            double lowest = INFINITY;
            for (int i = 0; i < C->n; i++)
                lowest = fmin(lowest, C->e[i]);
            if (!base) {
                base = C;
                printf("| %s | %s (baseline) | %d | %.3g | | | | |\n", groups[g], C->name, C->n, lowest);
                continue;
            }
            /* equal error: the lowest error both curves reach */
            double bl = INFINITY;
            for (int i = 0; i < base->n; i++)
                bl = fmin(bl, base->e[i]);
            double e_star = fmax(lowest, bl);
            double tc = interp(C->e, C->t, C->n, e_star), tb = interp(base->e, base->t, base->n, e_star);
            /* equal time: the longest time both reach */
            double tmax_c = 0, tmax_b = 0;
            for (int i = 0; i < C->n; i++)
                tmax_c = fmax(tmax_c, C->t[i]);
            for (int i = 0; i < base->n; i++)
                tmax_b = fmax(tmax_b, base->t[i]);
            double t_star = fmin(tmax_c, tmax_b);
            double ec = interp(C->t, C->e, C->n, t_star), eb = interp(base->t, base->e, base->n, t_star);
            char a[64] = "n/a", b[64] = "n/a", d[64] = "n/a", e[64] = "n/a";
            if (isfinite(tc) && isfinite(tb)) {
                snprintf(a, sizeof a, "%.3g / %.3g at %.3g", tc, tb, e_star);
                snprintf(b, sizeof b, "%.2f", tc / tb);
            }
            if (isfinite(ec) && isfinite(eb)) {
                snprintf(d, sizeof d, "%.3g / %.3g at %.3g s", ec, eb, t_star);
                snprintf(e, sizeof e, "%.2f", ec / eb);
            }
            printf("| %s | %s | %d | %.3g | %s | %s | %s | %s |\n", groups[g], C->name, C->n, lowest, a, b, d, e);
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    int rc = 2;
    if (argc >= 2 && !strcmp(argv[1], "render"))
        rc = cmd_render(argc - 2, argv + 2);
    else if (argc >= 2 && !strcmp(argv[1], "compare"))
        rc = cmd_compare(argc - 2, argv + 2);
    else if (argc >= 2 && !strcmp(argv[1], "attr"))
        rc = cmd_attr(argc - 2, argv + 2);
    else if (argc >= 2 && !strcmp(argv[1], "report"))
        rc = cmd_report(argc - 2, argv + 2);
    if (rc == 2)
        fprintf(stderr, "usage: bench_accuracy render|compare|attr|report ... (see bench/bench_accuracy.c)\n");
    return rc;
}
