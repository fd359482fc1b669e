/* Where an assignment named on the command line is found
 * (lf_grade_find_assignment, grade/rubric.c).  Runs from the repo root. */
#include <stdio.h>
#include <string.h>

#include "grade/lf_grade.h"
#include "lf_test.h"

int main(void)
{
    char dir[4096];
    lf_error err = {0};
    /* a folder with rubric.txt is itself */
    CHECK(lf_grade_find_assignment("assignments/1-thinlens", dir, sizeof dir, &err) == 0);
    CHECK(!strcmp(dir, "assignments/1-thinlens"));
    /* a name under assignments/ */
    CHECK(lf_grade_find_assignment("2-realistic", dir, sizeof dir, &err) == 0 && !strcmp(dir, "assignments/2-realistic"));
    /* none: named, LF_ERR_PARAM */
    lf_error e = {0};
    CHECK(lf_grade_find_assignment("no-such-assignment", dir, sizeof dir, &e) == LF_ERR_PARAM);
    CHECK(strstr(e.msg, "no-such-assignment: no such assignment") != NULL);
    /* a folder without rubric.txt is not an assignment */
    lf_error e2 = {0};
    CHECK(lf_grade_find_assignment("tests", dir, sizeof dir, &e2) == LF_ERR_PARAM);
    return lf_test_end();
}
