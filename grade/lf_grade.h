/* lf_grade.h - automatic grading of course assignments (lfgrade).
 *
 *   lf_grade_opts o = lf_grade_opts_default();      // cache dir, threads, report dir
 *   lf_grade_ctx *g;
 *   if (lf_grade_ctx_new("assignments/1-thinlens", &o, &g, &err)) ...  // reads rubric.txt
 *   lf_grade_result r;
 *   lf_grade_submission(g, "submissions/alice", &r, &err);  // 0: grading ran
 *   ... r.score, r.max, r.checks[i].reason ...
 *   lf_grade_write_gradebook("report", &r, 1, &err);        // gradebook.csv + .json
 *   lf_grade_result_free(&r); lf_grade_ctx_release(g);
 *
 * A submission is DATA: images are copied out of regular files inside the
 * submission folder (symbolic links only when they resolve inside it), with
 * size and header limits checked before decoding; Submission.md's commands
 * are tokenised and their flags re-implemented (lftool synth / refocus),
 * never run.  References are rendered in-process from the assignment's
 * scenes with fixed seeds and cached on disk.  The rubric format and the
 * metrics are documented in docs/grading.md.
 */
#ifndef LF_GRADE_H
#define LF_GRADE_H

#include <stdint.h>

#include "base/lf_error.h"
#include "image/lf_image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lf_grade_opts {
    const char *cache_dir;  /* NULL: $XDG_CACHE_HOME/lensfield or ~/.cache/lensfield */
    const char *report_dir; /* NULL: no HTML reports; else REPORT/<student>/index.html */
    int threads;            /* render threads; 0: all cores */
} lf_grade_opts;
lf_grade_opts lf_grade_opts_default(void);

typedef enum lf_grade_status { LF_GRADE_PASS, LF_GRADE_FAIL } lf_grade_status;

typedef struct lf_grade_check_result {
    char id[64];
    char kind[32];
    int points, earned;
    lf_grade_status status;
    char reason[1024];     /* empty when passed; why every lost point was lost */
    /* image comparisons (NAN when not compared) */
    double noise_ratio;    /* lf_grade_noise_ratio(submission, ref, ref with another seed) */
    double ssim, ssim_noise; /* SSIM vs the reference, and of the two references */
    double psnr_db;
    char best_variant[64]; /* the known mistake that matches best, if any */
    double variant_ratio;
    /* physical measurements of a failed (or focus-checked) image: blur, brightness,
     * focus, field of view (docs/grading.md, "Measurements"); empty when none */
    char measurements[1024];
} lf_grade_check_result;

typedef struct lf_grade_result {
    char student[128];     /* the submission folder's name */
    char path[1024];
    int score, max;
    int nchecks;
    lf_grade_check_result *checks;
    double seconds;
} lf_grade_result;
void lf_grade_result_free(lf_grade_result *r);

typedef struct lf_grade_ctx lf_grade_ctx;
/* The assignment folder a command line names: NAME itself when it holds
 * rubric.txt, else assignments/NAME under the working directory, else
 * assignments/NAME beside the executable's folder (build/bin/../../), else
 * the installed copy (PREFIX/bin/../share/lensfield/assignments/NAME).
 * LF_ERR_PARAM when none exists. */
int lf_grade_find_assignment(const char *name, char *dir, size_t dir_size, lf_error *err);
/* Loads ASSIGNMENT_DIR/rubric.txt (LF_ERR_PARSE with file:line on errors). */
int lf_grade_ctx_new(const char *assignment_dir, const lf_grade_opts *o, lf_grade_ctx **out, lf_error *err);
void lf_grade_ctx_release(lf_grade_ctx *g);
const char *lf_grade_title(const lf_grade_ctx *g);
int lf_grade_max_points(const lf_grade_ctx *g);

/* Grades one submission folder.  Returns 0 when grading ran (whatever the
 * submission's state: missing, corrupt or hostile files are reasons in
 * *res); non-zero only for grader-side failures (rubric references a scene
 * that does not render, cache unwritable, out of memory). */
int lf_grade_submission(lf_grade_ctx *g, const char *submission_dir, lf_grade_result *res, lf_error *err);

/* REPORT/gradebook.csv and REPORT/gradebook.json for n results. */
int lf_grade_write_gradebook(const char *report_dir, const lf_grade_result *res, int n, lf_error *err);
/* One result as a JSON object (malloc'ed; NULL when memory runs out). */
char *lf_grade_result_json(const lf_grade_result *r);
/* How many of a result's checks failed. */
int lf_grade_failed_checks(const lf_grade_result *r);

/* ---- helpers shared with tests (and useful to build model submissions) ---- */

/* A textual edit of a scene file: the first occurrence of find becomes replace. */
typedef struct lf_grade_edit {
    const char *find, *replace;
} lf_grade_edit;
/* Renders scene_path (after the edits; each must match) at spp with seed. */
int lf_grade_render(const char *scene_path, const lf_grade_edit *edits, int nedits, int spp, uint32_t seed,
                    int threads, lf_image *out, lf_attrs *meta, lf_error *err);
/* Post-processing ops the rubric's variants use (docs/grading.md):
 * "flip_tiles:NX:NY:h|v|hv", "no_cos4:TAN_HALF_HFOV". */
int lf_grade_post(const char *op, lf_image *img, lf_error *err);

/* Metrics.  Trimmed relative MSE: mean of (a - r)^2 / (r^2 + 0.01) over all
 * channels, the largest 0.1% of per-pixel values left out. */
double lf_grade_relmse(const lf_image *a, const lf_image *ref);
/* The decision metric: mean over pixels (largest 0.5% left out) of
 * (x - ref)^2 / local noise variance, the variance estimated from a and b,
 * the reference rendered with two seeds (ref is a, or a variant of it).
 * About 1 for an independent correct render. */
double lf_grade_noise_ratio(const lf_image *x, const lf_image *ref, const lf_image *a, const lf_image *b);
/* SSIM of sRGB-encoded luminance, 7x7 box windows. */
double lf_grade_ssim(const lf_image *a, const lf_image *b);
/* Contrast energy of [x0,x1) x [y0,y1): mean squared neighbour difference of
 * luminance over the squared mean (the focus checks' local sharpness). */
double lf_grade_sharpness(const lf_image *im, int x0, int y0, int x1, int y1);
/* Mean over all pixels and channels. */
double lf_grade_mean(const lf_image *im);
/* Measurements for explaining a wrong image in physical terms:
 * content magnification (> 1: the submission sees a wider field, tan of the
 * half angle times it), extra disc blur in pixels (> 0 blurrier, < 0
 * sharper), and the equivalent diameter of n highlights (bokeh discs). */
double lf_grade_fit_scale(const lf_image *S, const lf_image *A);
double lf_grade_fit_blur(const lf_image *S, const lf_image *A);
double lf_grade_highlight_diameter(const lf_image *im, int x0, int y0, int x1, int y1, int n);

/* Submission.md commands as data: splits a line into words (quotes group,
 * nothing is expanded).  Fails with LF_ERR_PARSE (the reason in err) on
 * shell syntax or an unterminated quote, LF_ERR_NOMEM when memory runs out. */
int lf_grade_tokenize(const char *line, char ***argv, int *argc, lf_error *err);
void lf_grade_free_argv(char **argv, int argc);

#ifdef __cplusplus
}
#endif
#endif
