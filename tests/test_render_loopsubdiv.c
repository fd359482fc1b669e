/* Loop subdivision (render/lf_subdiv.h) against properties that hold for
 * any correct implementation, computed here independently:
 *   - a planar control mesh stays in its plane, normals along the plane's;
 *   - a regular (valence 6) interior vertex ends at Loop's limit mask
 *     v/2 + sum(ring)/12, at every level (the limit point is invariant);
 *   - the boundary rule only sees boundary vertices: moving an interior
 *     control point leaves the boundary limit points where they are;
 *   - a closed mesh stays closed (every edge used twice, opposite ways,
 *     Euler characteristic 2), lies inside the convex control polyhedron,
 *     and its silhouettes converge with the level;
 *   - normals are unit, consistently oriented, and perpendicular to the
 *     surface (compared with the faces around each vertex);
 *   - the Shape "loopsubdiv" path renders the same as the equivalent
 *     trianglemesh with those normals. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "render/lf_subdiv.h"

static const double phi = 1.6180339887498949;

static void icosahedron(double P[36], int F[60])
{
    const double V[12][3] = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
                             {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
    const int I[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                          {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                          {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    memcpy(P, V, sizeof V);
    memcpy(F, I, sizeof I);
}

static void face_normal(const float *P, const int *f, double n[3])
{
    const float *a = P + 3 * f[0], *b = P + 3 * f[1], *c = P + 3 * f[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
}

/* Every vertex normal is unit and within `max_deg` of the area-weighted
 * normal of its triangles; returns the common sign (+1: along the winding's
 * right-hand normal, -1: against it, 0: mixed). */
static int check_normals(const lf_ply_mesh *m, double max_deg)
{
    double *acc = calloc(3 * m->n_vertices, sizeof *acc);
    for (size_t t = 0; t < m->n_triangles; t++) {
        double n[3];
        face_normal(m->P, m->indices + 3 * t, n);
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++)
                acc[3 * m->indices[3 * t + k] + c] += n[c];
    }
    int pos = 0, neg = 0;
    double worst = 0;
    for (size_t v = 0; v < m->n_vertices; v++) {
        const float *N = m->N + 3 * v;
        double *a = acc + 3 * v, la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        double ln = sqrt((double)N[0] * N[0] + (double)N[1] * N[1] + (double)N[2] * N[2]);
        CHECK_NEAR(ln, 1.0, 1e-5);
        double c = (a[0] * N[0] + a[1] * N[1] + a[2] * N[2]) / (la * ln);
        if (c > 0)
            pos++;
        else
            neg++;
        double deg = acos(fmin(1.0, fabs(c))) * 180 / M_PI;
        if (deg > worst)
            worst = deg;
    }
    CHECK_MSG(worst <= max_deg, "a vertex normal is %.2f deg from its faces' normal (limit %.1f)", worst, max_deg);
    free(acc);
    return pos && neg ? 0 : pos ? 1 : -1;
}

static void test_planar(void)
{
    /* A 4x4-quad grid in the plane n.p = 2 with n = (1,2,3)/|..|, rows of
     * triangles alternating diagonals; every vertex jittered within the
     * plane so no symmetry hides an error. */
    const int G = 4;
    double e1[3] = {2, -1, 0}, e2[3] = {3, 6, -5}; /* both perpendicular to (1,2,3) */
    double n[3] = {1, 2, 3}, ln = sqrt(14.0);
    double P[3 * 25];
    int F[3 * 32], nf = 0;
    for (int j = 0; j <= G; j++)
        for (int i = 0; i <= G; i++) {
            double u = i + 0.2 * sin(3.1 * i + 1.7 * j), v = j + 0.2 * cos(2.3 * i - 0.9 * j);
            for (int c = 0; c < 3; c++)
                P[3 * (j * (G + 1) + i) + c] = 2 * n[c] / ln + 0.3 * u * e1[c] / sqrt(5.0) + 0.3 * v * e2[c] / sqrt(70.0);
        }
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            int a = j * (G + 1) + i, b = a + 1, c = a + G + 1, d = c + 1;
            if ((i + j) % 2) {
                int t[6] = {a, b, d, a, d, c};
                memcpy(F + 3 * nf, t, sizeof t);
            } else {
                int t[6] = {a, b, c, b, d, c};
                memcpy(F + 3 * nf, t, sizeof t);
            }
            nf += 2;
        }
    for (int levels = 0; levels <= 3; levels++) {
        lf_ply_mesh m;
        lf_error err = {0};
        int rc = lf_loop_subdivide(P, 25, F, (size_t)nf, levels, &m, &err);
        CHECK_MSG(rc == 0, "%s", err.msg);
        if (rc)
            continue;
        CHECK(m.n_triangles == (size_t)nf << (2 * levels));
        double worst = 0, worst_n = 0;
        for (size_t v = 0; v < m.n_vertices; v++) {
            const float *p = m.P + 3 * v, *q = m.N + 3 * v;
            double d = (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / ln - 2.0;
            double c = fabs(q[0] * n[0] + q[1] * n[1] + q[2] * n[2]) / ln;
            worst = fmax(worst, fabs(d));
            worst_n = fmax(worst_n, 1 - c);
        }
        CHECK_MSG(worst < 1e-5, "level %d: a vertex is %g off the plane", levels, worst);
        CHECK_MSG(worst_n < 1e-5, "level %d: a normal is %g off the plane normal (1 - cos)", levels, worst_n);
        CHECK(check_normals(&m, 1e-2) != 0);
        lf_ply_free(&m);
    }
}

static void test_regular_vertex_limit(void)
{
    /* Vertex 0 with six neighbours at different heights; two rings, so the
     * inner ring is interior too. */
    double P[3 * 19];
    int F[3 * 24], nf = 0;
    P[0] = 0.1, P[1] = -0.05, P[2] = 0.4;
    for (int k = 0; k < 6; k++) {
        double a = k * M_PI / 3;
        P[3 * (1 + k) + 0] = cos(a);
        P[3 * (1 + k) + 1] = sin(a);
        P[3 * (1 + k) + 2] = 0.3 * sin(2.0 * k + 0.5);
    }
    for (int k = 0; k < 12; k++) { /* outer ring: corners and edge midpoints of a bigger hexagon */
        double a = k * M_PI / 6, r = k % 2 ? 2 * cos(M_PI / 6) : 2;
        P[3 * (7 + k) + 0] = r * cos(a);
        P[3 * (7 + k) + 1] = r * sin(a);
        P[3 * (7 + k) + 2] = 0.2 * cos(1.3 * k);
    }
    for (int k = 0; k < 6; k++) {
        int a = 1 + k, b = 1 + (k + 1) % 6;
        int o0 = 7 + 2 * k, o1 = 7 + 2 * k + 1, o2 = 7 + (2 * k + 2) % 12;
        int t[12] = {0, a, b, a, o0, o1, a, o1, b, b, o1, o2};
        memcpy(F + 3 * nf, t, sizeof t);
        nf += 4;
    }
    /* Loop's limit mask for valence 6: beta = 1/16, chi = 1/(3/(8 beta) + 6) = 1/12. */
    double want[3];
    for (int c = 0; c < 3; c++) {
        double s = 0;
        for (int k = 1; k <= 6; k++)
            s += P[3 * k + c];
        want[c] = 0.5 * P[c] + s / 12.0;
    }
    for (int levels = 0; levels <= 4; levels++) {
        lf_ply_mesh m;
        lf_error err = {0};
        if (lf_loop_subdivide(P, 19, F, (size_t)nf, levels, &m, &err)) {
            CHECK_MSG(0, "%s", err.msg);
            continue;
        }
        /* old vertices keep their index at every level */
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(m.P[c], want[c], 1e-6);
        CHECK(check_normals(&m, 30.0) != 0);
        lf_ply_free(&m);
    }
}

static void test_boundary_independent_of_interior(void)
{
    /* The fan above without the outer ring: vertices 1..6 are boundary
     * vertices.  Moving the interior vertex 0 must not move them. */
    double P[3 * 7];
    int F[3 * 6];
    for (int k = 0; k < 6; k++) {
        double a = k * M_PI / 3 + 0.1 * k * k;
        P[3 * (1 + k) + 0] = cos(a);
        P[3 * (1 + k) + 1] = sin(a);
        P[3 * (1 + k) + 2] = 0.25 * cos(3.0 * k);
        F[3 * k] = 0, F[3 * k + 1] = 1 + k, F[3 * k + 2] = 1 + (k + 1) % 6;
    }
    P[0] = 0, P[1] = 0, P[2] = 0.5;
    lf_ply_mesh a, b;
    lf_error err = {0};
    int rc = lf_loop_subdivide(P, 7, F, 6, 3, &a, &err);
    P[2] = -2.0;
    P[0] = 0.3;
    rc |= lf_loop_subdivide(P, 7, F, 6, 3, &b, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (rc)
        return;
    CHECK(a.n_vertices == b.n_vertices);
    /* boundary vertices: those on an edge used once */
    int nb = 0, moved = 0;
    for (size_t v = 0; v < a.n_vertices; v++) {
        int on_boundary = 0;
        for (size_t t = 0; t < a.n_triangles && !on_boundary; t++)
            for (int k = 0; k < 3; k++) {
                int p = a.indices[3 * t + k], q = a.indices[3 * t + (k + 1) % 3];
                if (p != (int)v && q != (int)v)
                    continue;
                int uses = 0;
                for (size_t s = 0; s < a.n_triangles; s++)
                    for (int j = 0; j < 3; j++) {
                        int x = a.indices[3 * s + j], y = a.indices[3 * s + (j + 1) % 3];
                        uses += (x == p && y == q) || (x == q && y == p);
                    }
                on_boundary |= uses == 1;
            }
        if (!on_boundary)
            continue;
        nb++;
        double d = 0;
        for (int c = 0; c < 3; c++)
            d = fmax(d, fabs(a.P[3 * v + c] - b.P[3 * v + c]));
        moved += d > 1e-6;
    }
    CHECK(nb == 6 * 8); /* 6 boundary edges, each split into 8 */
    CHECK_MSG(moved == 0, "%d boundary limit points moved with an interior control point", moved);
    lf_ply_free(&a);
    lf_ply_free(&b);
}

/* Largest projection of the mesh onto direction d. */
static double extent(const float *P, size_t n, const double d[3])
{
    double m = -1e300;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, P[3 * i] * d[0] + P[3 * i + 1] * d[1] + P[3 * i + 2] * d[2]);
    return m;
}

static void test_closed(void)
{
    double P[36];
    int F[60];
    icosahedron(P, F);
    lf_ply_mesh m[5];
    for (int levels = 0; levels <= 4; levels++) {
        lf_error err = {0};
        int rc = lf_loop_subdivide(P, 12, F, 20, levels, &m[levels], &err);
        CHECK_MSG(rc == 0, "%s", err.msg);
        if (rc)
            return;
        lf_ply_mesh *s = &m[levels];
        /* closed: every directed edge has its reverse, exactly once */
        size_t ne = 3 * s->n_triangles, bad = 0;
        for (size_t e = 0; e < ne && levels <= 2; e++) {
            int a = s->indices[e], b = s->indices[e % 3 == 2 ? e - 2 : e + 1];
            int rev = 0, same = 0;
            for (size_t g = 0; g < ne; g++) {
                int c = s->indices[g], d = s->indices[g % 3 == 2 ? g - 2 : g + 1];
                rev += c == b && d == a;
                same += c == a && d == b;
            }
            bad += rev != 1 || same != 1;
        }
        CHECK_MSG(bad == 0, "level %d: %zu edges not shared by exactly two triangles", levels, bad);
        /* Euler: V - E + F = 2 for a sphere */
        CHECK((long)s->n_vertices - (long)(ne / 2) + (long)s->n_triangles == 2);
        /* inside the convex control polyhedron */
        double worst = -1e300;
        for (int f = 0; f < 20; f++) {
            const double *a = P + 3 * F[3 * f], *b = P + 3 * F[3 * f + 1], *c = P + 3 * F[3 * f + 2];
            double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
            double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (size_t i = 0; i < s->n_vertices; i++) {
                const float *p = s->P + 3 * i;
                worst = fmax(worst, ((p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1] + (p[2] - a[2]) * n[2]) / ln);
            }
        }
        CHECK_MSG(worst < 1e-6, "level %d: a vertex is %g outside the control polyhedron", levels, worst);
        int sign = check_normals(s, levels == 0 ? 40.0 : levels == 1 ? 15.0 : 6.0);
        /* pbrt-v4's tangent order gives S x T on the side opposite the
         * right-hand winding normal; lensfield keeps pbrt's convention (the
         * geometric normal follows the shading normal, as in pbrt). */
        CHECK_MSG(sign == -1, "level %d: normals point %s", levels, sign ? "along the winding" : "both ways");
    }
    /* Silhouettes, as the extent in 50 directions: never beyond the control
     * mesh's (convex hull), converging with the level (levels 3 and 4 agree
     * to 0.5 %), and within 4 % of the sphere through the limit points of
     * the control vertices, 0.7236 of the circumradius (valence-5 limit mask
     * v/2 + sum(ring)/10, neighbours at cos = 1/sqrt 5): the limit surface
     * of a regular icosahedron is nearly round. */
    double R = sqrt(1 + phi * phi), worst_conv = 0, lo = 1e300, hi = 0, over = -1e300;
    double vertex_limit = (0.5 + 0.5 / sqrt(5.0)) * R;
    for (int k = 0; k < 50; k++) {
        double z = 1 - (k + 0.5) / 25.0, r = sqrt(1 - z * z), a = k * 2.399963;
        double d[3] = {r * cos(a), r * sin(a), z};
        double e4 = extent(m[4].P, m[4].n_vertices, d), e3 = extent(m[3].P, m[3].n_vertices, d);
        double ec = 0;
        for (int i = 0; i < 12; i++)
            ec = fmax(ec, P[3 * i] * d[0] + P[3 * i + 1] * d[1] + P[3 * i + 2] * d[2]);
        over = fmax(over, e4 - ec);
        worst_conv = fmax(worst_conv, fabs(e4 - e3) / e4);
        lo = fmin(lo, e4 / vertex_limit);
        hi = fmax(hi, e4 / vertex_limit);
    }
    CHECK_MSG(over <= 1e-6, "the silhouette reaches %g beyond the control mesh's", over);
    CHECK_MSG(worst_conv < 0.005, "silhouettes of levels 3 and 4 differ by %.3f%%", 100 * worst_conv);
    CHECK_MSG(lo > 0.96 && hi < 1.0 + 1e-6, "silhouette radius %.4f..%.4f of the vertex limit sphere", lo, hi);
    for (int l = 0; l <= 4; l++)
        lf_ply_free(&m[l]);
}

/* Not a 2-manifold, or misoriented: the offending edges become boundary
 * edges (two boundary vertices at one place), so the result is still a
 * finite surface whose vertex count shows the cut. */
static void test_non_manifold(void)
{
    lf_ply_mesh m;
    lf_error err = {0};
    double P[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    /* two triangles running edge (0,1) the same way: 5 edges + 1 for the cut -> 5 + 6 vertices after one level */
    int bad_orient[6] = {0, 1, 2, 0, 1, 3};
    CHECK(lf_loop_subdivide(P, 5, bad_orient, 2, 1, &m, &err) == 0);
    CHECK(m.n_triangles == 8 && m.n_vertices == 5 + 6);
    int finite = 1;
    for (size_t i = 0; i < 3 * m.n_vertices; i++)
        finite &= isfinite(m.P[i]) && isfinite(m.N[i]);
    CHECK(finite);
    lf_ply_free(&m);
    /* three triangles on edge (0,1): the third's copy of the edge is its own */
    int three[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    CHECK(lf_loop_subdivide(P, 5, three, 3, 2, &m, &err) == 0);
    CHECK(m.n_triangles == 48);
    lf_ply_free(&m);
    /* a degenerate triangle is dropped */
    int degen[6] = {0, 1, 2, 2, 2, 3};
    CHECK(lf_loop_subdivide(P, 5, degen, 2, 1, &m, &err) == 0 && m.n_triangles == 4);
    lf_ply_free(&m);
}

static void test_errors(void)
{
    lf_ply_mesh m;
    lf_error err = {0};
    double P[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    int oob[3] = {0, 1, 7};
    CHECK(lf_loop_subdivide(P, 4, oob, 1, 1, &m, &err) == LF_ERR_PARAM);
    CHECK(strstr(err.msg, "index 7") != NULL);
    lf_error_clear(&err);
    int ok[3] = {0, 1, 2};
    CHECK(lf_loop_subdivide(P, 4, ok, 1, 11, &m, &err) == LF_ERR_PARAM);
    lf_error_clear(&err);
    CHECK(lf_loop_subdivide(P, 4, ok, 1, -1, &m, &err) == LF_ERR_PARAM);
    lf_error_clear(&err);
    int all_degenerate[3] = {1, 1, 2};
    CHECK(lf_loop_subdivide(P, 4, all_degenerate, 1, 1, &m, &err) == LF_ERR_PARAM);
}

int main(void)
{
    test_planar();
    test_regular_vertex_limit();
    test_boundary_independent_of_interior();
    test_closed();
    test_non_manifold();
    test_errors();
    return lf_test_end();
}
