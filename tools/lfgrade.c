/* lfgrade - grade assignment submissions (docs/grading.md).
 *
 *   lfgrade ASSIGNMENT SUBMISSION... [--report DIR] [--json] [--cache DIR] [--threads N]
 *   (the flags are the table at the end; `lfgrade --help`)
 *
 * ASSIGNMENT is a folder with rubric.txt (or a name under assignments/).
 * Exit codes: 0 grading ran (whatever the scores), 1 grader-side error
 * (bad rubric, reference failed to render, report unwritable), 2 usage. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "grade/lf_grade.h"

typedef struct flags {
    const char *report, *cache;
    int json, threads;
} flags;

static int run_grade(void *ctx, int n, char **pos)
{
    const flags *f = ctx;
    const char *assignment = pos[0];
    char **subs = pos + 1;
    int nsubs = n - 1;
    lf_grade_opts o = lf_grade_opts_default();
    if (f->cache)
        o.cache_dir = f->cache;
    o.threads = f->threads;
    char adir[PATH_MAX];
    lf_error err = {0};
    if (lf_grade_find_assignment(assignment, adir, sizeof adir, &err))
        return lf_cli_usage_error("lfgrade", NULL, "%s", err.msg);
    for (int i = 0; i < nsubs; i++) /* a mistyped path is a usage error, not a score of 0 */
        if (access(subs[i], F_OK))
            return lf_cli_usage_error("lfgrade", NULL, "no such submission: %s", subs[i]);
    o.report_dir = f->report;
    lf_grade_ctx *g;
    if (lf_grade_ctx_new(adir, &o, &g, &err)) {
        fprintf(stderr, "lfgrade: %s\n", err.msg);
        return LF_EXIT_FAIL;
    }
    lf_grade_result *res = calloc((size_t)n, sizeof *res); /* n - 1 submissions */
    int rc = res ? LF_EXIT_OK : LF_EXIT_FAIL, graded = 0;
    for (int i = 0; i < nsubs && res; i++) {
        lf_error e = {0};
        if (lf_grade_submission(g, subs[i], &res[graded], &e)) {
            /* a grader-side failure: say so, keep going with the others */
            fprintf(stderr, "[%d/%d] %s: GRADER ERROR: %s\n", i + 1, nsubs, subs[i], e.msg);
            lf_grade_result_free(&res[graded]);
            rc = LF_EXIT_FAIL;
            continue;
        }
        const lf_grade_result *r = &res[graded++];
        int lost = lf_grade_failed_checks(r);
        fprintf(stderr, "[%d/%d] %s: %d/%d (%d check%s failed, %.2f s)\n", i + 1, nsubs, r->student, r->score,
                r->max, lost, lost == 1 ? "" : "s", r->seconds);
        for (int k = 0; k < r->nchecks; k++)
            if (r->checks[k].status == LF_GRADE_FAIL)
                fprintf(stderr, "    %s -%d: %s\n", r->checks[k].id, r->checks[k].points - r->checks[k].earned,
                        r->checks[k].reason);
        char *j = f->json ? lf_grade_result_json(r) : NULL;
        if (j)
            printf("%s\n", j);
        else if (f->json)
            fprintf(stderr, "lfgrade: %s: out of memory for the JSON result\n", r->student);
        free(j);
    }
    if (f->report && graded) {
        if (lf_grade_write_gradebook(f->report, res, graded, &err)) {
            fprintf(stderr, "lfgrade: %s\n", err.msg);
            rc = LF_EXIT_FAIL;
        } else {
            fprintf(stderr, "lfgrade: reports in %s (gradebook.csv, gradebook.json, <student>/index.html)\n",
                    f->report);
        }
    }
    for (int i = 0; i < graded; i++)
        lf_grade_result_free(&res[i]);
    free(res);
    lf_grade_ctx_release(g);
    return rc;
}

int main(int argc, char **argv)
{
    flags f = {0};
    const lf_arg grade_args[] = {
        {"--report", NULL, LF_ARG_STRING, &f.report, "DIR",
         "per-student HTML reports DIR/<student>/index.html, DIR/gradebook.csv|json"},
        {"--json", NULL, LF_ARG_FLAG, &f.json, NULL, "print each result as JSON on stdout"},
        {"--cache", NULL, LF_ARG_STRING, &f.cache, "DIR", "reference renders (default ~/.cache/lensfield)"},
        {"--threads", NULL, LF_ARG_INT, &f.threads, "N", "render threads (default 0: all cores)", .min = 0, .max = 1024,
         .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX},
    };
    const lf_command commands[] = {
        {NULL, "ASSIGNMENT SUBMISSION... [--report DIR] [--json] [--cache DIR] [--threads N]",
         "grade assignment submissions against reference renders", grade_args, LF_ARRAY_LEN(grade_args), 2, -1,
         run_grade,
         "ASSIGNMENT is a folder with rubric.txt, or a name under assignments/; each SUBMISSION is a student's folder "
         "with the requested images (PNG or EXR) and Submission.md. Nothing in a submission is executed; its commands "
         "are read as data."},
    };
    const lf_tool tool = {"lfgrade", "grade course assignments built on lensfield", LF_VERSION, commands,
                          LF_ARRAY_LEN(commands),
                          "Exit status: 0 grading ran (whatever the scores); 1 a grader-side error (bad rubric, "
                          "reference failed to render, report unwritable); 2 bad command line."};
    return lf_cli_main(&tool, &f, argc, argv);
}
