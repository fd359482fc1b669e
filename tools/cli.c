/* The shared front of every tool (cli.h). */
#include "cli.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/lf_progress.h"

int lf_cli_usage_error(const char *tool, const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "%s%s%s: ", tool, cmd ? " " : "", cmd ? cmd : "");
    vfprintf(stderr, fmt, ap);
    va_end(ap); /* then one line saying where help is, as git and cargo do: the error stays on screen */
    fprintf(stderr, "\nRun `%s%s%s --help` for usage.\n", tool, cmd ? " " : "", cmd ? cmd : "");
    return LF_EXIT_USAGE;
}

static int print_usage(FILE *f, const lf_tool *tool, const lf_command *cmd, int rc)
{
    char *u = lf_args_usage(tool, cmd);
    fputs(u ? u : "out of memory\n", f);
    free(u);
    return u ? rc : LF_EXIT_FAIL;
}

/* The man page: through man(1) on a terminal (as `git help` does), raw roff otherwise. */
static int print_man(const lf_tool *tool)
{
    char *m = lf_args_man(tool, getenv("LF_MAN_DATE"));
    FILE *man = m && isatty(1) ? popen("man -l - 2>/dev/null", "w") : NULL;
    int shown = man && fputs(m, man) >= 0 && pclose(man) == 0; /* else (no man(1)): the roff text */
    fputs(m && !shown ? m : "", stdout);
    free(m);
    return m ? LF_EXIT_OK : LF_EXIT_FAIL;
}

int lf_cli_main(const lf_tool *tool, void *opts, int argc, char **argv)
{
    const lf_command *fallback = lf_args_find(tool, NULL); /* the command run without a name */
    int named = tool->n_commands > (fallback ? 1 : 0);
    if (argc >= 2 && !strcmp(argv[1], "--version")) {
        printf("%s %s\n", tool->name, tool->version);
        return LF_EXIT_OK;
    }
    if (argc >= 2 && !strcmp(argv[1], "--man"))
        return print_man(tool);
    const lf_command *cmd = argc >= 2 && named ? lf_args_find(tool, argv[1]) : NULL;
    int first = cmd ? 2 : 1;
    if (!cmd && argc >= 2 && named && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")))
        return print_usage(stdout, tool, NULL, LF_EXIT_OK);
    if (!cmd)
        cmd = fallback;
    if (!cmd && argc < 2) {
        fprintf(stderr, "%s: no command given\n", tool->name);
        return print_usage(stderr, tool, NULL, LF_EXIT_USAGE);
    }
    lf_error err = {0};
    if (!cmd)
        return lf_cli_usage_error(tool->name, NULL, "%s", lf_args_unknown_command(tool, argv[1], &err));
    char **pos = calloc((size_t)argc + 1, sizeof *pos);
    if (!pos) {
        fprintf(stderr, "%s: out of memory\n", tool->name);
        return LF_EXIT_FAIL;
    }
    int n_pos = 0, rc = LF_EXIT_OK;
    lf_args_status st = lf_args_parse(tool, cmd, argc, argv, first, pos, &n_pos, &err);
    if (st == LF_ARGS_HELP)
        rc = print_usage(stdout, tool, cmd, LF_EXIT_OK);
    else if (st == LF_ARGS_VERSION)
        printf("%s %s\n", tool->name, tool->version);
    else
        rc = st == LF_ARGS_ERROR ? lf_cli_usage_error(tool->name, cmd->name, "%s", err.msg)
             : st == LF_ARGS_MAN ? print_man(tool) : cmd->run(opts, n_pos, pos);
    free(pos);
    return rc;
}

void lf_cli_progress(void *progress, long done, long total)
{
    char line[160];
    if (lf_progress_line(progress, done, total, line, sizeof line))
        fputs(line, stderr), fflush(stderr);
}

static volatile sig_atomic_t stop_requested; /* a signal handler's only way out */
static void on_stop_signal(int sig)
{
    stop_requested = sig; /* non-zero: stop */
}

volatile sig_atomic_t *lf_cli_stop_on_signals(void)
{
    struct sigaction sa = {0};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    return &stop_requested;
}
