/* fuzz_camera_params.c - libFuzzer target: see fuzz/fuzz_entry.h for what it drives.
 * Build and run: bash bench/fuzz.sh [SECONDS] (docs/fuzzing.md). */
#include "fuzz/fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (lf_fuzz_run(LF_FUZZ_CAMERA_PARAMS, data, size) < 0)
        abort(); /* refused without a message, or a contract broken: save the input */
    return 0;
}
