#include "lf_math.h"

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
