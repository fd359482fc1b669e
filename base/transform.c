#include "lf_math.h"

#include <stdlib.h>
#include <string.h>

lf_transform lf_transform_identity(void)
{
    lf_transform t;
    memset(&t, 0, sizeof t);
    for (int i = 0; i < 4; i++)
        t.m[i][i] = t.inv[i][i] = 1.0;
    return t;
}

/* Gauss-Jordan inversion with partial pivoting. */
static int invert4(const double m[4][4], double out[4][4])
{
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 8; c++)
            a[r][c] = c < 4 ? m[r][c] : (c - 4 == r ? 1.0 : 0.0);
    double scale = 0.0;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            if (fabs(m[r][c]) > scale)
                scale = fabs(m[r][c]);
    if (scale == 0.0)
        return -1;
    for (int col = 0; col < 4; col++) {
        int piv = col;
        for (int r = col + 1; r < 4; r++)
            if (fabs(a[r][col]) > fabs(a[piv][col]))
                piv = r;
        if (fabs(a[piv][col]) <= 1e-300 || fabs(a[piv][col]) < scale * 1e-14)
            return -1;
        if (piv != col)
            for (int c = 0; c < 8; c++) {
                double tmp = a[col][c];
                a[col][c] = a[piv][c];
                a[piv][c] = tmp;
            }
        double d = 1.0 / a[col][col];
        for (int c = 0; c < 8; c++)
            a[col][c] *= d;
        for (int r = 0; r < 4; r++) {
            if (r == col)
                continue;
            double f = a[r][col];
            if (f != 0.0)
                for (int c = 0; c < 8; c++)
                    a[r][c] -= f * a[col][c];
        }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            out[r][c] = a[r][c + 4];
    return 0;
}

int lf_transform_from_matrix(const double m[4][4], lf_transform *out)
{
    lf_transform t;
    memcpy(t.m, m, sizeof t.m);
    if (invert4(m, t.inv))
        return -1;
    *out = t;
    return 0;
}

lf_transform lf_transform_translate(double x, double y, double z)
{
    lf_transform t = lf_transform_identity();
    t.m[0][3] = x;
    t.m[1][3] = y;
    t.m[2][3] = z;
    t.inv[0][3] = -x;
    t.inv[1][3] = -y;
    t.inv[2][3] = -z;
    return t;
}

lf_transform lf_transform_scale(double x, double y, double z)
{
    lf_transform t = lf_transform_identity();
    t.m[0][0] = x;
    t.m[1][1] = y;
    t.m[2][2] = z;
    t.inv[0][0] = 1.0 / x;
    t.inv[1][1] = 1.0 / y;
    t.inv[2][2] = 1.0 / z;
    return t;
}

lf_transform lf_transform_rotate(double angle_deg, double ax, double ay, double az)
{
    double len = sqrt(ax * ax + ay * ay + az * az);
    lf_transform t = lf_transform_identity();
    if (len == 0.0)
        return t;
    ax /= len;
    ay /= len;
    az /= len;
    double th = angle_deg * LF_PI / 180.0;
    double s = sin(th), c = cos(th);
    t.m[0][0] = ax * ax + (1 - ax * ax) * c;
    t.m[0][1] = ax * ay * (1 - c) - az * s;
    t.m[0][2] = ax * az * (1 - c) + ay * s;
    t.m[1][0] = ax * ay * (1 - c) + az * s;
    t.m[1][1] = ay * ay + (1 - ay * ay) * c;
    t.m[1][2] = ay * az * (1 - c) - ax * s;
    t.m[2][0] = ax * az * (1 - c) - ay * s;
    t.m[2][1] = ay * az * (1 - c) + ax * s;
    t.m[2][2] = az * az + (1 - az * az) * c;
    for (int r = 0; r < 4; r++)
        for (int col = 0; col < 4; col++)
            t.inv[r][col] = t.m[col][r]; /* rotation: inverse = transpose */
    return t;
}

int lf_transform_look_at(const double eye[3], const double look[3], const double up[3], lf_transform *out)
{
    /* pbrt-v4 LookAt: columns of camera-to-world are right, newUp, dir, eye. */
    double dir[3] = {look[0] - eye[0], look[1] - eye[1], look[2] - eye[2]};
    double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double ul = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    if (dl == 0.0 || ul == 0.0)
        return -1;
    for (int i = 0; i < 3; i++)
        dir[i] /= dl;
    double u[3] = {up[0] / ul, up[1] / ul, up[2] / ul};
    double right[3] = {u[1] * dir[2] - u[2] * dir[1], u[2] * dir[0] - u[0] * dir[2], u[0] * dir[1] - u[1] * dir[0]};
    double rl = sqrt(right[0] * right[0] + right[1] * right[1] + right[2] * right[2]);
    if (rl < 1e-12)
        return -1;
    for (int i = 0; i < 3; i++)
        right[i] /= rl;
    double nu[3] = {dir[1] * right[2] - dir[2] * right[1], dir[2] * right[0] - dir[0] * right[2],
                    dir[0] * right[1] - dir[1] * right[0]};
    double c2w[4][4] = {{right[0], nu[0], dir[0], eye[0]},
                        {right[1], nu[1], dir[1], eye[1]},
                        {right[2], nu[2], dir[2], eye[2]},
                        {0, 0, 0, 1}};
    lf_transform t;
    if (lf_transform_from_matrix(c2w, &t))
        return -1;
    *out = lf_transform_inverse(&t);
    return 0;
}

lf_transform lf_transform_compose(const lf_transform *a, const lf_transform *b)
{
    lf_transform r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0.0, si = 0.0;
            for (int k = 0; k < 4; k++) {
                s += a->m[i][k] * b->m[k][j];
                si += b->inv[i][k] * a->inv[k][j];
            }
            r.m[i][j] = s;
            r.inv[i][j] = si;
        }
    return r;
}

lf_transform lf_transform_inverse(const lf_transform *t)
{
    lf_transform r;
    memcpy(r.m, t->inv, sizeof r.m);
    memcpy(r.inv, t->m, sizeof r.inv);
    return r;
}

int lf_transform_is_identity(const lf_transform *t)
{
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            if (t->m[i][j] != (i == j ? 1.0 : 0.0))
                return 0;
    return 1;
}

int lf_transform_swaps_handedness(const lf_transform *t)
{
    const double(*m)[4] = t->m;
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    return det < 0.0;
}

lf_dvec3 lf_xform_point_d(const lf_transform *t, lf_dvec3 p)
{
    const double(*m)[4] = t->m;
    double x = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
    double y = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
    double z = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
    double w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
    lf_dvec3 r = {x, y, z};
    if (w != 1.0 && w != 0.0) {
        r.x /= w;
        r.y /= w;
        r.z /= w;
    }
    return r;
}

lf_dvec3 lf_xform_vector_d(const lf_transform *t, lf_dvec3 v)
{
    const double(*m)[4] = t->m;
    lf_dvec3 r = {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                  m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    return r;
}

lf_vec3 lf_xform_point(const lf_transform *t, lf_vec3 p)
{
    lf_dvec3 d = {p.x, p.y, p.z};
    d = lf_xform_point_d(t, d);
    return lf_v3((float)d.x, (float)d.y, (float)d.z);
}

lf_vec3 lf_xform_vector(const lf_transform *t, lf_vec3 v)
{
    lf_dvec3 d = {v.x, v.y, v.z};
    d = lf_xform_vector_d(t, d);
    return lf_v3((float)d.x, (float)d.y, (float)d.z);
}

lf_vec3 lf_xform_normal(const lf_transform *t, lf_vec3 n)
{
    const double(*mi)[4] = t->inv;
    return lf_v3((float)(mi[0][0] * n.x + mi[1][0] * n.y + mi[2][0] * n.z),
                 (float)(mi[0][1] * n.x + mi[1][1] * n.y + mi[2][1] * n.z),
                 (float)(mi[0][2] * n.x + mi[1][2] * n.y + mi[2][2] * n.z));
}

static double det3(const double m[3][3])
{
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

static void inv3(const double m[3][3], double out[3][3], double det)
{
    out[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
    out[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
    out[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
    out[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
    out[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    out[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
    out[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
    out[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
    out[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
}

/* Rotation matrix -> unit quaternion (Shepperd's method, stable branch). */
static void quat_from_matrix(const double r[3][3], double q[4])
{
    double tr = r[0][0] + r[1][1] + r[2][2];
    if (tr > 0) {
        double s = sqrt(tr + 1.0) * 2;
        q[3] = 0.25 * s;
        q[0] = (r[2][1] - r[1][2]) / s;
        q[1] = (r[0][2] - r[2][0]) / s;
        q[2] = (r[1][0] - r[0][1]) / s;
    } else if (r[0][0] > r[1][1] && r[0][0] > r[2][2]) {
        double s = sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2;
        q[3] = (r[2][1] - r[1][2]) / s;
        q[0] = 0.25 * s;
        q[1] = (r[0][1] + r[1][0]) / s;
        q[2] = (r[0][2] + r[2][0]) / s;
    } else if (r[1][1] > r[2][2]) {
        double s = sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2;
        q[3] = (r[0][2] - r[2][0]) / s;
        q[0] = (r[0][1] + r[1][0]) / s;
        q[1] = 0.25 * s;
        q[2] = (r[1][2] + r[2][1]) / s;
    } else {
        double s = sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2;
        q[3] = (r[1][0] - r[0][1]) / s;
        q[0] = (r[0][2] + r[2][0]) / s;
        q[1] = (r[1][2] + r[2][1]) / s;
        q[2] = 0.25 * s;
    }
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++)
        q[i] /= l;
}

static void matrix_from_quat(const double q[4], double r[3][3])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    r[0][0] = 1 - 2 * (y * y + z * z), r[0][1] = 2 * (x * y - z * w), r[0][2] = 2 * (x * z + y * w);
    r[1][0] = 2 * (x * y + z * w), r[1][1] = 1 - 2 * (x * x + z * z), r[1][2] = 2 * (y * z - x * w);
    r[2][0] = 2 * (x * z - y * w), r[2][1] = 2 * (y * z + x * w), r[2][2] = 1 - 2 * (x * x + y * y);
}

int lf_transform_decompose(const lf_transform *m, lf_decomposed *out)
{
    double M[3][3], R[3][3];
    for (int i = 0; i < 3; i++) {
        out->t[i] = m->m[i][3];
        for (int j = 0; j < 3; j++)
            M[i][j] = R[i][j] = m->m[i][j];
    }
    double det = det3(M);
    if (!(fabs(det) > 1e-300) || !isfinite(det))
        return -1;
    /* Polar decomposition: R <- (R + R^-T) / 2 converges to the rotation
     * (a reflection when det < 0: pbrt handles that the same way). */
    for (int it = 0; it < 100; it++) {
        double Ri[3][3], d = det3(R);
        if (!(fabs(d) > 1e-300))
            return -1;
        inv3(R, Ri, d);
        double norm = 0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double next = 0.5 * (R[i][j] + Ri[j][i]);
                norm = fmax(norm, fabs(next - R[i][j]));
                R[i][j] = next;
            }
        if (norm < 1e-14)
            break;
    }
    int reflect = det3(R) < 0;
    double Rr[3][3];
    memcpy(Rr, R, sizeof Rr);
    if (reflect) /* keep a proper rotation for the quaternion; the reflection goes into S */
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                Rr[i][j] = -R[i][j];
    quat_from_matrix(Rr, out->q);
    /* S = R^-1 M = R^T M (with the reflection folded in) */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0;
            for (int k = 0; k < 3; k++)
                s += Rr[k][i] * M[k][j];
            out->s[i][j] = s;
        }
    return 0;
}

void lf_decomposed_matrix(const lf_decomposed *a, const lf_decomposed *b, double f, double m[4][4])
{
    double q[4], qb[4] = {b->q[0], b->q[1], b->q[2], b->q[3]};
    double dot = a->q[0] * qb[0] + a->q[1] * qb[1] + a->q[2] * qb[2] + a->q[3] * qb[3];
    if (dot < 0) { /* shortest arc */
        for (int i = 0; i < 4; i++)
            qb[i] = -qb[i];
        dot = -dot;
    }
    if (dot > 0.9995) {
        for (int i = 0; i < 4; i++)
            q[i] = (1 - f) * a->q[i] + f * qb[i];
    } else {
        double th = acos(dot < 1 ? dot : 1), s = sin(th);
        double wa = sin((1 - f) * th) / s, wb = sin(f * th) / s;
        for (int i = 0; i < 4; i++)
            q[i] = wa * a->q[i] + wb * qb[i];
    }
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++)
        q[i] /= l;
    double R[3][3];
    memset(m, 0, sizeof(double) * 16);
    matrix_from_quat(q, R);
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double s = 0;
            for (int k = 0; k < 3; k++)
                s += R[i][k] * ((1 - f) * a->s[k][j] + f * b->s[k][j]);
            m[i][j] = s;
        }
        m[i][3] = (1 - f) * a->t[i] + f * b->t[i];
    }
    m[3][3] = 1;
}

void lf_motion_pair_prepare(const lf_decomposed *a, const lf_decomposed *b, lf_motion_pair *p)
{
    double dot = 0;
    for (int i = 0; i < 4; i++)
        dot += a->q[i] * b->q[i];
    double sign = dot < 0 ? -1.0 : 1.0; /* shortest arc */
    for (int i = 0; i < 4; i++)
        p->qa[i] = a->q[i], p->qb[i] = sign * b->q[i];
    dot *= sign;
    p->lerp = dot > 0.9995;
    p->theta = acos(dot < 1 ? dot : 1);
    p->cos_theta = cos(p->theta);
    p->sin_theta = sin(p->theta);
    memcpy(p->sa, a->s, sizeof p->sa);
    memcpy(p->sb, b->s, sizeof p->sb);
    p->same_scale = !memcmp(p->sa, p->sb, sizeof p->sa);
    memcpy(p->ta, a->t, sizeof p->ta);
    memcpy(p->tb, b->t, sizeof p->tb);
}

void lf_motion_pair_matrix(const lf_motion_pair *p, double f, double m[4][4])
{
    /* Called per camera ray of a moving camera: written out on locals (the
     * output cannot alias the keys then, so nothing is reloaded), the
     * scale lerp skipped when both keys share it, and the slerp's sine and
     * cosine by series where the angle allows (lf_sincos_quarter). */
    double wa = 1 - f, wb = f;
    if (!p->lerp) {
        /* sin((1-f) th) = sin th cos(f th) - cos th sin(f th) */
        double x = f * p->theta, sf, cf;
        if (fabs(x) <= M_PI / 4)
            lf_sincos_quarter(x, &sf, &cf);
        else
            sf = sin(x), cf = cos(x);
        wa = (p->sin_theta * cf - p->cos_theta * sf) / p->sin_theta;
        wb = sf / p->sin_theta;
    }
    double x = wa * p->qa[0] + wb * p->qb[0], y = wa * p->qa[1] + wb * p->qb[1];
    double z = wa * p->qa[2] + wb * p->qb[2], w = wa * p->qa[3] + wb * p->qb[3];
    double il = 1.0 / sqrt(x * x + y * y + z * z + w * w);
    x *= il, y *= il, z *= il, w *= il;
    /* the rotation, as matrix_from_quat */
    double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                      {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                      {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    double Sl[3][3];
    const double(*S)[3] = p->sa;
    if (!p->same_scale) {
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                Sl[i][j] = (1 - f) * p->sa[i][j] + f * p->sb[i][j];
        S = (const double(*)[3])Sl;
    }
    double s00 = S[0][0], s01 = S[0][1], s02 = S[0][2], s10 = S[1][0], s11 = S[1][1], s12 = S[1][2];
    double s20 = S[2][0], s21 = S[2][1], s22 = S[2][2];
    double t0 = (1 - f) * p->ta[0] + f * p->tb[0], t1 = (1 - f) * p->ta[1] + f * p->tb[1];
    double t2 = (1 - f) * p->ta[2] + f * p->tb[2];
    m[0][0] = R[0][0] * s00 + R[0][1] * s10 + R[0][2] * s20;
    m[0][1] = R[0][0] * s01 + R[0][1] * s11 + R[0][2] * s21;
    m[0][2] = R[0][0] * s02 + R[0][1] * s12 + R[0][2] * s22;
    m[1][0] = R[1][0] * s00 + R[1][1] * s10 + R[1][2] * s20;
    m[1][1] = R[1][0] * s01 + R[1][1] * s11 + R[1][2] * s21;
    m[1][2] = R[1][0] * s02 + R[1][1] * s12 + R[1][2] * s22;
    m[2][0] = R[2][0] * s00 + R[2][1] * s10 + R[2][2] * s20;
    m[2][1] = R[2][0] * s01 + R[2][1] * s11 + R[2][2] * s21;
    m[2][2] = R[2][0] * s02 + R[2][1] * s12 + R[2][2] * s22;
    m[0][3] = t0, m[1][3] = t1, m[2][3] = t2;
    m[3][0] = m[3][1] = m[3][2] = 0, m[3][3] = 1;
}

int lf_motion_table_init(const lf_motion_pair *p, double max_err, int max_n, lf_motion_table *t)
{
    t->n = 0;
    t->m = NULL;
    /* |M''| <= (2 theta)^2 |S| + 2 (2 theta) |dS| (rotation by 2 theta over
     * f in [0, 1] at constant rate; nlerp'd pairs are within 1e-3 rad of
     * that), taken with a factor 2 of margin; scales are bounded by their
     * largest entry */
    double smax = 0, ds = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            smax = fmax(smax, fmax(fabs(p->sa[i][j]), fabs(p->sb[i][j])));
            ds = fmax(ds, fabs(p->sb[i][j] - p->sa[i][j]));
        }
    double rot = 2 * p->theta;
    double d2 = 2 * 3 * (rot * rot * smax + 2 * rot * ds); /* 3: a row sums three entries */
    double n = ceil(sqrt(d2 / (8 * max_err)));
    if (n < 1)
        n = 1;
    if (!(n <= max_n))
        return 0;
    t->n = (int)n;
    t->m = malloc(sizeof *t->m * (size_t)(t->n + 1));
    if (!t->m) {
        t->n = 0;
        return 0;
    }
    for (int k = 0; k <= t->n; k++) {
        double m[4][4];
        lf_motion_pair_matrix(p, (double)k / t->n, m);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++)
                t->m[k][4 * i + j] = m[i][j];
    }
    return 1;
}

void lf_motion_table_free(lf_motion_table *t)
{
    free(t->m);
    t->m = NULL;
    t->n = 0;
}

lf_transform lf_decomposed_interpolate(const lf_decomposed *a, const lf_decomposed *b, double f)
{
    double m[4][4];
    lf_decomposed_matrix(a, b, f, m);
    lf_transform t;
    if (lf_transform_from_matrix(m, &t))
        t = lf_transform_identity();
    return t;
}

int lf_mat3_inverse(const double a[3][3], double o[3][3])
{
    double d = det3(a);
    if (!(fabs(d) > 1e-300) || !isfinite(d))
        return -1;
    inv3(a, o, d);
    return 0;
}
