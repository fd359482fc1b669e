#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang into build-fuzz and runs each
# for SECONDS (default 60), printing the executions per target.
#
#   bash bench/fuzz.sh [SECONDS] [TARGET ...]     # targets: scene_parser ply lens_file lf_attributes image_exr camera_params folder
#   LF_FUZZ_RUNS=N bash bench/fuzz.sh            # deterministic: seed 1, N inputs per target, one process
#                                                # (at most LF_FUZZ_MAX_SECONDS, default 180, per target)
#
# CI uses the deterministic form: a fixed seed and input count replay the
# same inputs on every run, so CI fails only when the code changes, never
# because a random run got lucky; exploration happens in the timed form.
#
# Each target starts from its seeds in fuzz/corpus/<target>/ and grows a
# working corpus in build-fuzz/corpus/<target>/ (not in git).  A crash, leak,
# timeout or out-of-memory input is copied to fuzz/regressions/<target>/,
# where tests/test_fuzz_regressions.c replays it in every ctest run; its
# report is in build-fuzz/logs/<target>.log.  Exit status: 0 if no target
# found anything, 1 otherwise.  Results and the command: docs/fuzzing.md.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET="${1:-60}"
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(scene_parser ply lens_file lf_attributes image_exr camera_params folder)
B="${LF_FUZZ_BUILD:-build-fuzz}"

cmake -S . -B "$B" -G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLF_FUZZ=ON >/dev/null
cmake --build "$B" --target lf_fuzz -j"$(nproc)"

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
found=0
printf '%-14s %10s %10s %8s  %s\n' target seconds execs exec/s findings
for t in "${TARGETS[@]}"; do
  bin="$B/bin/fuzz_$t"
  [ -x "$bin" ] || { echo "fuzz.sh: no target $t" >&2; exit 2; }
  mkdir -p "$B/corpus/$t" "$B/artifacts/$t" "$B/logs" "fuzz/regressions/$t"
  log="$B/logs/$t.log"
  # Fork mode keeps fuzzing after a crash, so one known bug does not end
  # the run.  -timeout: one input taking 10 s is a finding; so is 2 GB RSS.
  start=$(date +%s)
  if [ -n "${LF_FUZZ_RUNS:-}" ]; then
    rm -rf "$B/corpus/$t" && mkdir -p "$B/corpus/$t" # same start every time
    runs=$LF_FUZZ_RUNS
    # camera_params builds a whole camera per input (a lens file parsed and
    # its exit pupil tabulated, a microlens lattice): ~100 inputs/s idle
    # against thousands for the parsers, so it runs 1/50 of the count
    [ "$t" = camera_params ] && runs=$(( (LF_FUZZ_RUNS + 49) / 50 ))
    # folder makes a folder of hard links and a file per input: 1/5
    [ "$t" = folder ] && runs=$(( (LF_FUZZ_RUNS + 4) / 5 ))
    # The seeds go in as a sorted list, not as a directory: libFuzzer takes a
    # directory in readdir order, which differs between file systems (ext4
    # hashes names with a per-file-system seed), and the shuffle and every
    # mutation after it follow that order; a list makes the run the same on
    # every machine.  A unit is slow or timed out at 30 s here, not 10: a
    # noisy shared CI machine must not turn a stall into a finding (the timed
    # form below keeps 10 s to catch slow inputs).
    seeds=$(find "fuzz/corpus/$t" -type f | LC_ALL=C sort | paste -sd, -)
    # The sequence of inputs is fixed; a slow machine runs less of it:
    # each target stops at its count or after LF_FUZZ_MAX_SECONDS (180),
    # whichever comes first, so a finding there is in the same sequence
    # here and CI's time stays bounded.
    "$bin" "$B/corpus/$t" -seed_inputs="$seeds" -seed=1 -runs="$runs" -max_total_time="${LF_FUZZ_MAX_SECONDS:-180}" \
      -timeout=30 -report_slow_units=30 -rss_limit_mb=2048 -artifact_prefix="$B/artifacts/$t/" >"$log" 2>&1 || true
  else
    "$bin" "$B/corpus/$t" "fuzz/corpus/$t" -fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 \
      -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$B/artifacts/$t/" >"$log" 2>&1 || true
  fi
  secs=$(( $(date +%s) - start ))
  execs=$(sed -n -e 's/^#\([0-9][0-9]*\):.*/\1/p' -e 's/^Done \([0-9][0-9]*\) runs.*/\1/p' "$log" | tail -1 || true)
  execs=${execs:-0}
  rate=$(( execs / (secs > 0 ? secs : 1) ))
  n=0
  names=""
  for a in "$B/artifacts/$t"/*; do
    [ -e "$a" ] || continue
    n=$((n + 1))
    names="$names $(basename "$a")"
    [ $n -le 5 ] && cp "$a" "fuzz/regressions/$t/"  # a few examples; the rest repeat them
    rm -f "$a"
  done
  findings=none
  if [ $n -gt 0 ]; then
    found=1
    findings="$n inputs ($( [ $n -le 5 ] && echo all || echo 5 ) saved in fuzz/regressions/$t/)"
    echo "fuzz.sh: $t: distinct reports (full log: $log):" >&2
    # what each saved input is (crash-, leak-, timeout-, oom-, slow-unit-)
    # and the target's own words about it, so a CI log says what was found
    echo "fuzz.sh: $t: saved:$names" >&2
    grep -h '^lf_fuzz_\|^Slowest unit\|^==[0-9]*==ERROR\|^ALARM\|^MS: .*; base unit' "$log" | head -n 20 >&2 || true
    # one line per place and kind: values replaced by N
    grep -h 'SUMMARY: \|runtime error: ' "$log" | sed 's/==[0-9]*==//' |
      awk -F'runtime error: ' 'NF > 1 { gsub(/-?(nan|inf|[0-9][0-9.e+-]*)/, "N", $2); print $1 "runtime error: " $2; next } { print }' |
      sort | uniq -c | sort -rn >&2 || true
  fi
  printf '%-14s %10s %10s %8s  %s\n' "$t" "$secs" "$execs" "$rate" "$findings"
done
exit $found
