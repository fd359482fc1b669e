/* Parse + build time of a Shape "loopsubdiv" scene at levels 1 and 3
 * (issue 18; docs/scene-format.md records the figures).
 *
 * The control mesh is killeroo-sized: an icosahedron split by midpoints
 * three times (1280 triangles, 642 vertices; pbrt-v4-scenes' killeroo has
 * about 2900 triangles), pushed onto a bumpy blob.  For each level the
 * bench times, median of RUNS:
 *   parse      lf_scene_parse_string on the scene text (numbers to doubles)
 *   subdivide  lf_loop_subdivide alone
 *   create     lf_renderer_create: scene build, incl. the subdivision and
 *              Embree's BVH build (rtcCommitScene)
 *
 *   build/bin/bench_loopsubdiv [RUNS]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/lf_render.h"
#include "scenefile/lf_scene_desc.h"
#include "render/lf_subdiv.h"
#include "bench/bench_util.h"

/* midpoint-split icosahedron */
static int nv, nf;
static double P[3 * 2000];
static int F[3 * 1300];

static int midpoint(int a, int b, int *cache_a, int *cache_b, int *cache_v, int *nc)
{
    for (int i = 0; i < *nc; i++)
        if ((cache_a[i] == a && cache_b[i] == b) || (cache_a[i] == b && cache_b[i] == a))
            return cache_v[i];
    for (int c = 0; c < 3; c++)
        P[3 * nv + c] = 0.5 * (P[3 * a + c] + P[3 * b + c]);
    cache_a[*nc] = a, cache_b[*nc] = b, cache_v[*nc] = nv;
    (*nc)++;
    return nv++;
}

static void make_mesh(void)
{
    const double t = 1.6180339887498949;
    const double V[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                             {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const int I[60] = {0, 11, 5, 0, 5, 1,  0, 1, 7,  0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                       4, 11, 10, 2, 10, 7, 6, 7, 1, 8,  3, 9, 4,  3, 4,  2,  3, 2, 6, 3,
                       6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6,  7,  9, 8, 1};
    memcpy(P, V, sizeof V);
    memcpy(F, I, sizeof I);
    nv = 12, nf = 20;
    static int ca[4000], cb[4000], cv[4000];
    for (int s = 0; s < 3; s++) {
        int nc = 0, F2[3 * 1300], n2 = 0;
        for (int f = 0; f < nf; f++) {
            int a = F[3 * f], b = F[3 * f + 1], c = F[3 * f + 2];
            int ab = midpoint(a, b, ca, cb, cv, &nc), bc = midpoint(b, c, ca, cb, cv, &nc),
                ca_ = midpoint(c, a, ca, cb, cv, &nc);
            int tri[12] = {a, ab, ca_, ab, b, bc, ca_, bc, c, ab, bc, ca_};
            memcpy(F2 + 3 * n2, tri, sizeof tri);
            n2 += 4;
        }
        memcpy(F, F2, sizeof(int) * 3 * n2);
        nf = n2;
    }
    for (int i = 0; i < nv; i++) { /* onto a bumpy blob of radius ~40 */
        double *p = P + 3 * i, r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        double k = 40 * (1 + 0.15 * sin(3 * p[0]) * cos(2 * p[1]) + 0.1 * sin(5 * p[2])) / r;
        p[0] *= k, p[1] *= 1.3 * k, p[2] *= 0.8 * k;
    }
}

static char *scene_text(int levels)
{
    size_t cap = 1 << 20, n = 0;
    char *s = malloc(cap);
    n += (size_t)snprintf(s + n, cap - n,
                          "LookAt 0 -200 0  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 40\n"
                          "Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 64\nWorldBegin\n"
                          "LightSource \"distant\" \"point3 from\" [0 -1 1]\n"
                          "Shape \"loopsubdiv\" \"integer levels\" %d\n  \"point3 P\" [",
                          levels);
    for (int i = 0; i < 3 * nv; i++)
        n += (size_t)snprintf(s + n, cap - n, " %.3f", P[i]);
    n += (size_t)snprintf(s + n, cap - n, " ]\n  \"integer indices\" [");
    for (int i = 0; i < 3 * nf; i++)
        n += (size_t)snprintf(s + n, cap - n, " %d", F[i]);
    snprintf(s + n, cap - n, " ]\n");
    return s;
}

int main(int argc, char **argv)
{
    int runs = argc > 1 ? atoi(argv[1]) : 7;
    if (runs < 1)
        runs = 1;
    make_mesh();
    printf("control mesh: %d vertices, %d triangles; median of %d runs\n\n", nv, nf, runs);
    printf("| levels | triangles | parse (ms) | subdivide (ms) | renderer create: subdivide + BVH (ms) |\n");
    printf("|---|---|---|---|---|\n");
    int levels_list[2] = {1, 3};
    for (int li = 0; li < 2; li++) {
        int levels = levels_list[li];
        char *text = scene_text(levels);
        double *tp = malloc(sizeof(double) * runs), *ts = malloc(sizeof(double) * runs),
               *tc = malloc(sizeof(double) * runs);
        size_t tris = 0;
        for (int r = 0; r < runs; r++) {
            lf_scene_desc d;
            lf_error err = {0};
            double t0 = lf_seconds();
            if (lf_scene_parse_string(text, "bench.pbrt", &d, &err)) {
                fprintf(stderr, "%s\n", err.msg);
                return 1;
            }
            double t1 = lf_seconds();
            lf_ply_mesh m;
            double *dp = malloc(sizeof(double) * 3 * nv);
            for (int i = 0; i < 3 * nv; i++)
                dp[i] = P[i];
            double t2 = lf_seconds();
            if (lf_loop_subdivide(dp, (size_t)nv, F, (size_t)nf, levels, &m, &err)) {
                fprintf(stderr, "%s\n", err.msg);
                return 1;
            }
            double t3 = lf_seconds();
            tris = m.n_triangles;
            lf_ply_free(&m);
            free(dp);
            lf_render_opts o = lf_render_opts_default();
            o.threads = 2;
            lf_renderer *rr;
            double t4 = lf_seconds();
            if (lf_renderer_create(&d, &o, &rr, &err)) {
                fprintf(stderr, "%s\n", err.msg);
                return 1;
            }
            double t5 = lf_seconds();
            lf_renderer_free(rr);
            lf_scene_desc_free(&d);
            tp[r] = 1e3 * (t1 - t0), ts[r] = 1e3 * (t3 - t2), tc[r] = 1e3 * (t5 - t4);
        }
        printf("| %d | %zu | %.2f | %.2f | %.2f |\n", levels, tris, bench_median(tp, runs), bench_median(ts, runs),
               bench_median(tc, runs));
        free(text);
        free(tp), free(ts), free(tc);
    }
    return 0;
}
