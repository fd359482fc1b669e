/* lf_args.h - table-driven command lines for every lensfield tool.
 *
 * A tool is a table of commands (one row per subcommand, or a single row
 * with name NULL for a tool without subcommands); a command is a table of
 * flags, each naming where its value goes, its type, range and help text.
 * The same tables give the parser, `--help`, `--version` and the man page,
 * so what a tool accepts and what it documents cannot drift apart.
 *
 *   static struct { double depth; const char *out; } o = {.depth = 1.0};
 *   static const lf_arg refocus_args[] = {
 *       {"--depth", NULL, LF_ARG_DOUBLE, &o.depth, "M", "focus depth in metres",
 *        .min = 0, .flags = LF_ARG_MIN_OPEN},
 *       {"--output", "-o", LF_ARG_STRING, &o.out, "OUT", "output image", .flags = LF_ARG_REQUIRED},
 *   };
 *   static const lf_command cmds[] = {
 *       {"refocus", "IN -o OUT [options]", "refocus a light field", refocus_args,
 *        LF_ARRAY_LEN(refocus_args), 1, 1, run_refocus},
 *   };
 *   static const lf_tool tool = {"lftool", "light-field tool", LF_VERSION, cmds, LF_ARRAY_LEN(cmds)};
 *
 * lf_args_parse() fills the values and returns a status; it never prints.
 * What is an error (exit status 2 in every tool): an unknown flag (the
 * message suggests the nearest known one, base/lf_suggest.h), a flag
 * that belongs to another subcommand (the message says which), a missing or
 * malformed value, a number out of its range or not an integer where one is
 * wanted, a choice not in the list, a required flag missing, too few or too
 * many positional arguments.  "--" ends the flags.
 */
#ifndef LF_ARGS_H
#define LF_ARGS_H

#include <stddef.h>

#include "lf_error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LF_ARRAY_LEN(a) ((int)(sizeof(a) / sizeof((a)[0])))

typedef enum lf_arg_type {
    LF_ARG_FLAG,   /* no value; *(int *)value = 1 */
    LF_ARG_INT,    /* int (count > 1: int[count]) */
    LF_ARG_DOUBLE, /* double (count > 1: double[count]) */
    LF_ARG_STRING, /* const char * (points into argv) */
    LF_ARG_CHOICE, /* const char *, one of `choices` ("a|b|c") */
    LF_ARG_LIST,   /* const char **, appended; *count_out counts; up to `count` */
    LF_ARG_LONG    /* long long (seeds, byte counts) */
} lf_arg_type;

enum {
    LF_ARG_HAS_MIN = 1u << 0,  /* value >= min (or > min with MIN_OPEN) */
    LF_ARG_HAS_MAX = 1u << 1,  /* value <= max (or < max with MAX_OPEN) */
    LF_ARG_MIN_OPEN = 1u << 2, /* implies HAS_MIN */
    LF_ARG_MAX_OPEN = 1u << 3, /* implies HAS_MAX */
    LF_ARG_INF_OK = 1u << 4,   /* LF_ARG_DOUBLE: "inf" accepted (above any max) */
    LF_ARG_REQUIRED = 1u << 5, /* must be given */
    LF_ARG_HIDDEN = 1u << 6    /* parsed, left out of --help and the man page */
};

typedef struct lf_arg {
    const char *name;       /* "--focus" */
    const char *short_name; /* "-o", or NULL */
    lf_arg_type type;
    void *value;            /* where the value goes (see lf_arg_type) */
    const char *metavar;    /* "M", "N", "FILE"; NULL for flags */
    const char *help;       /* one sentence */
    double min, max;        /* range, with LF_ARG_HAS_MIN / HAS_MAX */
    unsigned flags;
    int count;              /* values per occurrence (INT, DOUBLE); capacity (LIST); 0 = 1 */
    const char *choices;    /* LF_ARG_CHOICE: "clamp|filmic|aces" */
    int *given;             /* optional: set to 1 when the flag appears */
    int *count_out;         /* LF_ARG_LIST: how many were given */
} lf_arg;

typedef struct lf_command {
    const char *name;     /* subcommand, or NULL for a tool without subcommands */
    const char *synopsis; /* "IN -o OUT [options]" (after "tool name") */
    const char *summary;  /* one line */
    const lf_arg *args;
    int n_args;
    int min_positional, max_positional; /* max -1: unlimited */
    int (*run)(void *opts, int n_positional, char **positional); /* the handler; opts: lf_cli_main's */
    const char *description;                          /* optional paragraph for --help and man */
} lf_command;

typedef struct lf_tool {
    const char *name;    /* "lftool" */
    const char *summary; /* one line */
    const char *version; /* the CMake project version */
    const lf_command *commands;
    int n_commands;
    const char *description; /* optional paragraph: exit codes, environment */
} lf_tool;

typedef enum lf_args_status {
    LF_ARGS_OK = 0,
    LF_ARGS_HELP,    /* --help / -h: print lf_args_usage() to stdout, exit 0 */
    LF_ARGS_VERSION, /* --version: print "tool version", exit 0 */
    LF_ARGS_ERROR,   /* message in err: print it and where help is to stderr, exit 2 */
    LF_ARGS_MAN      /* --man: print the tool's man page (lf_args_man), exit 0 */
} lf_args_status;

/* Finds a command by name (NULL name: the single command of a tool without
 * subcommands).  Returns NULL if there is none. */
const lf_command *lf_args_find(const lf_tool *tool, const char *name);

/* Sets err to "unknown command "WORD"", with the nearest command name
 * suggested (lf_suggest.h) when one is near; returns err->msg. */
const char *lf_args_unknown_command(const lf_tool *tool, const char *word, lf_error *err);

/* Parses argv[first..argc) against cmd's flags.  Positional arguments are
 * collected in order into positional[] (room for argc entries is enough);
 * *n_positional counts them.  err (cleared first) gets a one-line message
 * and LF_ERR_PARAM on LF_ARGS_ERROR. */
lf_args_status lf_args_parse(const lf_tool *tool, const lf_command *cmd, int argc, char **argv, int first,
                             char **positional, int *n_positional, lf_error *err);

/* Usage text of one command (cmd) or of the whole tool (cmd NULL), ending
 * in a newline.  malloc'd (free it); NULL when memory runs out. */
char *lf_args_usage(const lf_tool *tool, const lf_command *cmd);

/* The tool's man page in roff (man(7)), from the same tables.  malloc'd. */
char *lf_args_man(const lf_tool *tool, const char *date);

#ifdef __cplusplus
}
#endif
#endif
