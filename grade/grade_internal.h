/* grade_internal.h - private to grade/: rubric structures, safe reading. */
#ifndef LF_GRADE_INTERNAL_H
#define LF_GRADE_INTERNAL_H

#include <stddef.h>

#include "lf_grade.h"

#define LF_GRADE_MAX_EDITS 8
#define LF_GRADE_MAX_VARIANTS 8
#define LF_GRADE_MAX_FILE (64u << 20)   /* bytes read from any submitted file */
#define LF_GRADE_MAX_MD (256u << 10)    /* Submission.md */
#define LF_GRADE_MAX_DIM 16384          /* image header limits, checked before decoding */
#define LF_GRADE_MAX_PIXELS (1u << 26)

typedef struct lf_grade_variant {
    char name[64];
    char reason[512];
    int nedits;
    char *find[LF_GRADE_MAX_EDITS], *replace[LF_GRADE_MAX_EDITS];
    char post[128];
    char set[256]; /* synth/refocus overrides "key:value[,key:value]" */
    /* a search (docs/grading.md): the with= text holds {v} (or {v*K}), the
     * scene value base x factor, factors searched over [lo, hi] */
    int search;
    double base, lo, hi;
    char measure[256]; /* what the best value means physically ({value}, {base}, {K/value}, {value*K}) */
    /* the variant's exposure over the correct camera's, by construction
     * (0: 1), so a brightness fitted against it reads against the correct one */
    double brightness;
} lf_grade_variant;

typedef struct lf_grade_check {
    char id[64], kind[32];
    int points;
    int line;
    /* key=value parameters */
    int nkv;
    char *key[24], *val[24];
    int nvariants;
    lf_grade_variant variants[LF_GRADE_MAX_VARIANTS];
} lf_grade_check;

typedef struct lf_grade_rubric {
    char assignment[128], title[256];
    int nchecks;
    lf_grade_check *checks;
} lf_grade_rubric;

int lf_grade_rubric_parse(const char *path, lf_grade_rubric *r, lf_error *err);
void lf_grade_rubric_free(lf_grade_rubric *r);
const char *lf_grade_check_get(const lf_grade_check *c, const char *key, const char *def);

/* Reads the plain file name `name` from directory dir: only regular files,
 * symbolic links only when they resolve inside dir, at most max bytes.
 * Returns 0 (data malloc'ed), 1 when the file does not exist, -1 with the
 * reason in why otherwise. */
int lf_grade_read_inside(const char *dir, const char *name, size_t max, unsigned char **data, size_t *n,
                         char *why, size_t why_size);

/* Header of an in-memory PNG or EXR: format ("png"/"exr") and size, without
 * decoding.  -1 with why for unknown formats, truncated or absurd headers. */
int lf_grade_image_header(const unsigned char *data, size_t n, const char **format, int *w, int *h, char *why,
                          size_t why_size);
/* Decodes in-memory bytes (already header-checked) through lf_image_read via
 * a private temporary file. */
int lf_grade_image_decode(const unsigned char *data, size_t n, const char *format, lf_image *img, char *why,
                          size_t why_size);

/* 8-bit sRGB round trip (what a PNG of img holds). */
void lf_grade_quantize8(lf_image *img);
/* Per-pixel error heat map (error / local noise, log scale) for reports. */
int lf_grade_heatmap(const lf_image *x, const lf_image *a, const lf_image *b, lf_image *out);

#endif
