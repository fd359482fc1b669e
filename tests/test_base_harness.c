/* test_base_harness.c - the test harness itself: a binary in which no check
 * ran must fail, so a test that forgets to check anything cannot pass. */
#include "lf_test.h"

int main(void)
{
    int rc_empty = lf_test_end(); /* nothing checked yet: must fail */
    int rc_one_pass, rc_one_fail;
    lf_test_passed = 1;
    lf_test_failed = 0;
    rc_one_pass = lf_test_end();
    lf_test_passed = 1;
    lf_test_failed = 1;
    rc_one_fail = lf_test_end();
    lf_test_passed = lf_test_failed = 0;
    CHECK(rc_empty != 0);
    CHECK(rc_one_pass == 0);
    CHECK(rc_one_fail != 0);
    return lf_test_end();
}
