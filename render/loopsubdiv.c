/* loopsubdiv.c - Loop subdivision surfaces (see lf_subdiv.h).
 *
 * The mesh is kept as plain arrays: three vertex indices per triangle and,
 * rebuilt at every level from an edge hash table, the triangle across each
 * of its edges.  Child triangles and new vertices are numbered as pbrt-v4
 * numbers them (four children per parent in order, then the old vertices,
 * then one new vertex per edge in order of first use). */
#include "base/lf_sampler.h"
#include "lf_subdiv.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define NEXT(k) ((k) == 2 ? 0 : (k) + 1)
#define PREV(k) ((k) == 0 ? 2 : (k) - 1)

typedef struct topo {
    size_t nv, nf, ne;
    const int *fv;         /* 3 per face */
    int *fn;               /* 3 per face: face across edge (v[k], v[k+1]), -1 on a boundary */
    int *fe;               /* 3 per face: index of edge (v[k], v[k+1]) */
    int *vstart;           /* per vertex: a face that uses it, -1 if none */
    unsigned char *vbound; /* per vertex: on a boundary */
    size_t cut;            /* edges left unshared (non-manifold or misoriented) */
} topo;

static void topo_free(topo *t)
{
    free(t->fn);
    free(t->fe);
    free(t->vstart);
    free(t->vbound);
    memset(t, 0, sizeof *t);
}

static int vnum(const topo *t, int f, int v)
{
    const int *w = t->fv + 3 * (size_t)f;
    return w[0] == v ? 0 : w[1] == v ? 1 : 2;
}
static int next_face(const topo *t, int f, int v) { return t->fn[3 * (size_t)f + vnum(t, f, v)]; }
static int prev_face(const topo *t, int f, int v) { return t->fn[3 * (size_t)f + PREV(vnum(t, f, v))]; }
static int next_vert(const topo *t, int f, int v) { return t->fv[3 * (size_t)f + NEXT(vnum(t, f, v))]; }
static int prev_vert(const topo *t, int f, int v) { return t->fv[3 * (size_t)f + PREV(vnum(t, f, v))]; }

/* Face adjacency, edge numbering and boundary flags. */
static int topo_build(topo *t, size_t nv, size_t nf, const int *fv, lf_error *err)
{
    memset(t, 0, sizeof *t);
    t->nv = nv;
    t->nf = nf;
    t->fv = fv;
    t->fn = malloc(3 * nf * sizeof *t->fn);
    t->fe = malloc(3 * nf * sizeof *t->fe);
    t->vstart = malloc((nv ? nv : 1) * sizeof *t->vstart);
    t->vbound = calloc(nv ? nv : 1, 1);
    size_t cap = 16;
    while (cap < 6 * nf)
        cap *= 2;
    uint64_t *keys = malloc(cap * sizeof *keys);
    int *slot_fk = malloc(cap * sizeof *slot_fk); /* 3 * face + k of the first use */
    if (!t->fn || !t->fe || !t->vstart || !t->vbound || !keys || !slot_fk) {
        free(keys), free(slot_fk);
        topo_free(t);
        return lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
    }
    memset(keys, 0xff, cap * sizeof *keys); /* UINT64_MAX: empty */
    for (size_t i = 0; i < nv; i++)
        t->vstart[i] = -1;
    int rc = LF_OK;
    for (size_t f = 0; f < nf; f++) {
        for (int k = 0; k < 3; k++) {
            int a = fv[3 * f + k], b = fv[3 * f + NEXT(k)];
            t->vstart[a] = (int)f;
            uint64_t lo = (uint64_t)(a < b ? a : b), hi = (uint64_t)(a < b ? b : a);
            uint64_t key = lo << 32 | hi;
            size_t i = lf_hash_u64(key) & (cap - 1);
            while (keys[i] != UINT64_MAX && keys[i] != key)
                i = (i + 1) & (cap - 1);
            if (keys[i] == UINT64_MAX) {
                keys[i] = key;
                slot_fk[i] = (int)(3 * f + (size_t)k);
                t->fn[3 * f + k] = -1;
                t->fe[3 * f + k] = (int)t->ne++;
                continue;
            }
            int first = slot_fk[i];
            int g = first / 3, gk = first % 3;
            if (first < 0 || fv[3 * (size_t)g + gk] != b) {
                /* A third triangle on an edge, or two that run it the same
                 * way: not an oriented 2-manifold there.  The edge is cut
                 * (this side gets an edge of its own, on the boundary), as
                 * pbrt-v4 also leaves such edges unshared; the surface may
                 * crease there but everything stays defined. */
                t->fn[3 * f + k] = -1;
                t->fe[3 * f + k] = (int)t->ne++;
                t->cut++;
                continue;
            }
            t->fn[3 * f + k] = g;
            t->fn[first] = (int)f;
            t->fe[3 * f + k] = t->fe[first];
            slot_fk[i] = -1; /* both sides seen */
        }
    }
    free(keys);
    free(slot_fk);
    if (rc) {
        topo_free(t);
        return rc;
    }
    /* A vertex is on the boundary if walking around it ends at a missing
     * neighbour; every walk is bounded by the number of faces. */
    for (size_t v = 0; v < nv; v++) {
        int f = t->vstart[v];
        if (f < 0)
            continue;
        size_t steps = 0;
        do {
            f = next_face(t, f, (int)v);
        } while (f >= 0 && f != t->vstart[v] && ++steps <= nf);
        if (f >= 0 && f != t->vstart[v]) {
            topo_free(t);
            return lf_error_set(err, LF_ERR_PARAM, "loopsubdiv: the triangles around vertex %zu do not form a fan", v);
        }
        t->vbound[v] = f < 0;
    }
    return LF_OK;
}

/* The one ring of v in pbrt's order (for a boundary vertex the two ends are
 * its boundary neighbours).  *ring grows as needed; returns the count, or -1
 * when out of memory. */
static int one_ring(const topo *t, int v, int **ring, size_t *cap)
{
    size_t n = 0;
#define PUSH(x)                                                                                                        \
    do {                                                                                                               \
        if (n == *cap) {                                                                                               \
            size_t nc = *cap ? 2 * *cap : 16;                                                                          \
            int *r = realloc(*ring, nc * sizeof *r);                                                                   \
            if (!r)                                                                                                    \
                return -1;                                                                                             \
            *ring = r;                                                                                                 \
            *cap = nc;                                                                                                 \
        }                                                                                                              \
        (*ring)[n++] = (x);                                                                                            \
    } while (0)
    int start = t->vstart[v];
    if (start < 0)
        return 0;
    if (!t->vbound[v]) {
        int f = start;
        do {
            PUSH(next_vert(t, f, v));
            f = next_face(t, f, v);
        } while (f != start && f >= 0 && n <= t->nf);
    } else {
        int f = start, g;
        size_t steps = 0;
        while ((g = next_face(t, f, v)) >= 0 && ++steps <= t->nf)
            f = g;
        PUSH(next_vert(t, f, v));
        do {
            PUSH(prev_vert(t, f, v));
            f = prev_face(t, f, v);
        } while (f >= 0 && n <= t->nf + 1);
    }
#undef PUSH
    return (int)n;
}

static double loop_beta(int n) { return n == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * n); }

/* Vertex v's new position q from its one ring: a boundary vertex takes
 * ws p + wn (a + b) with its two boundary neighbours, (3/4, 1/8) when
 * refining and (3/5, 1/5) for the limit; an interior one (1 - n w) p +
 * w (sum of the ring), w = beta(n) when refining and 1 / (n + 3 / (8 beta))
 * for the limit (Loop 1987; pbrt-v4's LoopSubdivide).  Returns the ring
 * size (0: an unused vertex, copied), or -1 when memory runs out. */
static int vertex_mask(const topo *t, const double *P, size_t v, int limit, int **ring, size_t *rcap, double *q)
{
    const double *p = P + 3 * v;
    int n = one_ring(t, (int)v, ring, rcap);
    if (n == 0)
        memcpy(q, p, 3 * sizeof *q);
    if (n <= 0)
        return n;
    if (t->vbound[v]) {
        const double *a = P + 3 * (size_t)(*ring)[0], *b = P + 3 * (size_t)(*ring)[n - 1];
        const double ws = limit ? 0.6 : 0.75, wn = limit ? 0.2 : 0.125;
        for (int c = 0; c < 3; c++)
            q[c] = ws * p[c] + wn * (a[c] + b[c]);
        return n;
    }
    double beta = loop_beta(n), w = limit ? 1.0 / (n + 3.0 / (8.0 * beta)) : beta, s[3] = {0, 0, 0};
    for (int j = 0; j < n; j++)
        for (int c = 0; c < 3; c++)
            s[c] += P[3 * (size_t)(*ring)[j] + c];
    for (int c = 0; c < 3; c++)
        q[c] = (1.0 - n * w) * p[c] + w * s[c];
    return n;
}

/* One level: P (3 * nv) and the faces of t -> P2 (3 * (nv + ne)), F2 (12 * nf). */
static int refine(const topo *t, const double *P, double *P2, int *F2, int **ring, size_t *rcap, lf_error *err)
{
    size_t nv = t->nv;
    for (size_t v = 0; v < nv; v++) /* even vertices */
        if (vertex_mask(t, P, v, 0, ring, rcap, P2 + 3 * v) < 0)
            return lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
    unsigned char *done = calloc(t->ne ? t->ne : 1, 1);
    if (!done)
        return lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
    for (size_t f = 0; f < t->nf; f++) { /* odd (edge) vertices */
        for (int k = 0; k < 3; k++) {
            int e = t->fe[3 * f + k];
            if (done[e])
                continue;
            done[e] = 1;
            const double *a = P + 3 * (size_t)t->fv[3 * f + k], *b = P + 3 * (size_t)t->fv[3 * f + NEXT(k)];
            double *q = P2 + 3 * (nv + (size_t)e);
            int g = t->fn[3 * f + k];
            if (g < 0) {
                for (int c = 0; c < 3; c++)
                    q[c] = 0.5 * (a[c] + b[c]);
            } else {
                const double *o1 = P + 3 * (size_t)t->fv[3 * f + PREV(k)];
                int gk = vnum(t, g, t->fv[3 * f + NEXT(k)]); /* in g the edge runs b -> a */
                const double *o2 = P + 3 * (size_t)t->fv[3 * (size_t)g + PREV(gk)];
                for (int c = 0; c < 3; c++)
                    q[c] = 0.375 * (a[c] + b[c]) + 0.125 * (o1[c] + o2[c]);
            }
        }
    }
    free(done);
    for (size_t f = 0; f < t->nf; f++) { /* four children per face */
        int odd[3];
        for (int k = 0; k < 3; k++)
            odd[k] = (int)(nv + (size_t)t->fe[3 * f + k]);
        for (int j = 0; j < 3; j++) {
            int *c = F2 + 3 * (4 * f + (size_t)j);
            c[j] = t->fv[3 * f + j];
            c[NEXT(j)] = odd[j];
            c[PREV(j)] = odd[PREV(j)];
        }
        int *c = F2 + 3 * (4 * f + 3);
        c[0] = odd[0], c[1] = odd[1], c[2] = odd[2];
    }
    return LF_OK;
}

static void sub3(const double *a, const double *b, double *o) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }

/* Limit positions and normals of the final level. */
static int limit_surface(const topo *t, const double *P, float *outP, float *outN, int **ring, size_t *rcap,
                         lf_error *err)
{
    double *L = malloc((t->nv ? t->nv : 1) * 3 * sizeof *L);
    if (!L)
        return lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
    for (size_t v = 0; v < t->nv; v++)
        if (vertex_mask(t, P, v, 1, ring, rcap, L + 3 * v) < 0) {
            free(L);
            return lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
        }
    for (size_t v = 0; v < t->nv; v++) {
        int n = one_ring(t, (int)v, ring, rcap);
        if (n < 0) {
            free(L);
            return lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
        }
        const double *p = L + 3 * v;
        double S[3] = {0, 0, 0}, T[3] = {0, 0, 0};
#define R(j) (L + 3 * (size_t)(*ring)[j])
        if (n == 0) {
            /* unused vertex: no surface, no normal */
        } else if (!t->vbound[v]) {
            for (int j = 0; j < n; j++) {
                double cs = cos(2 * M_PI * j / n), sn = sin(2 * M_PI * j / n);
                for (int c = 0; c < 3; c++) {
                    S[c] += cs * R(j)[c];
                    T[c] += sn * R(j)[c];
                }
            }
        } else {
            sub3(R(n - 1), R(0), S);
            for (int c = 0; c < 3; c++) {
                if (n == 2)
                    T[c] = R(0)[c] + R(1)[c] - 2 * p[c];
                else if (n == 3)
                    T[c] = R(1)[c] - p[c];
                else if (n == 4)
                    T[c] = -R(0)[c] + 2 * R(1)[c] + 2 * R(2)[c] - R(3)[c] - 2 * p[c];
                else {
                    double th = M_PI / (n - 1), x = sin(th) * (R(0)[c] + R(n - 1)[c]);
                    for (int k = 1; k < n - 1; k++)
                        x += (2 * cos(th) - 2) * sin(k * th) * R(k)[c];
                    T[c] = -x;
                }
            }
        }
#undef R
        double N[3] = {S[1] * T[2] - S[2] * T[1], S[2] * T[0] - S[0] * T[2], S[0] * T[1] - S[1] * T[0]};
        double len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
        for (int c = 0; c < 3; c++) {
            outP[3 * v + c] = (float)p[c];
            outN[3 * v + c] = len > 0 && isfinite(len) ? (float)(N[c] / len) : 0.f;
        }
    }
    /* Where the tangents are parallel (a collapsed neighbourhood), the
     * normal of the surrounding triangles, on the same side as the tangent
     * normals (against the winding, see lf_subdiv.h). */
    for (size_t f = 0; f < t->nf; f++) {
        const int *w = t->fv + 3 * f;
        int needs = 0;
        for (int k = 0; k < 3; k++)
            needs |= t->vstart[w[k]] >= 0 && outN[3 * w[k]] == 0.f && outN[3 * w[k] + 1] == 0.f &&
                     outN[3 * w[k] + 2] == 0.f;
        if (!needs)
            continue;
        double u[3], e[3];
        sub3(L + 3 * (size_t)w[1], L + 3 * (size_t)w[0], u);
        sub3(L + 3 * (size_t)w[2], L + 3 * (size_t)w[0], e);
        double n[3] = {-(u[1] * e[2] - u[2] * e[1]), -(u[2] * e[0] - u[0] * e[2]), -(u[0] * e[1] - u[1] * e[0])};
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 0))
            continue;
        for (int k = 0; k < 3; k++) {
            float *o = outN + 3 * (size_t)w[k];
            if (o[0] == 0.f && o[1] == 0.f && o[2] == 0.f)
                for (int c = 0; c < 3; c++)
                    o[c] = (float)(n[c] / len);
        }
    }
    free(L);
    return LF_OK;
}

int lf_loop_subdivide(const double *P, size_t nv, const int *indices, size_t nt, int levels, lf_ply_mesh *out,
                      lf_error *err)
{
    memset(out, 0, sizeof *out);
    if (levels < 0 || levels > LF_LOOP_MAX_LEVELS)
        return lf_error_set(err, LF_ERR_PARAM, "loopsubdiv: \"levels\" must be 0 to %d, got %d", LF_LOOP_MAX_LEVELS,
                            levels);
    if (nt == 0 || nv == 0)
        return lf_error_set(err, LF_ERR_PARAM, "loopsubdiv: needs at least one triangle");
    /* Every level makes 4x the triangles and about 4x the vertices. */
    double final_tris = (double)nt * pow(4.0, levels), final_verts = (double)nv + (double)nt * 3 * pow(4.0, levels);
    if (final_tris * 3 > INT_MAX || final_verts > INT_MAX)
        return lf_error_set(err, LF_ERR_PARAM,
                            "loopsubdiv: %d levels would make %.0f triangles, more than a mesh can index", levels,
                            final_tris);
    for (size_t i = 0; i < 3 * nt; i++)
        if (indices[i] < 0 || (size_t)indices[i] >= nv)
            return lf_error_set(err, LF_ERR_PARAM, "loopsubdiv: index %d (triangle %zu) is not a vertex (0..%zu)",
                                indices[i], i / 3, nv - 1);
    double *curP = malloc(3 * nv * sizeof *curP);
    int *curF = malloc(3 * nt * sizeof *curF);
    int *ring = NULL;
    size_t rcap = 0;
    if (!curP || !curF) {
        free(curP), free(curF);
        return lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
    }
    memcpy(curP, P, 3 * nv * sizeof *curP);
    /* Triangles that repeat a vertex have no area and no consistent
     * neighbours: they are dropped. */
    size_t cf = 0;
    for (size_t f = 0; f < nt; f++) {
        const int *w = indices + 3 * f;
        if (w[0] != w[1] && w[1] != w[2] && w[0] != w[2])
            memcpy(curF + 3 * cf++, w, 3 * sizeof *w);
    }
    if (cf == 0) {
        free(curP), free(curF);
        return lf_error_set(err, LF_ERR_PARAM, "loopsubdiv: every triangle repeats a vertex");
    }
    size_t cv = nv;
    topo t;
    int rc = topo_build(&t, cv, cf, curF, err);
    for (int level = 0; !rc && level < levels; level++) {
        size_t nv2 = cv + t.ne, nf2 = 4 * cf;
        double *P2 = malloc(3 * nv2 * sizeof *P2);
        int *F2 = malloc(3 * nf2 * sizeof *F2);
        if (!P2 || !F2) {
            free(P2), free(F2);
            rc = lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory at level %d", level + 1);
            break;
        }
        rc = refine(&t, curP, P2, F2, &ring, &rcap, err);
        topo_free(&t);
        free(curP), free(curF);
        curP = P2, curF = F2, cv = nv2, cf = nf2;
        if (!rc)
            rc = topo_build(&t, cv, cf, curF, err);
    }
    if (!rc) {
        out->P = malloc(3 * cv * sizeof *out->P);
        out->N = malloc(3 * cv * sizeof *out->N);
        if (!out->P || !out->N)
            rc = lf_error_set(err, LF_ERR_NOMEM, "loopsubdiv: out of memory");
        else
            rc = limit_surface(&t, curP, out->P, out->N, &ring, &rcap, err);
        topo_free(&t);
    }
    free(ring);
    free(curP);
    if (rc) {
        free(curF);
        lf_ply_free(out);
        memset(out, 0, sizeof *out);
        return rc;
    }
    out->n_vertices = cv;
    out->indices = curF;
    out->n_triangles = cf;
    return LF_OK;
}
