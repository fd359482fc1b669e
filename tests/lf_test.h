/* lf_test.h - a tiny test harness: CHECK-style macros and a summary line.
 *
 *   int main(void) { CHECK(1 + 1 == 2); CHECK_NEAR(x, 2.0, 1e-9); return lf_test_end(); }
 *
 * Each test binary prints "N passed, N failed" and exits non-zero on failure,
 * or when no check ran at all.
 */
#ifndef LF_TEST_H
#define LF_TEST_H

#include <math.h>
#include <stdio.h>

static int lf_test_passed, lf_test_failed;

#define CHECK(cond)                                                                   \
    do {                                                                              \
        if (cond) {                                                                   \
            lf_test_passed++;                                                         \
        } else {                                                                      \
            lf_test_failed++;                                                         \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                             \
    } while (0)

#define CHECK_MSG(cond, ...)                                                  \
    do {                                                                      \
        if (cond) {                                                           \
            lf_test_passed++;                                                 \
        } else {                                                              \
            lf_test_failed++;                                                 \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                     \
            fputc('\n', stderr);                                              \
        }                                                                     \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                              \
    do {                                                                                   \
        double lf_a_ = (double)(a), lf_b_ = (double)(b), lf_t_ = (double)(tol);            \
        if (fabs(lf_a_ - lf_b_) <= lf_t_) {                                                \
            lf_test_passed++;                                                              \
        } else {                                                                           \
            lf_test_failed++;                                                              \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, %s = %.9g, tol %.3g\n", \
                    __FILE__, __LINE__, #a, lf_a_, #b, lf_b_, lf_t_);                     \
        }                                                                                  \
    } while (0)

/* A test binary in which no check ran has tested nothing: that fails. */
static inline int lf_test_end(void)
{
    if (lf_test_passed + lf_test_failed == 0) {
        fprintf(stderr, "no check ran: a test that checks nothing fails\n");
        printf("0 passed, 1 failed\n");
        return 1;
    }
    printf("%d passed, %d failed\n", lf_test_passed, lf_test_failed);
    return lf_test_failed ? 1 : 0;
}

#endif
