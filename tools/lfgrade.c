/* lfgrade - grade assignment submissions (docs/grading.md).
 *
 *   lfgrade ASSIGNMENT SUBMISSION... [--report DIR] [--json] [--cache DIR] [--threads N]
 *
 * ASSIGNMENT is a folder with rubric.txt (or a name under assignments/).
 * Exit codes: 0 grading ran (whatever the scores), 1 grader-side error
 * (bad rubric, reference failed to render, report unwritable), 2 usage. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "grade/lf_grade.h"

enum { EXIT_OK = 0, EXIT_GRADER = 1, EXIT_USAGE = 2 };

static int usage(const char *msg)
{
    if (msg)
        fprintf(stderr, "lfgrade: %s\n", msg);
    fprintf(msg ? stderr : stdout,
            "usage: lfgrade ASSIGNMENT SUBMISSION... [--report DIR] [--json] [--cache DIR] [--threads N]\n"
            "  ASSIGNMENT     assignment folder with rubric.txt, or a name under assignments/\n"
            "  SUBMISSION     a student's folder: the requested images (PNG or EXR) and Submission.md\n"
            "  --report DIR   per-student HTML reports DIR/<student>/index.html, DIR/gradebook.csv|json\n"
            "  --json         print each result as JSON on stdout\n"
            "  --cache DIR    reference renders (default ~/.cache/lensfield)\n"
            "  --threads N    render threads (default: all cores)\n"
            "Nothing in a submission is executed; its commands are read as data.\n");
    return msg ? EXIT_USAGE : EXIT_OK;
}

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

/* A folder, else assignments/NAME here, else next to the executable
 * (build/bin/../../assignments). */
static int find_assignment(const char *a, char *out, size_t n)
{
    char rubric[PATH_MAX + 16];
    snprintf(rubric, sizeof rubric, "%s/rubric.txt", a);
    if (is_dir(a) && access(rubric, R_OK) == 0)
        return snprintf(out, n, "%s", a), 0;
    snprintf(out, n, "assignments/%s", a);
    if (is_dir(out))
        return 0;
    char exe[PATH_MAX];
    ssize_t l = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (l > 0) {
        exe[l] = 0;
        char *s = strrchr(exe, '/');
        if (s) {
            *s = 0;
            if (snprintf(out, n, "%s/../../assignments/%s", exe, a) < (int)n && is_dir(out))
                return 0;
        }
    }
    return -1;
}

int main(int argc, char **argv)
{
    const char *assignment = NULL, *report = NULL;
    const char **subs = calloc((size_t)argc, sizeof *subs);
    int nsubs = 0, json = 0;
    lf_grade_opts o = lf_grade_opts_default();
    if (!subs)
        return EXIT_GRADER;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help"))
            return free(subs), usage(NULL);
        else if (!strcmp(a, "--json"))
            json = 1;
        else if (!strcmp(a, "--report") || !strcmp(a, "--cache") || !strcmp(a, "--threads")) {
            if (i + 1 >= argc) {
                free(subs);
                fprintf(stderr, "lfgrade: %s needs a value\n", a);
                return usage("");
            }
            const char *v = argv[++i];
            if (!strcmp(a, "--report"))
                report = v;
            else if (!strcmp(a, "--cache"))
                o.cache_dir = v;
            else {
                char *end;
                long t = strtol(v, &end, 10);
                if (*end || t < 0 || t > 1024) {
                    free(subs);
                    return usage("--threads needs a number 0..1024");
                }
                o.threads = (int)t;
            }
        } else if (a[0] == '-' && a[1]) {
            free(subs);
            fprintf(stderr, "lfgrade: unknown option %s\n", a);
            return usage("");
        } else if (!assignment)
            assignment = a;
        else
            subs[nsubs++] = a;
    }
    if (!assignment || !nsubs) {
        free(subs);
        return usage("need an assignment and at least one submission");
    }
    char adir[PATH_MAX];
    if (find_assignment(assignment, adir, sizeof adir)) {
        fprintf(stderr, "lfgrade: %s: no such assignment (a folder with rubric.txt, or a name under assignments/)\n",
                assignment);
        free(subs);
        return EXIT_USAGE;
    }
    o.report_dir = report;
    lf_error err = {0};
    lf_grade_ctx *g;
    if (lf_grade_ctx_new(adir, &o, &g, &err)) {
        fprintf(stderr, "lfgrade: %s\n", err.msg);
        free(subs);
        return EXIT_GRADER;
    }
    lf_grade_result *res = calloc((size_t)nsubs, sizeof *res);
    int rc = res ? EXIT_OK : EXIT_GRADER, graded = 0;
    for (int i = 0; i < nsubs && res; i++) {
        lf_error e = {0};
        if (lf_grade_submission(g, subs[i], &res[graded], &e)) {
            /* a grader-side failure: say so, keep going with the others */
            fprintf(stderr, "[%d/%d] %s: GRADER ERROR: %s\n", i + 1, nsubs, subs[i], e.msg);
            lf_grade_result_free(&res[graded]);
            rc = EXIT_GRADER;
            continue;
        }
        const lf_grade_result *r = &res[graded++];
        int lost = 0;
        for (int k = 0; k < r->nchecks; k++)
            lost += r->checks[k].status == LF_GRADE_FAIL;
        fprintf(stderr, "[%d/%d] %s: %d/%d (%d check%s failed, %.2f s)\n", i + 1, nsubs, r->student, r->score,
                r->max, lost, lost == 1 ? "" : "s", r->seconds);
        for (int k = 0; k < r->nchecks; k++)
            if (r->checks[k].status == LF_GRADE_FAIL)
                fprintf(stderr, "    %s -%d: %s\n", r->checks[k].id, r->checks[k].points - r->checks[k].earned,
                        r->checks[k].reason);
        if (json) {
            char *j = lf_grade_result_json(r);
            if (j)
                printf("%s\n", j);
            free(j);
        }
    }
    if (report && graded) {
        if (lf_grade_write_gradebook(report, res, graded, &err)) {
            fprintf(stderr, "lfgrade: %s\n", err.msg);
            rc = EXIT_GRADER;
        } else {
            fprintf(stderr, "lfgrade: reports in %s (gradebook.csv, gradebook.json, <student>/index.html)\n", report);
        }
    }
    for (int i = 0; i < graded; i++)
        lf_grade_result_free(&res[i]);
    free(res);
    free(subs);
    lf_grade_ctx_release(g);
    return rc;
}
