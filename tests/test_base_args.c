/* test_base_args.c - the table-driven flag parser (base/lf_args.h): types,
 * ranges, foreign flags, help/version, usage and man text. */
#include <string.h>
#include <stdlib.h>

#include "base/lf_args.h"
#include "base/lf_buf.h"
#include "base/lf_suggest.h"
#include "lf_test.h"

static struct {
    double depth, pos[3];
    int steps, verbose, views[4];
    const char *out, *tonemap, *inputs[3];
    int n_inputs, depth_given;
} o;

static const lf_arg refocus_args[] = {
    {"--depth", NULL, LF_ARG_DOUBLE, &o.depth, "M", "focus depth", .min = 0, .flags = LF_ARG_MIN_OPEN | LF_ARG_INF_OK,
     .given = &o.depth_given},
    {"--steps", NULL, LF_ARG_INT, &o.steps, "N", "slices", .min = 1, .max = 4096, .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX},
    {"--views", NULL, LF_ARG_INT, o.views, "N", "view window", .min = 0, .max = 1000,
     .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX, .count = 4},
    {"--output", "-o", LF_ARG_STRING, &o.out, "OUT", "output image", .flags = LF_ARG_REQUIRED},
    {"--tonemap", NULL, LF_ARG_CHOICE, &o.tonemap, NULL, "tone curve", .choices = "clamp|filmic|aces"},
    {"--verbose", "-v", LF_ARG_FLAG, &o.verbose, NULL, "say more"},
    {"--input", NULL, LF_ARG_LIST, o.inputs, "FILE", "an input", .count = 3, .count_out = &o.n_inputs},
};
static const lf_arg synth_args[] = {
    {"--camerapos", NULL, LF_ARG_DOUBLE, o.pos, "X", "camera position", .count = 3},
};
static int run_nothing(void *opts, int n, char **p)
{
    (void)opts;
    (void)n;
    (void)p;
    return 0;
}
static const lf_command cmds[] = {
    {"refocus", "IN -o OUT [options]", "refocus a light field", refocus_args, LF_ARRAY_LEN(refocus_args), 1, 1,
     run_nothing, NULL},
    {"synth", "IN OUT [options]", "a virtual camera", synth_args, LF_ARRAY_LEN(synth_args), 2, 2, run_nothing, NULL},
};
static const lf_tool tool = {"lftool", "light-field tool", "9.8", cmds, LF_ARRAY_LEN(cmds), NULL};

static char err[1024]; /* the last parse's message */
static char *pos[32];
static int npos;

static lf_args_status parse(const char *cmd, int argc, const char **words)
{
    char *argv[32];
    argv[0] = (char *)"lftool";
    argv[1] = (char *)cmd;
    for (int i = 0; i < argc; i++)
        argv[i + 2] = (char *)words[i];
    memset(&o, 0, sizeof o);
    lf_error e = {0};
    e.code = LF_ERR_IO; /* a stale error is cleared */
    lf_args_status st = lf_args_parse(&tool, lf_args_find(&tool, cmd), argc + 2, argv, 2, pos, &npos, &e);
    snprintf(err, sizeof err, "%s", e.msg);
    CHECK((st == LF_ARGS_ERROR) == (e.code == LF_ERR_PARAM) && (st == LF_ARGS_ERROR || e.code == LF_OK));
    return st;
}

#define ARGS(...) (int)(sizeof((const char *[]){__VA_ARGS__}) / sizeof(const char *)), (const char *[]){__VA_ARGS__}

int main(void)
{
    /* a complete, valid line */
    CHECK(parse("refocus", ARGS("in.exr", "-o", "x.png", "--depth", "1.5", "--steps", "64", "--tonemap", "aces", "-v",
                                "--views", "0", "1", "2", "3", "--input", "a", "--input=b")) == LF_ARGS_OK);
    CHECK_NEAR(o.depth, 1.5, 0);
    CHECK(o.steps == 64 && o.verbose == 1 && o.depth_given == 1);
    CHECK(o.views[0] == 0 && o.views[3] == 3);
    CHECK(!strcmp(o.out, "x.png") && !strcmp(o.tonemap, "aces"));
    CHECK(npos == 1 && !strcmp(pos[0], "in.exr"));
    CHECK(o.n_inputs == 2 && !strcmp(o.inputs[1], "b"));
    /* --name=value and inf where allowed */
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--depth=inf")) == LF_ARGS_OK && o.depth > 1e300);
    CHECK(o.depth_given == 1);
    CHECK(parse("refocus", ARGS("in", "-o", "x")) == LF_ARGS_OK && o.depth_given == 0);

    /* ranges and integers: no undefined casts */
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--steps", "1e12")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "--steps wants an integer from 1 to 4096") != NULL, "%s", err);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--views", "1e10", "0", "0", "0")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--steps", "99999999999999999999")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--steps", "0")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--steps", "4096")) == LF_ARGS_OK);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--depth", "0")) == LF_ARGS_ERROR); /* open lower bound */
    CHECK_MSG(strstr(err, "> 0") != NULL, "%s", err);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--depth", "nan")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--depth", "2m")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--views", "1", "2")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "takes 4 values") != NULL, "%s", err);
    CHECK(parse("synth", ARGS("a", "b", "--camerapos", "inf", "0", "0")) == LF_ARGS_ERROR); /* inf not allowed here */
    CHECK(parse("synth", ARGS("a", "b", "--camerapos", "-0.5", "1e-3", "2")) == LF_ARGS_OK);
    CHECK_NEAR(o.pos[0], -0.5, 0);
    CHECK_NEAR(o.pos[1], 1e-3, 0);

    /* choices, required flags, positionals */
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--tonemap", "reinhard")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "clamp|filmic|aces") != NULL, "%s", err);
    CHECK(parse("refocus", ARGS("in")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "--output is required") != NULL, "%s", err);
    CHECK(parse("refocus", ARGS("-o", "x")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("a", "b", "-o", "x")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--verbose=1")) == LF_ARGS_ERROR);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--input", "1", "--input", "2", "--input", "3", "--input", "4")) ==
          LF_ARGS_ERROR);
    /* a negative number and "-" are positional; "--" ends the flags */
    CHECK(parse("synth", ARGS("-1.5", "-")) == LF_ARGS_OK && npos == 2);
    CHECK(parse("synth", ARGS("--", "--camerapos", "b")) == LF_ARGS_OK && npos == 2);

    /* unknown and foreign flags */
    CHECK(parse("synth", ARGS("a", "b", "--depth", "2")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "--depth is a flag of `lftool refocus`, not of `lftool synth`") != NULL, "%s", err);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--lensradius", "0.01")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "unknown flag --lensradius") != NULL, "%s", err);

    /* did you mean: the nearest flag of the command (base/lf_suggest.h) */
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--dpth", "1")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "unknown flag --dpth (did you mean --depth?)") != NULL, "%s", err);
    CHECK(parse("refocus", ARGS("in", "-o", "x", "--stpes=3")) == LF_ARGS_ERROR); /* swapped neighbours */
    CHECK_MSG(strstr(err, "unknown flag --stpes (did you mean --steps?)") != NULL, "%s", err);
    CHECK(parse("refocus", ARGS("-o", "x")) == LF_ARGS_ERROR);
    CHECK_MSG(strstr(err, "missing argument (usage: lftool refocus IN -o OUT [options])") != NULL, "%s", err);
    /* the distance: optimal string alignment, case-insensitive (textbook values) */
    CHECK(lf_suggest_distance("kitten", "sitting") == 3);
    CHECK(lf_suggest_distance("ca", "abc") == 3); /* OSA, not unrestricted Damerau (2) */
    CHECK(lf_suggest_distance("fvo", "fov") == 1 && lf_suggest_distance("WORLDbegin", "WorldBegin") == 0);
    CHECK(lf_suggest_distance("", "abc") == 3);
    /* the limit: one edit per three characters typed, at least one */
    const char *const names[] = {"fov", "lensradius", "focaldistance", "screenwindow", NULL};
    CHECK(lf_suggest_among("fvo", names) && !strcmp(lf_suggest_among("fvo", names), "fov"));
    CHECK(lf_suggest_among("lnsradus", names) && !strcmp(lf_suggest_among("lnsradus", names), "lensradius"));
    CHECK(lf_suggest_among("xyz", names) == NULL);      /* 3 edits from fov: limit 1 */
    CHECK(lf_suggest_among("fo", names) != NULL);        /* 1 edit, limit 1 */
    CHECK(lf_suggest_among("fov", names) == NULL);       /* the word itself is not a suggestion */
    CHECK(lf_suggest_among("focal", names) == NULL);     /* 8 edits from focaldistance */

    /* help, version and man win wherever they stand */
    CHECK(parse("refocus", ARGS("in", "--man")) == LF_ARGS_MAN);
    CHECK(parse("refocus", ARGS("--help")) == LF_ARGS_HELP);
    CHECK(parse("refocus", ARGS("in", "-h")) == LF_ARGS_HELP);
    CHECK(parse("synth", ARGS("--version")) == LF_ARGS_VERSION);

    /* usage and man page come from the same table */
    char *u = lf_args_usage(&tool, lf_args_find(&tool, "refocus"));
    CHECK(u && strstr(u, "usage: lftool refocus IN -o OUT [options]"));
    CHECK(u && strstr(u, "-o, --output OUT") && strstr(u, "--views N N N N"));
    CHECK(u && strstr(u, "an integer from 1 to 4096"));
    CHECK(u && strstr(u, "--help") && strstr(u, "--man") && !strstr(u, "--camerapos"));
    free(u);
    u = lf_args_usage(&tool, NULL);
    CHECK(u && strstr(u, "refocus") && strstr(u, "synth") && strstr(u, "lftool COMMAND --help") &&
          strstr(u, "lftool --man"));
    free(u);
    char *m = lf_args_man(&tool, "2026-01-01");
    CHECK(m && !strncmp(m, ".TH lftool 1 \"2026-01-01\" \"lensfield 9.8\"", 41));
    CHECK(m && strstr(m, ".SS refocus") && strstr(m, "\\-\\-camerapos"));
    free(m);

    /* the string buffer and arrays */
    lf_strbuf b = {0};
    for (int i = 0; i < 1000; i++)
        lf_strbuf_printf(&b, "%04d", i);
    CHECK(b.len == 4000 && !b.failed && !strncmp(b.s + 3996, "0999", 4));
    char *t = lf_strbuf_take(&b);
    CHECK(t && strlen(t) == 4000 && b.s == NULL);
    free(t);
    double *arr = NULL;
    size_t cap = 0;
    CHECK(lf_array_reserve((void **)&arr, &cap, 100, sizeof *arr) == 0 && cap >= 100);
    CHECK(lf_array_reserve((void **)&arr, &cap, (size_t)-1 / 4, sizeof *arr) == -1 && cap >= 100);
    free(arr);
    return lf_test_end();
}
