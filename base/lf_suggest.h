/* lf_suggest.h - "did you mean": the known name nearest a mistyped one.
 *
 *   lf_suggest s = lf_suggest_begin("--dpth");
 *   for (...) lf_suggest_consider(&s, known_name);
 *   const char *best = lf_suggest_best(&s);   // "--depth", or NULL
 *
 * Used for every name a user types: flags, subcommands, scene directives,
 * scene types and parameter names.  The distance is the optimal string
 * alignment (Damerau-Levenshtein) distance, case-insensitive: an insertion,
 * deletion, substitution or swap of neighbours costs 1, so "fvo" is one edit
 * from "fov".  A name is suggested only within one edit per three characters
 * of the typed word (at least one): beyond that the guess shares too little
 * with what was typed to help.  Ties go to the first candidate considered. */
#ifndef LF_SUGGEST_H
#define LF_SUGGEST_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lf_suggest {
    const char *word; /* what was typed */
    const char *best; /* nearest candidate so far, NULL if none within the limit */
    int distance;
} lf_suggest;

lf_suggest lf_suggest_begin(const char *word);
/* Considers one known name (NULL or "" is skipped; so is the word itself). */
void lf_suggest_consider(lf_suggest *s, const char *candidate);
const char *lf_suggest_best(const lf_suggest *s);

/* The nearest of a NULL-terminated list of names, or NULL. */
const char *lf_suggest_among(const char *word, const char *const *names);

/* Case-insensitive optimal string alignment distance; names longer than 63
 * characters count as far from everything (returns a large number). */
int lf_suggest_distance(const char *a, const char *b);

#ifdef __cplusplus
}
#endif
#endif
