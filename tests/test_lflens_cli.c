/* lflens, the lens analysis tool: exit codes, file:line messages, the JSON
 * focal length against the published paraxial value, plot outputs.
 * Needs the lflens binary built first (tests/CMakeLists.txt:
 * add_dependencies(test_lflens_cli lflens)). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lf_test.h"
#include "lf_test_tools.h"

#define LFLENS LF_BINARY_DIR "/bin/lflens"
#define LENSES LF_SOURCE_DIR "/scenes/lenses/"

static double json_number(const char *text, const char *key)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    const char *p = strstr(text, pat);
    return p ? atof(p + strlen(pat)) : NAN;
}

int main(void)
{
    if (access(LFLENS, X_OK) != 0) {
        fprintf(stderr, "%s is missing: build the lflens target first\n", LFLENS);
        CHECK(0);
        return lf_test_end();
    }
    char out[16384], cmd[1024];
    char logdir[] = "/tmp/lflens_cli_XXXXXX"; /* run()'s log */
    if (!mkdtemp(logdir)) {
        perror("mkdtemp");
        return 1;
    }
    lf_test_run_setup(logdir, 0, out, sizeof out);
    static const struct {
        const char *file;
        double efl;
    } lenses[] = {{"dgauss.50mm.dat", 50.36}, {"wide.22mm.dat", 22.02}, {"telephoto.250mm.dat", 249.57},
                  {"fisheye.10mm.dat", 9.99}, {"dgauss.100mm.dat", 100.72}};
    for (size_t k = 0; k < sizeof lenses / sizeof lenses[0]; k++) {
        snprintf(cmd, sizeof cmd, LFLENS " info " LENSES "%s --json", lenses[k].file);
        CHECK(run("%s", cmd) == 0);
        double efl = json_number(out, "efl_mm");
        CHECK_MSG(fabs(efl - lenses[k].efl) <= 0.005 * lenses[k].efl, "%s: %s", lenses[k].file, out);
        static const char *const keys[] = {"bfl_mm", "ffl_mm", "fnumber", "entrance_pupil_mm", "exit_pupil_mm",
                                           "fov_deg"};
        for (int i = 0; i < 6; i++)
            CHECK_MSG(isfinite(json_number(out, keys[i])), "%s missing in %s", keys[i], out);
    }
    /* Human-readable output and a focus distance. */
    CHECK(run(LFLENS " info " LENSES "dgauss.50mm.dat --focus 2 --sensor apsc") == 0);
    CHECK(strstr(out, "effective focal length") != NULL);
    /* Usage errors: 2. */
    CHECK(run(LFLENS) == 2);
    CHECK(run(LFLENS " frobnicate x.dat") == 2);
    CHECK(run(LFLENS " info " LENSES "dgauss.50mm.dat --sensor nosuch") == 2);
    CHECK(run(LFLENS " plot " LENSES "dgauss.50mm.dat -o /tmp/x.jpg") == 2);
    /* Bad input: 1, with file:line. */
    char tmpl[] = "/tmp/lflens_cli_XXXXXX";
    int fd = mkstemp(tmpl);
    CHECK(fd >= 0);
    if (fd >= 0) {
        const char *bad = "# lens\n50 5 1.5 30\n-50 40 1\n";
        CHECK(write(fd, bad, strlen(bad)) == (ssize_t)strlen(bad));
        close(fd);
        snprintf(cmd, sizeof cmd, LFLENS " info %s", tmpl);
        CHECK(run("%s", cmd) == 1);
        char want[256];
        snprintf(want, sizeof want, "%s:3: expected 4 or 5 columns", tmpl);
        CHECK_MSG(strstr(out, want) != NULL, "%s", out);
        unlink(tmpl);
    }
    CHECK(run(LFLENS " info " LENSES "no-such.dat") == 1);
    CHECK(run(LFLENS " info " LENSES "dgauss.50mm.dat --focus 0.1") == 1);
    CHECK(strstr(out, "closer than") != NULL);
    /* Plots: SVG and PNG, written whole. */
    char dir[] = "/tmp/lflens_plot_XXXXXX";
    if (mkdtemp(dir)) {
        snprintf(cmd, sizeof cmd, LFLENS " plot " LENSES "fisheye.10mm.dat -o %s/f.svg", dir);
        CHECK(run("%s", cmd) == 0);
        snprintf(cmd, sizeof cmd, "%s/f.svg", dir);
        FILE *f = fopen(cmd, "r");
        CHECK(f != NULL);
        if (f) {
            char head[256] = "";
            size_t n = fread(head, 1, sizeof head - 1, f);
            head[n] = 0;
            fclose(f);
            CHECK(strncmp(head, "<svg", 4) == 0);
            unlink(cmd);
        }
        snprintf(cmd, sizeof cmd, LFLENS " plot " LENSES "dgauss.50mm.dat -o %s/d.png", dir);
        CHECK(run("%s", cmd) == 0);
        snprintf(cmd, sizeof cmd, "%s/d.png", dir);
        CHECK(access(cmd, R_OK) == 0);
        unlink(cmd);
        rmdir(dir);
    }
    snprintf(cmd, sizeof cmd, "%s/log.txt", logdir);
    unlink(cmd);
    rmdir(logdir);
    return lf_test_end();
}
