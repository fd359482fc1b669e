/* bench_parse.c - scene-file parse time: lf_scene_parse_file on FILE,
 * REPEATS times (default 5); prints the median and best wall-clock seconds
 * and the rate in MB of file text per second.  Run by bench/parse_stream.sh.
 *
 *   bench_parse FILE [REPEATS]
 */
#include "bench_util.h"
#include "scenefile/lf_scene_desc.h"

#include <stdio.h>
#include <sys/stat.h>

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_parse FILE [REPEATS]\n");
        return 2;
    }
    int reps = argc > 2 ? atoi(argv[2]) : 5;
    if (reps < 1 || reps > 100)
        reps = 5;
    struct stat st;
    if (stat(argv[1], &st)) {
        perror(argv[1]);
        return 1;
    }
    double t[100], cpu[100];
    size_t shapes = 0;
    for (int i = 0; i < reps; i++) {
        lf_scene_desc d;
        lf_error err = {0};
        double t0 = lf_seconds(), c0 = bench_cpu_seconds();
        int rc = lf_scene_parse_file(argv[1], &d, &err);
        t[i] = lf_seconds() - t0;
        cpu[i] = bench_cpu_seconds() - c0;
        if (rc) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        shapes = d.n_shapes;
        lf_scene_desc_free(&d);
    }
    double med = bench_median(t, reps), med_cpu = bench_median(cpu, reps);
    printf("%s: %.1f MB, %zu shapes: median %.3f s (CPU %.3f s), best %.3f s (%d runs), %.0f MB/s\n", argv[1],
           st.st_size / 1e6, shapes, med, med_cpu, t[0], reps, st.st_size / 1e6 / med);
    return 0;
}
