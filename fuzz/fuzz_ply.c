/* fuzz_ply.c - libFuzzer target: see fuzz/fuzz_entry.h for what it drives.
 * Build and run: bash bench/fuzz.sh [SECONDS] (docs/fuzzing.md). */
#include "fuzz/fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (lf_fuzz_run(LF_FUZZ_PLY, data, size) < 0)
        abort(); /* refused without a message: save the input */
    return 0;
}
