/* lf_params.h - typed parameter lists as written in pbrt-v4 scene files.
 *
 *   Shape "sphere" "float radius" [2] "rgb reflectance" [.5 .5 .5]
 *
 * Every lookup marks the parameter as used.  A lookup whose type does not
 * match the declared type (e.g. "integer fov" looked up as float) parks an
 * lf_error in the set (the first one; lf_params_error reads it).  After a
 * consumer has read everything it understands it calls lf_params_finish(),
 * which reports the parked error or the first parameter nobody read, with
 * the file:line:column where it was written, so typos in scene files never
 * pass silently (pbrt-v4 does the same).
 *
 * pbrt type aliases are normalised by the parser: "point" -> point3,
 * "vector" -> vector3, "normal" -> normal3, "color" -> rgb.
 */
#ifndef LF_PARAMS_H
#define LF_PARAMS_H

#include <stddef.h>

#include "lf_error.h"
#include "lf_math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lf_param_type {
    LF_PT_FLOAT,
    LF_PT_INTEGER,
    LF_PT_BOOL,
    LF_PT_STRING,
    LF_PT_POINT2,
    LF_PT_VECTOR2,
    LF_PT_POINT3,
    LF_PT_VECTOR3,
    LF_PT_NORMAL3,
    LF_PT_RGB,
    LF_PT_SPECTRUM,  /* nums: (lambda nm, value) pairs, or strs[0]: named spectrum / file */
    LF_PT_BLACKBODY, /* nums[0]: temperature in kelvin */
    LF_PT_TEXTURE    /* strs[0]: texture name */
} lf_param_type;

typedef struct lf_param {
    lf_param_type type;
    char *name;
    double *nums;
    size_t n_nums;
    char **strs;
    size_t n_strs;
    unsigned char *bools;
    size_t n_bools;
    lf_loc loc;
    int used;
} lf_param;

typedef struct lf_paramset {
    lf_param *items;
    size_t count, cap;
    /* The first error a lookup found (a type mismatch, a wrong value count,
     * a bad colour), an lf_error like any other, carrying the parameter's
     * file:line:col.  Lookups return their default instead of failing, so a
     * directive reads its parameters one after another as pbrt-v4's do; the
     * error is deferred, not lost: lf_params_finish reports it.  Read it
     * with lf_params_error. */
    lf_error error;
    /* The names looked up but absent, each as one type byte (lf_param_type
     * + 1, 0 when the lookup took any type) then the name and a NUL, so
     * lf_params_finish can suggest the nearest for an unused one ("float
     * fvo": did you mean "float fov"?).  Only a hint: if memory runs out a
     * name is not recorded. */
    char *absent;
    size_t absent_len, absent_cap;
} lf_paramset;

/* The error parked by the lookups so far (code LF_OK when none), for a
 * caller that must stop before lf_params_finish (e.g. a shape whose
 * geometry a bad lookup left unread). */
const lf_error *lf_params_error(const lf_paramset *ps);

const char *lf_param_type_name(lf_param_type t);
/* Parses a pbrt type word ("float", "point", "color", ...); -1 if unknown. */
int lf_param_type_from_name(const char *word, lf_param_type *out);

/* Appends a copy-less parameter: the set takes ownership of p's arrays. */
int lf_params_add(lf_paramset *ps, const lf_param *p);
/* Deep copy (used flags are reset). */
int lf_params_copy(lf_paramset *dst, const lf_paramset *src);
/* Adds the parameters of `defaults` that `ps` does not already name
 * (pbrt-v4 `Attribute` defaults). */
int lf_params_merge_defaults(lf_paramset *ps, const lf_paramset *defaults);
void lf_params_free(lf_paramset *ps);

/* Finds a parameter by name regardless of type; marks it used. NULL if absent. */
lf_param *lf_params_find(lf_paramset *ps, const char *name);
/* Finds by name without marking it used. */
const lf_param *lf_params_peek(const lf_paramset *ps, const char *name);

/* Single-value lookups: default when absent; a type mismatch or a wrong
 * value count is parked in the set (lf_params_error) and the default
 * returned. */
double lf_params_float(lf_paramset *ps, const char *name, double def);
int lf_params_int(lf_paramset *ps, const char *name, int def);
int lf_params_bool(lf_paramset *ps, const char *name, int def);
/* Returned pointer is owned by the set. */
const char *lf_params_string(lf_paramset *ps, const char *name, const char *def);
/* Fixed-size lookups (point2/vector2 -> 2, point3/vector3/normal3 -> 3).
 * Returns 1 if found (out filled), 0 if absent. */
int lf_params_point2(lf_paramset *ps, const char *name, double out[2]);
int lf_params_point3(lf_paramset *ps, const char *name, double out[3]);
int lf_params_vector3(lf_paramset *ps, const char *name, double out[3]);
/* Array lookups: pointer to the numbers and their count, NULL if absent.
 * `type` must match the declared type. */
const double *lf_params_nums(lf_paramset *ps, const char *name, lf_param_type type, size_t *count);
const char *const *lf_params_strings(lf_paramset *ps, const char *name, size_t *count);

/* What a spectrum-valued parameter means, which decides how a spectrum or
 * blackbody is turned into RGB (see base/lf_color.h). */
typedef enum lf_spectrum_kind {
    LF_SPECTRUM_ALBEDO,     /* reflectance, clamped to [0,1] */
    LF_SPECTRUM_UNBOUNDED,  /* e.g. conductor eta and k */
    LF_SPECTRUM_ILLUMINANT  /* emission: blackbody normalised to luminance 1 */
} lf_spectrum_kind;

/* Spectrum-valued lookup: accepts rgb, blackbody, spectrum (pairs or named),
 * and a single float (grey).  Returns 1 if found, 0 if absent (out = def). */
int lf_params_rgb(lf_paramset *ps, const char *name, lf_spectrum_kind kind, lf_vec3 def, lf_vec3 *out);

/* Reports the parked lookup error, else the first unused parameter:
 * "file:line:col: unused parameter "float fvo" in Camera "perspective" (did
 * you mean "float fov"?)", the suggestion among the names the directive
 * looked up and did not find (base/lf_suggest.h).
 * `context` names the directive, e.g. "Camera \"perspective\"". */
int lf_params_finish(const lf_paramset *ps, const char *context, lf_error *err);

#ifdef __cplusplus
}
#endif
#endif
