/* cli.h - the one way every lensfield tool runs its command table
 * (base/lf_args.h): picks the subcommand, parses its flags, answers --help,
 * --version and --man, prints usage errors (one line and where help is,
 * exit 2), then calls the
 * command's handler with the tool's options and returns its exit code.
 * The flag tables point into the options, which main() owns: no tool keeps
 * its flags in file-scope state. */
#ifndef LF_TOOLS_CLI_H
#define LF_TOOLS_CLI_H

#include <signal.h>

#include "base/lf_args.h"

#ifndef LF_VERSION
#define LF_VERSION "unknown"
#endif

/* Exit codes, the same in every tool (its --help says what 1 means there). */
enum { LF_EXIT_OK = 0, LF_EXIT_FAIL = 1, LF_EXIT_USAGE = 2, LF_EXIT_INTERRUPTED = 130 };

int lf_cli_main(const lf_tool *tool, void *opts, int argc, char **argv);
/* Prints "TOOL [CMD]: message" and one line saying where help is; returns LF_EXIT_USAGE. */
int lf_cli_usage_error(const char *tool, const char *cmd, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* A progress callback drawing the bar on stderr; progress: an lf_progress (base/lf_progress.h). */
void lf_cli_progress(void *progress, long done, long total);

/* From now on SIGINT/SIGTERM set the returned flag (no SA_RESTART: accept() returns EINTR). */
volatile sig_atomic_t *lf_cli_stop_on_signals(void);

#endif
