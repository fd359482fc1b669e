/* cli.h - the one way every lensfield tool runs its command table
 * (base/lf_args.h): picks the subcommand, parses its flags, answers --help,
 * --version and --man, prints usage errors (exit 2), then calls the
 * command's handler and returns its exit code. */
#ifndef LF_TOOLS_CLI_H
#define LF_TOOLS_CLI_H

#include "base/lf_args.h"

#ifndef LF_VERSION
#define LF_VERSION "unknown"
#endif

int lf_cli_main(const lf_tool *tool, int argc, char **argv);

#endif
