/* lf_math.h - small vector and transform math shared by every module.
 *
 * lf_vec3 is single precision (what Embree and the integrator use);
 * lf_transform holds a 4x4 matrix and its inverse in double precision so that
 * chains of scene transforms and camera set-up stay accurate at large scale.
 * Matrices are row-major in memory: m[row][col], points are column vectors
 * (p' = M p), as in pbrt.  pbrt's `Transform [..16..]` directive lists the
 * matrix column-major; the parser transposes it.
 */
#ifndef LF_MATH_H
#define LF_MATH_H

#include <math.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LF_PI 3.14159265358979323846
#define LF_INV_PI 0.31830988618379067154
#define LF_INV_2PI 0.15915494309189533577
#define LF_INV_4PI 0.07957747154594766788
#define LF_ONE_MINUS_EPS 0x1.fffffep-1f

typedef struct lf_vec3 {
    float x, y, z;
} lf_vec3;

typedef struct lf_vec2 {
    float x, y;
} lf_vec2;

typedef struct lf_dvec3 {
    double x, y, z;
} lf_dvec3;

static inline lf_vec3 lf_v3(float x, float y, float z)
{
    lf_vec3 v = {x, y, z};
    return v;
}
static inline lf_vec3 lf_add(lf_vec3 a, lf_vec3 b) { return lf_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lf_vec3 lf_sub(lf_vec3 a, lf_vec3 b) { return lf_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lf_vec3 lf_mul(lf_vec3 a, lf_vec3 b) { return lf_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline lf_vec3 lf_scale(lf_vec3 a, float s) { return lf_v3(a.x * s, a.y * s, a.z * s); }
static inline lf_vec3 lf_madd(lf_vec3 a, lf_vec3 b, float s) { return lf_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline lf_vec3 lf_neg(lf_vec3 a) { return lf_v3(-a.x, -a.y, -a.z); }
static inline float lf_dot(lf_vec3 a, lf_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline float lf_absdot(lf_vec3 a, lf_vec3 b) { return fabsf(lf_dot(a, b)); }
static inline lf_vec3 lf_cross(lf_vec3 a, lf_vec3 b)
{
    return lf_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float lf_length(lf_vec3 a) { return sqrtf(lf_dot(a, a)); }
static inline lf_vec3 lf_normalize(lf_vec3 a)
{
    float l = lf_length(a);
    return l > 0.f ? lf_scale(a, 1.f / l) : a;
}
static inline float lf_maxc(lf_vec3 a)
{
    float m = a.x > a.y ? a.x : a.y;
    return m > a.z ? m : a.z;
}
static inline float lf_luminance(lf_vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline int lf_is_black(lf_vec3 c) { return c.x == 0.f && c.y == 0.f && c.z == 0.f; }
static inline float lf_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
static inline double lf_clampd(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }
static inline float lf_lerpf(float t, float a, float b) { return a + t * (b - a); }
static inline float lf_radians(float deg) { return deg * (float)(LF_PI / 180.0); }

/* Orthonormal basis around unit n (Duff et al. 2017, "Building an
 * Orthonormal Basis, Revisited"). */
static inline void lf_basis(lf_vec3 n, lf_vec3 *s, lf_vec3 *t)
{
    float sign = copysignf(1.f, n.z);
    float a = -1.f / (sign + n.z);
    float b = n.x * n.y * a;
    *s = lf_v3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    *t = lf_v3(b, sign + n.y * n.y * a, -n.y);
}

typedef struct lf_transform {
    double m[4][4];
    double inv[4][4];
} lf_transform;

lf_transform lf_transform_identity(void);
/* Builds from a row-major matrix; returns 0 and sets *out, or -1 if singular. */
int lf_transform_from_matrix(const double m[4][4], lf_transform *out);
lf_transform lf_transform_translate(double x, double y, double z);
lf_transform lf_transform_scale(double x, double y, double z);
/* Rotation by angle in degrees about axis (pbrt's Rotate). */
lf_transform lf_transform_rotate(double angle_deg, double ax, double ay, double az);
/* pbrt's LookAt: returns the world-to-camera transform.  Returns -1 if the
 * up vector is parallel to the viewing direction or eye == look. */
int lf_transform_look_at(const double eye[3], const double look[3], const double up[3], lf_transform *out);
lf_transform lf_transform_compose(const lf_transform *a, const lf_transform *b); /* a * b */
lf_transform lf_transform_inverse(const lf_transform *t);

/* o = a^-1 for a 3 x 3 matrix (cofactors over the determinant); -1 when
 * the determinant is 0 or not finite (o untouched). */
int lf_mat3_inverse(const double a[3][3], double o[3][3]);
int lf_transform_is_identity(const lf_transform *t);
/* True if the transform swaps handedness (negative determinant of 3x3). */
int lf_transform_swaps_handedness(const lf_transform *t);

lf_dvec3 lf_xform_point_d(const lf_transform *t, lf_dvec3 p);
lf_dvec3 lf_xform_vector_d(const lf_transform *t, lf_dvec3 v);
lf_vec3 lf_xform_point(const lf_transform *t, lf_vec3 p);
lf_vec3 lf_xform_vector(const lf_transform *t, lf_vec3 v);
/* Normals transform by the inverse transpose. */
lf_vec3 lf_xform_normal(const lf_transform *t, lf_vec3 n);

/* A transform split into translation, rotation (unit quaternion x y z w) and
 * a remaining stretch matrix, M = T R S, by polar decomposition (Shoemake &
 * Duff 1992, as pbrt's AnimatedTransform), so motion between two keyframes
 * can rotate rigidly instead of shearing through a matrix lerp. */
typedef struct lf_decomposed {
    double t[3];
    double q[4];
    double s[3][3];
} lf_decomposed;

/* Returns 0, or -1 if the linear part is singular (a degenerate keyframe). */
int lf_transform_decompose(const lf_transform *m, lf_decomposed *out);
/* Interpolates at f in [0,1]: lerp translation, slerp rotation (shortest
 * arc), lerp stretch. */
lf_transform lf_decomposed_interpolate(const lf_decomposed *a, const lf_decomposed *b, double f);
/* The same, forward matrix only (no inverse). */
void lf_decomposed_matrix(const lf_decomposed *a, const lf_decomposed *b, double f, double m[4][4]);

/* A keyframe pair prepared for many evaluations (per-sample camera motion):
 * the slerp's angle and the shortest-arc sign are found once, so each
 * evaluation costs one sine/cosine pair and a 3x3 product. */
typedef struct lf_motion_pair {
    double qa[4], qb[4];   /* qb on qa's hemisphere */
    double theta, cos_theta, sin_theta;
    int lerp;              /* nearly parallel: normalised lerp, as lf_decomposed_matrix */
    double sa[3][3], sb[3][3], ta[3], tb[3];
    int same_scale;        /* sa == sb: no scale lerp */
} lf_motion_pair;
void lf_motion_pair_prepare(const lf_decomposed *a, const lf_decomposed *b, lf_motion_pair *p);
/* Equals lf_decomposed_matrix(a, b, f, m) up to rounding (1e-15). */
void lf_motion_pair_matrix(const lf_motion_pair *p, double f, double m[4][4]);

/* A motion pair tabulated for evaluation per camera ray: the 3x4 matrix at
 * n + 1 evenly spaced times, lerped between them.  n is chosen so that the
 * lerp departs from lf_motion_pair_matrix by at most max_err (the lerp's
 * error is at most |M''| / (8 n^2), with |M''| bounded by the rotation's
 * angle and the scale's change); 0 from lf_motion_table_init (no table)
 * when that would take more than max_n steps. */
typedef struct lf_motion_table {
    int n;
    double (*m)[12];       /* n + 1 rows of a 3x4 matrix */
} lf_motion_table;
int lf_motion_table_init(const lf_motion_pair *p, double max_err, int max_n, lf_motion_table *t);
void lf_motion_table_free(lf_motion_table *t);
static inline void lf_motion_table_matrix(const lf_motion_table *t, double f, double m[4][4])
{
    double x = f * t->n;
    int k = (int)x;
    k = k < 0 ? 0 : (k >= t->n ? t->n - 1 : k);
    double w = x - k;
    const double *a = t->m[k], *b = t->m[k + 1];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            m[i][j] = a[4 * i + j] + w * (b[4 * i + j] - a[4 * i + j]);
    m[3][0] = m[3][1] = m[3][2] = 0, m[3][3] = 1;
}

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* sin and cos of x for |x| <= pi/4 by their Taylor series through x^15
 * and x^16: the first omitted terms are below 5e-17, so the result is as
 * good as libm's here, with no call and no branch (loops over many samples
 * vectorise). */
static inline void lf_sincos_quarter(double x, double *s, double *c)
{
    double x2 = x * x;
    *s = x * (1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880 +
         x2 * (-1.0 / 39916800 + x2 * (1.0 / 6227020800.0 + x2 * (-1.0 / 1307674368000.0))))))));
    *c = 1.0 + x2 * (-1.0 / 2 + x2 * (1.0 / 24 + x2 * (-1.0 / 720 + x2 * (1.0 / 40320 + x2 * (-1.0 / 3628800 +
         x2 * (1.0 / 479001600.0 + x2 * (-1.0 / 87178291200.0 + x2 * (1.0 / 20922789888000.0))))))));
}

/* Shirley-Chiu concentric mapping of [0,1)^2 onto the unit disk: area
 * preserving, so a uniform sample stays uniform and strata stay compact.
 * Written with selects instead of branches (same points as pbrt's form:
 * for |a| > |b| the angle is pi/4 b/a; otherwise pi/2 - pi/4 a/b, whose cos
 * and sin are the sin and cos of pi/4 a/b). */
/* Solves the n x n system A X = B in place by Gaussian elimination with
 * partial pivoting; A row-major n x n, B row-major n x nrhs, X left in B.
 * Returns 0 when a pivot falls below 1e-12 (singular or nearly), else 1. */
static inline int lf_solve(double *A, double *B, int n, int nrhs)
{
    for (int i = 0; i < n; i++) {
        int p = i;
        for (int r = i + 1; r < n; r++)
            if (fabs(A[r * n + i]) > fabs(A[p * n + i]))
                p = r;
        if (fabs(A[p * n + i]) < 1e-12)
            return 0;
        if (p != i) {
            for (int k = 0; k < n; k++) {
                double t = A[i * n + k];
                A[i * n + k] = A[p * n + k], A[p * n + k] = t;
            }
            for (int k = 0; k < nrhs; k++) {
                double t = B[i * nrhs + k];
                B[i * nrhs + k] = B[p * nrhs + k], B[p * nrhs + k] = t;
            }
        }
        for (int r = i + 1; r < n; r++) {
            double f = A[r * n + i] / A[i * n + i];
            for (int k = i; k < n; k++)
                A[r * n + k] -= f * A[i * n + k];
            for (int k = 0; k < nrhs; k++)
                B[r * nrhs + k] -= f * B[i * nrhs + k];
        }
    }
    for (int i = n - 1; i >= 0; i--)
        for (int k = 0; k < nrhs; k++) {
            double t = B[i * nrhs + k];
            for (int j = i + 1; j < n; j++)
                t -= A[i * n + j] * B[j * nrhs + k];
            B[i * nrhs + k] = t / A[i * n + i];
        }
    return 1;
}

static inline void lf_concentric_disk(double u, double v, double *x, double *y)
{
    double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    int horizontal = fabs(a) > fabs(b);
    double r = horizontal ? a : b, num = horizontal ? b : a;
    double t = num / (r != 0.0 ? r : 1.0); /* r == 0 only at the centre, where num == 0 */
    double sn, cs;
    lf_sincos_quarter((M_PI / 4.0) * t, &sn, &cs);
    *x = r * (horizontal ? cs : sn);
    *y = r * (horizontal ? sn : cs);
}

#ifdef __cplusplus
}
#endif
#endif
