/* Directories, the writable check and extensions (base/file_write.c,
 * base/file.c), and the progress line (base/progress.c). */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/lf_file.h"
#include "base/lf_file_write.h"
#include "base/lf_progress.h"
#include "lf_test.h"

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

static int entries(const char *d)
{
    DIR *dp = opendir(d);
    int n = 0;
    for (struct dirent *e; dp && (e = readdir(dp));)
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (dp)
        closedir(dp);
    return n;
}

int main(void)
{
    char root[256], p[512], q[512];
    snprintf(root, sizeof root, "%s/test_base_paths.%ld", LF_BINARY_DIR, (long)getpid());
    lf_error err = {0};
    CHECK(lf_dir_create(root, &err) == 0 && is_dir(root));
    CHECK(lf_dir_create(root, &err) == 0); /* an existing folder is fine */
    snprintf(p, sizeof p, "%s/a/b", root); /* parent missing */
    lf_error e1 = {0};
    CHECK(lf_dir_create(p, &e1) == LF_ERR_IO && strstr(e1.msg, "cannot create directory") && strstr(e1.msg, p));

    /* mkdir -p of a file's folder; a bare name or a root-level file needs none */
    snprintf(p, sizeof p, "%s/x/y/z/out.exr", root);
    CHECK(lf_dir_create_parents(p, &err) == 0);
    snprintf(q, sizeof q, "%s/x/y/z", root);
    CHECK(is_dir(q) && access(p, F_OK) != 0);
    CHECK(lf_dir_create_parents("out.exr", &err) == 0 && lf_dir_create_parents("/out.exr", &err) == 0);

    /* the writable check creates the folder, leaves no probe behind */
    snprintf(p, sizeof p, "%s/w/out.png", root);
    CHECK(lf_file_check_writable(p, &err) == 0);
    snprintf(q, sizeof q, "%s/w", root);
    CHECK(is_dir(q) && entries(q) == 0);
    /* a path through a regular file cannot be created (even as root) */
    snprintf(q, sizeof q, "%s/file", root);
    FILE *f = fopen(q, "w");
    CHECK(f != NULL);
    if (f)
        fclose(f);
    snprintf(p, sizeof p, "%s/file/sub/out.exr", root);
    lf_error e2 = {0};
    CHECK(lf_file_check_writable(p, &e2) == LF_ERR_IO && strstr(e2.msg, "cannot create the directory of"));

    CHECK(lf_path_has_ext("a/b.EXR", ".exr") && lf_path_has_ext("b.exr", ".exr"));
    CHECK(!lf_path_has_ext("exr", ".exr") && !lf_path_has_ext("b.exr.png", ".exr") && !lf_path_has_ext("", ".exr"));

    /* progress: a 40-character bar filled in proportion; the final line ends
     * the line; a line less than 0.2 s after the previous one is skipped */
    lf_progress pr;
    lf_progress_start(&pr);
    char line[160];
    CHECK(lf_progress_line(&pr, 1, 4, line, sizeof line) == 1);
    CHECK_MSG(!strncmp(line, "\r[##########..............................]  25.0%", 50), "%s", line);
    CHECK(lf_progress_line(&pr, 2, 4, line, sizeof line) == 0);
    CHECK(lf_progress_line(&pr, 4, 4, line, sizeof line) == 1);
    CHECK(strstr(line, "[########################################] 100.0%") && line[strlen(line) - 1] == '\n');
    double t0 = lf_seconds();
    CHECK(lf_seconds() >= t0);

    snprintf(p, sizeof p, "rm -rf '%s'", root);
    if (system(p)) {
    }
    return lf_test_end();
}
