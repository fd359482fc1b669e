/* ply.c - reads triangle meshes from PLY files for pbrt's "plymesh" shape.
 *
 * Formats ascii, binary_little_endian and binary_big_endian (PLY 1.0, Greg
 * Turk's specification).  From the "vertex" element: x y z, optional nx ny nz
 * and texture coordinates under any of the names u v / s t / texture_u
 * texture_v / texture_s texture_t; other properties are skipped.  From the
 * "face" element: the list "vertex_indices" (or "vertex_index"); triangles
 * are kept, quads split into (0,1,2) (0,2,3) as pbrt does, larger polygons
 * fan-triangulated; faces with fewer than 3 vertices are dropped (pbrt-v4
 * ignores them too).  Other elements are skipped.  The file may be gzipped.
 */
#include "lf_scene_desc.h"
#include "base/lf_file.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef enum ply_format { PLY_ASCII, PLY_BINARY_LE, PLY_BINARY_BE } ply_format;

typedef enum scalar_type { ST_INT8, ST_UINT8, ST_INT16, ST_UINT16, ST_INT32, ST_UINT32, ST_FLOAT32, ST_FLOAT64 } scalar_type;

static const struct {
    const char *name;
    scalar_type type;
} scalar_names[] = {
    {"char", ST_INT8},     {"int8", ST_INT8},     {"uchar", ST_UINT8},    {"uint8", ST_UINT8},
    {"short", ST_INT16},   {"int16", ST_INT16},   {"ushort", ST_UINT16},  {"uint16", ST_UINT16},
    {"int", ST_INT32},     {"int32", ST_INT32},   {"uint", ST_UINT32},    {"uint32", ST_UINT32},
    {"float", ST_FLOAT32}, {"float32", ST_FLOAT32}, {"double", ST_FLOAT64}, {"float64", ST_FLOAT64},
};

static const size_t scalar_size[] = {1, 1, 2, 2, 4, 4, 4, 8};

/* What the reader does with a property. */
typedef enum prop_role {
    ROLE_SKIP,
    ROLE_X, ROLE_Y, ROLE_Z,
    ROLE_NX, ROLE_NY, ROLE_NZ,
    ROLE_U, ROLE_V,
    ROLE_INDICES
} prop_role;

typedef struct ply_property {
    char name[64];
    int is_list;
    scalar_type count_type, type;
    prop_role role;
} ply_property;

typedef struct ply_element {
    char name[64];
    size_t count;
    ply_property *props;
    size_t n_props;
} ply_element;

typedef struct ply_reader {
    const char *path;
    const char *buf; /* NUL-terminated copy of the file */
    size_t len, pos;
    int line;        /* current line, for ascii messages */
    ply_format format;
    lf_error *err;
} ply_reader;

/* Where an error happened: path:line for ascii and the header, path (byte
 * offset) for binary data. */
static int ply_fail(ply_reader *r, int in_header, const char *msg, const char *detail)
{
    if (in_header || r->format == PLY_ASCII) {
        lf_loc at = {r->path, r->line, 0};
        return lf_error_at(r->err, LF_ERR_PARSE, &at, "%s%s", msg, detail ? detail : "");
    }
    return lf_error_set(r->err, LF_ERR_PARSE, "%s: %s%s (at byte %zu)", r->path, msg, detail ? detail : "", r->pos);
}

/* Next header line as [*s, *e); 0, or -1 at end of file. */
static int header_line(ply_reader *r, const char **s, const char **e)
{
    if (r->pos >= r->len)
        return -1;
    const char *b = r->buf + r->pos;
    const char *nl = memchr(b, '\n', r->len - r->pos);
    const char *end = nl ? nl : r->buf + r->len;
    r->pos = (size_t)(end - r->buf) + (nl ? 1 : 0);
    r->line++;
    if (end > b && end[-1] == '\r')
        end--;
    *s = b;
    *e = end;
    return 0;
}

/* Splits a header line into at most max words (copied, truncated to 63 chars). */
static int split_words(const char *s, const char *e, char words[][64], int max)
{
    int n = 0;
    while (s < e) {
        while (s < e && (*s == ' ' || *s == '\t'))
            s++;
        if (s >= e)
            break;
        const char *w = s;
        while (s < e && *s != ' ' && *s != '\t')
            s++;
        if (n < max) {
            size_t len = (size_t)(s - w) < 63 ? (size_t)(s - w) : 63;
            memcpy(words[n], w, len);
            words[n][len] = '\0';
        }
        n++;
    }
    return n;
}

static int scalar_from_name(const char *name, scalar_type *t)
{
    for (size_t i = 0; i < sizeof scalar_names / sizeof scalar_names[0]; i++)
        if (strcmp(scalar_names[i].name, name) == 0) {
            *t = scalar_names[i].type;
            return 0;
        }
    return -1;
}

static void free_elements(ply_element *els, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(els[i].props);
    free(els);
}

static int parse_header(ply_reader *r, ply_element **out_els, size_t *out_n)
{
    const char *s, *e;
    char w[6][64];
    ply_element *els = NULL;
    size_t n_els = 0;
    int have_format = 0;
    if (header_line(r, &s, &e) || split_words(s, e, w, 6) != 1 || strcmp(w[0], "ply") != 0)
        return ply_fail(r, 1, "not a PLY file: the first line must be \"ply\"", NULL);
    for (;;) {
        if (header_line(r, &s, &e)) {
            free_elements(els, n_els);
            return ply_fail(r, 1, "bad PLY header: end of file before end_header", NULL);
        }
        int nw = split_words(s, e, w, 6);
        if (nw == 0 || strcmp(w[0], "comment") == 0 || strcmp(w[0], "obj_info") == 0)
            continue;
        if (strcmp(w[0], "end_header") == 0)
            break;
        const char *bad = NULL;
        if (strcmp(w[0], "format") == 0) {
            if (nw != 3)
                bad = "bad PLY header: expected \"format <kind> 1.0\"";
            else if (strcmp(w[1], "ascii") == 0)
                r->format = PLY_ASCII;
            else if (strcmp(w[1], "binary_little_endian") == 0)
                r->format = PLY_BINARY_LE;
            else if (strcmp(w[1], "binary_big_endian") == 0)
                r->format = PLY_BINARY_BE;
            else
                bad = "bad PLY header: unknown format ";
            if (!bad && strcmp(w[2], "1.0") != 0)
                bad = "bad PLY header: unsupported version ";
            if (bad) {
                free_elements(els, n_els);
                const char *detail = nw != 3 ? NULL : strstr(bad, "version") ? w[2] : w[1];
                return ply_fail(r, 1, bad, detail);
            }
            have_format = 1;
        } else if (strcmp(w[0], "element") == 0) {
            char *end = NULL;
            unsigned long long count = nw == 3 ? strtoull(w[2], &end, 10) : 0;
            if (nw != 3 || !end || *end || w[2][0] == '-') {
                free_elements(els, n_els);
                return ply_fail(r, 1, "bad PLY header: expected \"element <name> <count>\"", NULL);
            }
            ply_element *ne = realloc(els, (n_els + 1) * sizeof *els);
            if (!ne) {
                free_elements(els, n_els);
                return lf_error_set(r->err, LF_ERR_NOMEM, "%s: out of memory", r->path);
            }
            els = ne;
            memset(&els[n_els], 0, sizeof els[n_els]);
            snprintf(els[n_els].name, sizeof els[n_els].name, "%s", w[1]);
            els[n_els].count = (size_t)count;
            n_els++;
        } else if (strcmp(w[0], "property") == 0) {
            ply_property p = {0};
            if (n_els == 0)
                bad = "bad PLY header: property before any element";
            else if (nw == 3 && strcmp(w[1], "list") != 0) {
                if (scalar_from_name(w[1], &p.type))
                    bad = "bad PLY header: unknown property type ";
                snprintf(p.name, sizeof p.name, "%s", w[2]);
            } else if (nw == 5 && strcmp(w[1], "list") == 0) {
                p.is_list = 1;
                if (scalar_from_name(w[2], &p.count_type) || scalar_from_name(w[3], &p.type))
                    bad = "bad PLY header: unknown list type in property ";
                snprintf(p.name, sizeof p.name, "%s", w[4]);
            } else {
                bad = "bad PLY header: expected \"property <type> <name>\" or \"property list <count type> <type> <name>\"";
            }
            if (bad) {
                free_elements(els, n_els);
                /* split_words counts every word but stores at most 6 */
                return ply_fail(r, 1, bad, strstr(bad, "type") && nw >= 2 ? w[(nw < 6 ? nw : 6) - 1] : NULL);
            }
            ply_element *el = &els[n_els - 1];
            ply_property *np = realloc(el->props, (el->n_props + 1) * sizeof *np);
            if (!np) {
                free_elements(els, n_els);
                return lf_error_set(r->err, LF_ERR_NOMEM, "%s: out of memory", r->path);
            }
            el->props = np;
            el->props[el->n_props++] = p;
        } else {
            free_elements(els, n_els);
            return ply_fail(r, 1, "bad PLY header: unknown keyword ", w[0]);
        }
    }
    if (!have_format) {
        free_elements(els, n_els);
        return ply_fail(r, 1, "bad PLY header: no format line", NULL);
    }
    *out_els = els;
    *out_n = n_els;
    return LF_OK;
}

static int host_is_little_endian(void)
{
    const uint16_t one = 1;
    return *(const unsigned char *)&one == 1;
}

/* Reads one scalar of type t: 0, -1 for a malformed value, or
 * END_OF_DATA. */
#define END_OF_DATA (-2)

static int read_scalar(ply_reader *r, scalar_type t, double *out)
{
    if (r->format == PLY_ASCII) {
        const char *p = r->buf + r->pos;
        int line = r->line;
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') {
            if (*p == '\n')
                line++;
            p++;
        }
        r->pos = (size_t)(p - r->buf);
        if (!*p || r->pos >= r->len)
            return END_OF_DATA; /* r->line stays on the last line with data */
        r->line = line;
        char *end;
        double v = strtod(p, &end);
        if (end == p || (*end && *end != ' ' && *end != '\t' && *end != '\r' && *end != '\n'))
            return -1;
        r->pos = (size_t)(end - r->buf);
        if (!isfinite(v) || (t < ST_FLOAT32 && v != floor(v)))
            return -1;
        *out = v;
        return 0;
    }
    size_t n = scalar_size[t];
    if (r->len - r->pos < n)
        return END_OF_DATA;
    unsigned char b[8];
    memcpy(b, r->buf + r->pos, n);
    r->pos += n;
    if ((r->format == PLY_BINARY_LE) != host_is_little_endian())
        for (size_t i = 0; i < n / 2; i++) {
            unsigned char tmp = b[i];
            b[i] = b[n - 1 - i];
            b[n - 1 - i] = tmp;
        }
    switch (t) {
    case ST_INT8: { int8_t v; memcpy(&v, b, 1); *out = v; break; }
    case ST_UINT8: { uint8_t v; memcpy(&v, b, 1); *out = v; break; }
    case ST_INT16: { int16_t v; memcpy(&v, b, 2); *out = v; break; }
    case ST_UINT16: { uint16_t v; memcpy(&v, b, 2); *out = v; break; }
    case ST_INT32: { int32_t v; memcpy(&v, b, 4); *out = v; break; }
    case ST_UINT32: { uint32_t v; memcpy(&v, b, 4); *out = v; break; }
    case ST_FLOAT32: { float v; memcpy(&v, b, 4); *out = v; break; }
    case ST_FLOAT64: { double v; memcpy(&v, b, 8); *out = v; break; }
    }
    return isfinite(*out) ? 0 : -1;
}

static void assign_roles(ply_element *el, int *has_normals, int *has_uv, int is_vertex)
{
    static const struct {
        const char *name;
        prop_role role;
    } vertex_names[] = {
        {"x", ROLE_X},         {"y", ROLE_Y},         {"z", ROLE_Z},         {"nx", ROLE_NX},
        {"ny", ROLE_NY},       {"nz", ROLE_NZ},       {"u", ROLE_U},         {"v", ROLE_V},
        {"s", ROLE_U},         {"t", ROLE_V},         {"texture_u", ROLE_U}, {"texture_v", ROLE_V},
        {"texture_s", ROLE_U}, {"texture_t", ROLE_V},
    };
    unsigned seen = 0;
    for (size_t i = 0; i < el->n_props; i++) {
        ply_property *p = &el->props[i];
        p->role = ROLE_SKIP;
        if (is_vertex && !p->is_list) {
            for (size_t k = 0; k < sizeof vertex_names / sizeof vertex_names[0]; k++)
                if (strcmp(p->name, vertex_names[k].name) == 0 && !(seen & (1u << vertex_names[k].role))) {
                    p->role = vertex_names[k].role; /* the first alias present wins */
                    seen |= 1u << p->role;
                    break;
                }
        } else if (!is_vertex && p->is_list &&
                   (strcmp(p->name, "vertex_indices") == 0 || strcmp(p->name, "vertex_index") == 0) &&
                   !(seen & (1u << ROLE_INDICES))) {
            p->role = ROLE_INDICES;
            seen |= 1u << ROLE_INDICES;
        }
    }
    if (is_vertex) {
        unsigned n = (1u << ROLE_NX) | (1u << ROLE_NY) | (1u << ROLE_NZ), uv = (1u << ROLE_U) | (1u << ROLE_V);
        *has_normals = (seen & n) == n;
        *has_uv = (seen & uv) == uv;
        /* A partial set (nx without nz, u without v) is ignored. */
        for (size_t i = 0; i < el->n_props; i++) {
            prop_role r = el->props[i].role;
            if ((!*has_normals && r >= ROLE_NX && r <= ROLE_NZ) || (!*has_uv && (r == ROLE_U || r == ROLE_V)))
                el->props[i].role = ROLE_SKIP;
        }
    }
}

static int has_xyz(const ply_element *el)
{
    unsigned seen = 0;
    for (size_t i = 0; i < el->n_props; i++)
        if (el->props[i].role >= ROLE_X && el->props[i].role <= ROLE_Z)
            seen |= 1u << el->props[i].role;
    return seen == ((1u << ROLE_X) | (1u << ROLE_Y) | (1u << ROLE_Z));
}

typedef struct tri_buf {
    int *idx;
    size_t n, cap; /* in triangles */
} tri_buf;

static int push_tri(tri_buf *t, int a, int b, int c)
{
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 1024;
        int *p = realloc(t->idx, cap * 3 * sizeof *p);
        if (!p)
            return -1;
        t->idx = p;
        t->cap = cap;
    }
    t->idx[3 * t->n] = a;
    t->idx[3 * t->n + 1] = b;
    t->idx[3 * t->n + 2] = c;
    t->n++;
    return 0;
}

/* The vertex and face elements, their properties given roles; every other
 * element is read past. */
static void find_elements(ply_element *els, size_t n_els, ply_element **vertex, ply_element **face, int *has_normals,
                          int *has_uv)
{
    *vertex = *face = NULL;
    *has_normals = *has_uv = 0;
    for (size_t i = 0; i < n_els; i++) {
        if (!*vertex && strcmp(els[i].name, "vertex") == 0) {
            *vertex = &els[i];
            assign_roles(*vertex, has_normals, has_uv, 1);
        } else if (!*face && strcmp(els[i].name, "face") == 0) {
            *face = &els[i];
            assign_roles(*face, NULL, NULL, 0);
        } else {
            for (size_t k = 0; k < els[i].n_props; k++)
                els[i].props[k].role = ROLE_SKIP;
        }
    }
}

/* A mesh needs positions and faces; counts must fit the file. */
static int check_elements(const char *path, size_t len, const ply_element *vertex, const ply_element *face,
                          lf_error *err)
{
    int face_has_indices = 0;
    if (face)
        for (size_t k = 0; k < face->n_props; k++)
            face_has_indices |= face->props[k].role == ROLE_INDICES;
    if (!vertex || !has_xyz(vertex))
        return lf_error_set(err, LF_ERR_PARSE, "%s: no \"vertex\" element with x, y and z properties", path);
    if (!face || !face_has_indices)
        return lf_error_set(err, LF_ERR_PARSE, "%s: no \"face\" element with a vertex_indices list", path);
    if (vertex->count > (size_t)INT32_MAX)
        return lf_error_set(err, LF_ERR_PARSE, "%s: too many vertices (%zu)", path, vertex->count);
    if (vertex->count > len) /* every vertex takes at least one byte: a corrupt count */
        return lf_error_set(err, LF_ERR_PARSE, "%s: vertex count %zu exceeds the file size", path, vertex->count);
    return 0;
}

/* One scalar property of element item, stored by its role. */
static int read_scalar_property(ply_reader *r, const ply_property *p, const ply_element *el, size_t item,
                                lf_ply_mesh *out)
{
    double v;
    int got = read_scalar(r, p->type, &v);
    if (got) {
        char what[160];
        snprintf(what, sizeof what, "\"%s\" of %s %zu", p->name, el->name, item);
        return ply_fail(r, 0, got == END_OF_DATA ? "unexpected end of data reading " : "bad value for ", what);
    }
    float f = (float)v;
    switch (p->role) {
    case ROLE_X: out->P[3 * item] = f; break;
    case ROLE_Y: out->P[3 * item + 1] = f; break;
    case ROLE_Z: out->P[3 * item + 2] = f; break;
    case ROLE_NX: out->N[3 * item] = f; break;
    case ROLE_NY: out->N[3 * item + 1] = f; break;
    case ROLE_NZ: out->N[3 * item + 2] = f; break;
    case ROLE_U: out->uv[2 * item] = f; break;
    case ROLE_V: out->uv[2 * item + 1] = f; break;
    default: break;
    }
    return 0;
}

/* A polygon's vertex indices, kept between faces. */
typedef struct poly_buf {
    int *idx;
    size_t cap;
} poly_buf;

/* One list property of element item: a face's vertex indices become a
 * triangle fan; other lists are read past. */
static int read_list_property(ply_reader *r, const ply_property *p, const ply_element *el, size_t item, size_t nv,
                              poly_buf *poly, tri_buf *tris)
{
    char what[160];
    double cnt, v;
    int got = read_scalar(r, p->count_type, &cnt);
    if (got || cnt < 0 || cnt > 1e6) {
        snprintf(what, sizeof what, "list \"%s\" of %s %zu", p->name, el->name, item);
        return ply_fail(r, 0, got == END_OF_DATA ? "unexpected end of data reading " : "bad list count in ", what);
    }
    size_t n = (size_t)cnt;
    if (p->role == ROLE_INDICES && n > poly->cap) {
        int *np = realloc(poly->idx, n * sizeof *np);
        if (!np)
            return lf_error_set(r->err, LF_ERR_NOMEM, "%s: out of memory", r->path);
        poly->idx = np;
        poly->cap = n;
    }
    for (size_t k = 0; k < n; k++) {
        if ((got = read_scalar(r, p->type, &v))) {
            snprintf(what, sizeof what, "list \"%s\" of %s %zu", p->name, el->name, item);
            return ply_fail(r, 0, got == END_OF_DATA ? "unexpected end of data reading " : "bad value in ", what);
        }
        if (p->role != ROLE_INDICES)
            continue;
        if (v < 0 || v >= (double)nv) {
            snprintf(what, sizeof what, "%.0f in face %zu (%zu vertices)", v, item, nv);
            return ply_fail(r, 0, "vertex index out of range: ", what);
        }
        poly->idx[k] = (int)v;
    }
    if (p->role != ROLE_INDICES)
        return 0;
    /* Fan from vertex 0: a quad gives (0,1,2) (0,2,3), as pbrt. */
    for (size_t k = 1; k + 1 < n; k++)
        if (push_tri(tris, poly->idx[0], poly->idx[k], poly->idx[k + 1]))
            return lf_error_set(r->err, LF_ERR_NOMEM, "%s: out of memory", r->path);
    return 0;
}

/* The data section: every element's items in order. */
static int read_data(ply_reader *r, ply_element *els, size_t n_els, size_t nv, lf_ply_mesh *out, tri_buf *tris)
{
    if (r->format == PLY_ASCII)
        r->line++; /* data starts on the line after end_header */
    poly_buf poly = {0};
    int rc = 0;
    for (size_t ei = 0; ei < n_els && !rc; ei++) {
        ply_element *el = &els[ei];
        for (size_t item = 0; item < el->count && !rc; item++)
            for (size_t pi = 0; pi < el->n_props && !rc; pi++) {
                const ply_property *p = &el->props[pi];
                rc = p->is_list ? read_list_property(r, p, el, item, nv, &poly, tris)
                                : read_scalar_property(r, p, el, item, out);
            }
    }
    free(poly.idx);
    return rc;
}

/* The most and the fewest bytes one row of el can take in the file. */
static void row_bytes(const ply_element *el, ply_format fmt, double *most, double *fewest)
{
    enum { ASCII_MOST = 64 }; /* a number and its separator; %.17g takes 25 */
    *most = *fewest = 0;
    for (size_t k = 0; k < el->n_props; k++) {
        const ply_property *p = &el->props[k];
        double item = fmt == PLY_ASCII ? ASCII_MOST : (double)scalar_size[p->type];
        if (!p->is_list) {
            *most += item, *fewest += fmt == PLY_ASCII ? 2 : item;
            continue;
        }
        double count_bytes = fmt == PLY_ASCII ? 2 : (double)scalar_size[p->count_type];
        double max_count = ldexp(1.0, 8 * (int)scalar_size[p->count_type]) - 1;
        *most += (fmt == PLY_ASCII ? ASCII_MOST : count_bytes) + max_count * item;
        *fewest += count_bytes;
    }
}

/* For a gzipped PLY, *max_bytes becomes what its header says the file can
 * hold (plus the compressed size), read before anything else is inflated
 * (issue 32: a 23 MB .ply.gz was inflated to the 4 GiB cap before it was
 * refused).  A header that
 * declares more than the cap is refused at once. */
static int gz_bound(const char *path, size_t *max_bytes, lf_error *err)
{
    char *head;
    size_t n;
    int gz;
    lf_error ferr = {0};
    if (lf_file_read_head(path, 1 << 20, &head, &n, &gz, &ferr))
        return lf_error_set(err, ferr.code, "PLY file %s", ferr.msg);
    ply_element *els = NULL;
    size_t n_els = 0;
    ply_reader r = {path, head, n, 0, 0, PLY_ASCII, err};
    lf_error herr = {0};
    r.err = &herr;
    int rc = gz ? parse_header(&r, &els, &n_els) : LF_OK;
    if (rc && n < (size_t)1 << 20) {
        /* the whole stream is shorter than the window, or it is corrupt:
         * the full read says which (and costs no more than this) */
        free_elements(els, n_els);
        free(head);
        return LF_OK;
    }
    if (rc)
        rc = lf_error_set(err, LF_ERR_PARSE, "%s: no PLY header in the first MiB of the decompressed data", path);
    double most = (double)r.pos, fewest = (double)r.pos;
    for (size_t i = 0; i < n_els; i++) {
        double hi, lo;
        row_bytes(&els[i], r.format, &hi, &lo);
        most += (double)els[i].count * hi, fewest += (double)els[i].count * lo;
    }
    if (!rc && gz && fewest > (double)*max_bytes)
        rc = lf_error_set(err, LF_ERR_PARSE, "%s: its header declares at least %.0f bytes of data, more than the "
                                             "%zu-byte limit (refused before decompressing)", path, fewest, *max_bytes);
    /* the compressed bytes are held to the same limit as the inflated ones
     * (lf_file_read): a tiny incompressible file is a few bytes larger */
    struct stat st;
    if (!rc && gz && stat(path, &st) == 0)
        most += (double)st.st_size + 1024;
    if (!rc && gz && most < (double)*max_bytes)
        *max_bytes = (size_t)most;
    free_elements(els, n_els);
    free(head);
    return rc;
}

int lf_ply_read(const char *path, lf_ply_mesh *out, lf_error *err)
{
    memset(out, 0, sizeof *out);
    char *buf;
    size_t len;
    /* A gzipped PLY (".ply.gz", or any name: the magic bytes decide) is
     * decompressed whole first. */
    lf_error ferr = {0};
    size_t max_bytes = LF_FILE_MAX_DEFAULT;
    if (gz_bound(path, &max_bytes, err))
        return err->code;
    if (lf_file_read(path, max_bytes, &buf, &len, NULL, &ferr))
        return lf_error_set(err, ferr.code, "PLY file %s%s", ferr.msg,
                            max_bytes < LF_FILE_MAX_DEFAULT ? " (more than its header declares)" : "");
    ply_reader r = {path, buf, len, 0, 0, PLY_ASCII, err};
    ply_element *els = NULL;
    size_t n_els = 0;
    int rc = parse_header(&r, &els, &n_els);
    if (rc) {
        free(buf);
        return rc;
    }
    ply_element *vertex, *face;
    int has_normals, has_uv;
    find_elements(els, n_els, &vertex, &face, &has_normals, &has_uv);
    tri_buf tris = {0};
    rc = check_elements(path, len, vertex, face, err);
    if (!rc) {
        size_t nv = vertex->count;
        out->n_vertices = nv;
        out->P = malloc((nv ? nv : 1) * 3 * sizeof *out->P);
        out->N = has_normals ? malloc((nv ? nv : 1) * 3 * sizeof *out->N) : NULL;
        out->uv = has_uv ? malloc((nv ? nv : 1) * 2 * sizeof *out->uv) : NULL;
        if (!out->P || (has_normals && !out->N) || (has_uv && !out->uv))
            rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory for %zu vertices", path, nv);
        else
            rc = read_data(&r, els, n_els, nv, out, &tris);
    }
    free_elements(els, n_els);
    free(buf);
    if (rc) {
        free(tris.idx);
        lf_ply_free(out);
        return rc;
    }
    out->indices = tris.idx;
    out->n_triangles = tris.n;
    return LF_OK;
}

void lf_ply_free(lf_ply_mesh *m)
{
    if (!m)
        return;
    free(m->P);
    free(m->N);
    free(m->uv);
    free(m->indices);
    memset(m, 0, sizeof *m);
}
