/* The shared front of every tool (cli.h). */
#include "cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void print_usage(FILE *f, const lf_tool *tool, const lf_command *cmd)
{
    char *u = lf_args_usage(tool, cmd);
    fputs(u ? u : "out of memory\n", f);
    free(u);
}

int lf_cli_main(const lf_tool *tool, void *opts, int argc, char **argv)
{
    const lf_command *fallback = lf_args_find(tool, NULL); /* the command run without a name */
    int named = tool->n_commands > (fallback ? 1 : 0);
    if (argc >= 2 && !strcmp(argv[1], "--version")) {
        printf("%s %s\n", tool->name, tool->version);
        return LF_EXIT_OK;
    }
    if (argc >= 2 && !strcmp(argv[1], "--man")) {
        char *m = lf_args_man(tool, getenv("LF_MAN_DATE"));
        fputs(m ? m : "", stdout);
        free(m);
        return m ? LF_EXIT_OK : LF_EXIT_FAIL;
    }
    const lf_command *cmd = argc >= 2 && named ? lf_args_find(tool, argv[1]) : NULL;
    int first = cmd ? 2 : 1;
    if (!cmd && argc >= 2 && named && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help"))) {
        print_usage(stdout, tool, NULL);
        return LF_EXIT_OK;
    }
    if (!cmd)
        cmd = fallback;
    if (!cmd) {
        if (argc < 2)
            fprintf(stderr, "%s: no command given\n", tool->name);
        else
            fprintf(stderr, "%s: unknown command \"%s\"\n", tool->name, argv[1]);
        print_usage(stderr, tool, NULL);
        return LF_EXIT_USAGE;
    }
    char **pos = calloc((size_t)argc + 1, sizeof *pos);
    if (!pos) {
        fprintf(stderr, "%s: out of memory\n", tool->name);
        return LF_EXIT_FAIL;
    }
    int n_pos = 0;
    lf_error err = {0};
    lf_args_status st = lf_args_parse(tool, cmd, argc, argv, first, pos, &n_pos, &err);
    int rc;
    switch (st) {
    case LF_ARGS_HELP:
        print_usage(stdout, tool, cmd);
        rc = LF_EXIT_OK;
        break;
    case LF_ARGS_VERSION:
        printf("%s %s\n", tool->name, tool->version);
        rc = LF_EXIT_OK;
        break;
    case LF_ARGS_ERROR:
        fprintf(stderr, "%s%s%s: %s\n", tool->name, cmd->name ? " " : "", cmd->name ? cmd->name : "", err.msg);
        print_usage(stderr, tool, cmd);
        rc = LF_EXIT_USAGE;
        break;
    default:
        rc = cmd->run(opts, n_pos, pos);
        break;
    }
    free(pos);
    return rc;
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
