/* Replays every saved fuzz input through the same entry points the libFuzzer
 * targets drive (fuzz/fuzz_entry.h), without the fuzzer runtime, so a fixed
 * crasher stays fixed in the ordinary ctest run (and under LF_SANITIZE):
 *   fuzz/regressions/<target>/     inputs that once crashed or misbehaved
 *   fuzz/corpus/<target>/          the seed corpora (valid files: accepted)
 * Each input must be accepted (0) or refused with a message (1); a refusal
 * without a message (-1) fails.  A crash fails the test by crashing.
 * Files whose names start with '.' or "README" are skipped.  Most memory
 * and undefined-behaviour bugs only show in the sanitizer build
 * (LF_SANITIZE=ON, run by .ci/run): in a Release build an out-of-bounds
 * read usually passes silently. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz/fuzz_entry.h"
#include "lf_test.h"

static int read_all(const char *path, uint8_t **data, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t cap = 4096, n = 0;
    uint8_t *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            uint8_t *b = realloc(buf, cap *= 2);
            if (!b) {
                free(buf);
                buf = NULL;
            }
            buf = b;
        }
    }
    fclose(f);
    if (!buf)
        return -1;
    *data = buf;
    *size = n;
    return 0;
}

/* Runs every file of dir through target t; returns how many were run. */
static int replay_dir(lf_fuzz_target t, const char *dir, int corpus)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0; /* an empty regressions folder is not in git */
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.' || !strncmp(e->d_name, "README", 6))
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        uint8_t *data = NULL;
        size_t size = 0;
        if (read_all(path, &data, &size)) {
            CHECK_MSG(0, "cannot read %s", path);
            continue;
        }
        int rc = lf_fuzz_run(t, data, size);
        free(data);
        CHECK_MSG(rc >= 0, "%s: refused without an error message", path);
        /* Seeds may be refused (a scene whose Include is not beside the
         * fuzzed text, a layout that lacks a kind); they must not crash. */
        (void)corpus;
        count++;
    }
    closedir(d);
    return count;
}

int main(void)
{
    int total = 0;
    for (int t = 0; t < LF_FUZZ_TARGET_COUNT; t++) {
        char dir[1024];
        snprintf(dir, sizeof dir, "%s/fuzz/regressions/%s", LF_SOURCE_DIR, lf_fuzz_target_names[t]);
        int r = replay_dir((lf_fuzz_target)t, dir, 0);
        snprintf(dir, sizeof dir, "%s/fuzz/corpus/%s", LF_SOURCE_DIR, lf_fuzz_target_names[t]);
        int c = replay_dir((lf_fuzz_target)t, dir, 1);
        CHECK_MSG(c > 0, "no seed corpus for %s", lf_fuzz_target_names[t]);
        printf("%-14s %3d regressions, %3d seeds replayed\n", lf_fuzz_target_names[t], r, c);
        total += r + c;
    }
    printf("%d inputs replayed\n", total);
    return lf_test_end();
}
