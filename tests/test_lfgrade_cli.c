/* lfgrade as a user runs it: exit codes (0 grading ran, 1 grader error,
 * 2 usage), progress on stderr, per-student HTML reports and the grade
 * book, batch runs that go on past bad submissions. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "lf_test.h"
#include "lf_test_tools.h"

#define LFGRADE LF_BINARY_DIR "/bin/lfgrade"

static char dir[256];
static char out_text[65536];

static int exists(const char *fmt, const char *a)
{
    char p[512];
    struct stat s;
    snprintf(p, sizeof p, fmt, a);
    return stat(p, &s) == 0;
}

int main(void)
{
    lf_test_run_setup(dir, 0, out_text, sizeof out_text);
    snprintf(dir, sizeof dir, "/tmp/lf_lfgrade_XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    CHECK(run("%s --help", LFGRADE) == 0);
    CHECK(strstr(out_text, "usage: lfgrade") != NULL);
    CHECK(run("%s", LFGRADE) == 2);
    CHECK(run("%s 1-thinlens", LFGRADE) == 2);
    CHECK(run("%s no-such-assignment %s", LFGRADE, dir) == 2);
    CHECK(strstr(out_text, "no such assignment") != NULL);
    CHECK(run("%s 1-thinlens %s --bogus", LFGRADE, dir) == 2);
    CHECK(run("%s 1-thinlens %s --threads x", LFGRADE, dir) == 2);

    /* a broken rubric is a grader-side error */
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "mkdir -p %s/badrubric && printf 'check a 1 nosuchkind\\n' > %s/badrubric/rubric.txt",
             dir, dir);
    CHECK(system(cmd) == 0);
    CHECK(run("%s %s/badrubric %s", LFGRADE, dir, dir) == 1);
    CHECK(strstr(out_text, "rubric.txt:1: unknown check kind") != NULL);

    /* batch: an empty folder and a half-done submission;
     * grading runs (exit 0) and reports each */
    snprintf(cmd, sizeof cmd,
             "mkdir -p %s/subs/empty %s/subs/half && printf '## Answers\\nx\\n## Commands\\nlfrender\\n' > "
             "%s/subs/half/Submission.md && %s assignments/1-thinlens/scenes/flatfield.pbrt -o "
             "%s/subs/half/flatfield.png --quiet --seed 5",
             dir, dir, dir, LF_BINARY_DIR "/bin/lfrender", dir);
    CHECK(system(cmd) == 0);
    /* a submission path that does not exist is a mistyped command line: exit 2, one line naming it, nothing
     * graded (issue 33: it was a silent 0/25) */
    CHECK(run("%s 1-thinlens %s/subs/empty %s/subs/missing --cache %s/cache", LFGRADE, dir, dir, dir) == 2);
    CHECK_MSG(strstr(out_text, "lfgrade: no such submission: ") && strstr(out_text, "/subs/missing\n") &&
                  !strstr(out_text, "0/25"), "%s", out_text);
    int batch_rc = run("%s 1-thinlens %s/subs/empty %s/subs/half --report %s/rep --cache %s/cache --json --threads 2",
                       LFGRADE, dir, dir, dir, dir);
    CHECK_MSG(batch_rc == 0, "exit %d:\n%s", batch_rc, out_text);
    CHECK(strstr(out_text, "[1/2] empty: 0/25") != NULL);
    CHECK(strstr(out_text, "[2/2] half: 12/25") != NULL);
    CHECK(strstr(out_text, "\"student\": \"half\"") != NULL);
    CHECK(strstr(out_text, "missing: neither bokeh.png nor bokeh.exr") != NULL);
    CHECK(exists("%s/rep/gradebook.csv", dir));
    CHECK(exists("%s/rep/gradebook.json", dir));
    CHECK(exists("%s/rep/half/index.html", dir));
    CHECK(exists("%s/rep/half/flatfield-diff.png", dir));
    CHECK(exists("%s/rep/half/flatfield-reference.png", dir));
    char path[512];
    snprintf(path, sizeof path, "%s/rep/gradebook.csv", dir);
    FILE *f = fopen(path, "r");
    char csv[8192] = "";
    size_t n = f ? fread(csv, 1, sizeof csv - 1, f) : 0;
    csv[n] = 0;
    if (f)
        fclose(f);
    CHECK(strncmp(csv, "student,score,max,files,handout,bokeh-size,bokeh,flatfield-size,flatfield,reasons\n", 80) == 0);
    CHECK(strstr(csv, "\"half\",12,25") != NULL);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {
    }
    return lf_test_end();
}
