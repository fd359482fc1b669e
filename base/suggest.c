/* "Did you mean" (lf_suggest.h). */
#include "lf_suggest.h"

#include <ctype.h>
#include <string.h>

enum { MAX_LEN = 63, FAR = 1 << 20 };

/* The distance, or some number above bound as soon as every alignment of
 * the rows so far costs more than bound (the rest can only add). */
static int distance_within(const char *a, const char *b, int bound)
{
    size_t n = strlen(a), m = strlen(b);
    if (n > MAX_LEN || m > MAX_LEN)
        return FAR;
    int d[MAX_LEN + 1][MAX_LEN + 1];
    for (size_t i = 0; i <= n; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= m; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= n; i++) {
        int row_min = d[i][0];
        for (size_t j = 1; j <= m; j++) {
            int ai = tolower((unsigned char)a[i - 1]), bj = tolower((unsigned char)b[j - 1]);
            int best = d[i - 1][j - 1] + (ai != bj);
            if (d[i - 1][j] + 1 < best)
                best = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < best)
                best = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && ai == tolower((unsigned char)b[j - 2]) &&
                tolower((unsigned char)a[i - 2]) == bj && d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1; /* neighbours swapped */
            d[i][j] = best;
            row_min = best < row_min ? best : row_min;
        }
        /* a swap reaches back two rows, so stop only when this row and the
         * one before are both past the bound */
        if (row_min > bound && i > 1) {
            int prev_min = d[i - 1][0];
            for (size_t j = 1; j <= m; j++)
                prev_min = d[i - 1][j] < prev_min ? d[i - 1][j] : prev_min;
            if (prev_min > bound)
                return bound + 1;
        }
    }
    return d[n][m];
}

int lf_suggest_distance(const char *a, const char *b)
{
    return distance_within(a, b, FAR);
}

lf_suggest lf_suggest_begin(const char *word)
{
    lf_suggest s = {word, NULL, FAR};
    return s;
}

void lf_suggest_consider(lf_suggest *s, const char *candidate)
{
    if (!s->word || !candidate || !*candidate || !strcmp(candidate, s->word))
        return;
    int limit = (int)(strlen(s->word) / 3); /* one edit per three characters typed */
    if (limit < 1)
        limit = 1;
    /* the distance is at least the difference in length: most candidates
     * are ruled out without the table (a scene full of unknown words asks
     * this for every word and every known name) */
    size_t n = strlen(s->word), m = strlen(candidate);
    int at_least = (int)(n > m ? n - m : m - n);
    if (at_least > limit || at_least >= s->distance)
        return;
    int d = distance_within(s->word, candidate, limit < s->distance - 1 ? limit : s->distance - 1);
    if (d <= limit && d < s->distance)
        s->best = candidate, s->distance = d;
}

const char *lf_suggest_best(const lf_suggest *s) { return s->best; }

const char *lf_suggest_among(const char *word, const char *const *names)
{
    lf_suggest s = lf_suggest_begin(word);
    for (; names && *names; names++)
        lf_suggest_consider(&s, *names);
    return lf_suggest_best(&s);
}
