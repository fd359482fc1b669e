/* Plain regions of the depth map (depth_internal.h; docs/depth.md,
 * "Plain regions").  A region whose pixels' cost curves are flat (no
 * label is better than another beyond what the views' noise gives) has no
 * depth in the data; the aggregation hands it whatever reaches it, and at
 * a silhouette that is the nearer surface (the foreground spreads over a
 * plain background).  Here such a region takes the far end of the
 * evidence around it that has its colour: its own foot, the edges of the
 * shadows on it; a nearer object's outline is of another colour. */
#include <stdlib.h>

#include "lightfield/depth_internal.h"

enum {
    COLOUR_BOX = 2,      /* colours compared as 5 x 5 box means (noise) */
    EVIDENCE_REACH = 2,  /* evidence within 2 px of the region counts */
    MIN_EVIDENCE = 8,    /* fewer such pixels: the region is left alone */
    MIN_EVIDENCE_NEIGHBOURS = 2,
};
static const float JOIN_TOL = 0.02f;     /* neighbours join a region when their colours differ by less */
static const float EVIDENCE_TOL = 0.04f; /* evidence counts when its colour is this close to the region's mean */
static const double MIN_REGION = 1e-3;   /* of the image: smaller regions are left to the aggregation */
/* evidence counts when its aggregated curve is decisive: the confidence
 * the range estimate calls confident (docs/depth.md, "Disparity range");
 * in noisy views most pixels that pass the plain test are noise */
static const float EVIDENCE_MIN_CONFIDENCE = 0.3f;
/* the far end of the evidence: its lower quartile, robust to the mixed
 * pixels of a nearer outline of the same colour and to the spread of small
 * marks' own estimates (0.1 and 0.25 compared on the tune split: 17.72 and
 * 17.58 %; the test's clean wall 25 and 2 %) */
static const double FAR_QUANTILE = 0.25;

/* 5 x 5 box means of the 3-channel image src into dst (clamped borders). */
static void box3(const float *src, float *dst, int w, int h)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float s[3] = {0, 0, 0};
            int n = 0;
            for (int yy = y - COLOUR_BOX; yy <= y + COLOUR_BOX; yy++) {
                if (yy < 0 || yy >= h)
                    continue;
                for (int xx = x - COLOUR_BOX; xx <= x + COLOUR_BOX; xx++) {
                    if (xx < 0 || xx >= w)
                        continue;
                    const float *p = src + 3 * ((size_t)yy * w + xx);
                    s[0] += p[0], s[1] += p[1], s[2] += p[2], n++;
                }
            }
            float *d = dst + 3 * ((size_t)y * w + x);
            d[0] = s[0] / n, d[1] = s[1] / n, d[2] = s[2] / n;
        }
}

static inline float colour_gap(const float *a, const float *b)
{
    float g = 0;
    for (int c = 0; c < 3; c++) {
        float d = a[c] > b[c] ? a[c] - b[c] : b[c] - a[c];
        g = d > g ? d : g;
    }
    return g;
}

/* Evidence pixel (x, y) has evidence beside it: at least 2 of its 8
 * neighbours.  A plain pixel passes the noise test by chance 1 time in
 * 100, alone; an edge or a textured patch comes in lines and clusters. */
static int clustered(const unsigned char *plain, int w, int h, int x, int y)
{
    int n = 0;
    for (int yy = y - 1; yy <= y + 1; yy++)
        for (int xx = x - 1; xx <= x + 1; xx++)
            if ((xx != x || yy != y) && xx >= 0 && xx < w && yy >= 0 && yy < h && !plain[(size_t)yy * w + xx])
                n++;
    return n >= MIN_EVIDENCE_NEIGHBOURS;
}

int lf_depth_plain_fill(float *map, const unsigned char *plain, const float *conf, const float *refs, int w, int h,
                        lf_error *err)
{
    size_t np = (size_t)w * h;
    float *col = malloc(sizeof(float) * 3 * np), *ev = malloc(sizeof(float) * np);
    int *region = malloc(sizeof(int) * np), *stamp = malloc(sizeof(int) * np);
    size_t *queue = malloc(sizeof(size_t) * np);
    if (!col || !ev || !region || !stamp || !queue) {
        free(col), free(ev), free(region), free(stamp), free(queue);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the plain-region step");
    }
    box3(refs, col, w, h);
    for (size_t i = 0; i < np; i++)
        region[i] = -1, stamp[i] = -1;
    size_t min_region = (size_t)(MIN_REGION * (double)np);
    int id = 0;
    for (size_t seed = 0; seed < np; seed++) {
        if (!plain[seed] || region[seed] >= 0)
            continue;
        /* the 4-connected plain pixels of one colour */
        size_t head = 0, tail = 0;
        queue[tail++] = seed, region[seed] = id;
        double mean[3] = {0, 0, 0};
        while (head < tail) {
            size_t i = queue[head++];
            int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
            for (int c = 0; c < 3; c++)
                mean[c] += col[3 * i + c];
            const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
            for (int k = 0; k < 4; k++) {
                if (nx[k] < 0 || nx[k] >= w || ny[k] < 0 || ny[k] >= h)
                    continue;
                size_t j = (size_t)ny[k] * w + nx[k];
                if (!plain[j] || region[j] >= 0)
                    continue;
                /* against the region's mean so far, not the neighbour: a
                 * gradient of colour must not chain a region across the image */
                float m[3] = {(float)(mean[0] / head), (float)(mean[1] / head), (float)(mean[2] / head)};
                if (colour_gap(m, col + 3 * j) < JOIN_TOL)
                    region[j] = id, queue[tail++] = j;
            }
        }
        size_t n = tail;
        if (n >= min_region) {
            float m[3] = {(float)(mean[0] / n), (float)(mean[1] / n), (float)(mean[2] / n)};
            /* the evidence of the region's colour within reach of it */
            size_t ne = 0;
            for (size_t q = 0; q < n; q++) {
                size_t i = queue[q];
                int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
                for (int yy = y - EVIDENCE_REACH; yy <= y + EVIDENCE_REACH; yy++) {
                    if (yy < 0 || yy >= h)
                        continue;
                    for (int xx = x - EVIDENCE_REACH; xx <= x + EVIDENCE_REACH; xx++) {
                        if (xx < 0 || xx >= w)
                            continue;
                        size_t j = (size_t)yy * w + xx;
                        if (plain[j] || stamp[j] == id || conf[j] < EVIDENCE_MIN_CONFIDENCE || !clustered(plain, w, h, xx, yy) ||
                            colour_gap(col + 3 * j, m) >= EVIDENCE_TOL)
                            continue;
                        stamp[j] = id, ev[ne++] = map[j];
                    }
                }
            }
            if (ne >= MIN_EVIDENCE) {
                qsort(ev, ne, sizeof *ev, lf_depth_cmpf);
                float far = ev[(size_t)(FAR_QUANTILE * (double)(ne - 1))];
                /* only ever farther: a plain region's error is the nearer
                 * surface grown over it, never the reverse */
                for (size_t q = 0; q < n; q++)
                    if (map[queue[q]] > far)
                        map[queue[q]] = far;
            }
        }
        id++;
    }
    free(col), free(ev), free(region), free(stamp), free(queue);
    return LF_OK;
}
