#!/usr/bin/env bash
# Render time of the light-field demos and of every assignment's reference
# scenes on 2 threads (docs/lightfield.md "Bench", docs/grading.md "Bench").
# Each scene is rendered N times (the camera-array demo, ~1-2 minutes a run,
# NBIG times) at its own sample count; prints the median wall time, the
# renderer's own render time and the load average before each scene (other
# work on the machine inflates wall times: quote medians with the load).
#   bash bench/demo_times.sh [BUILD_DIR] [N] [NBIG]
set -euo pipefail
B=${1:-build}/bin
N=${2:-3}
NBIG=${3:-1}
W=$(mktemp -d /tmp/lf_bench_demo.XXXXXX)
trap 'rm -rf "$W"' EXIT
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
printf '%-46s %5s %6s %12s %12s %s\n' scene spp runs "wall med(s)" "render med" "load (1 min)"
run() {
  local scene=$1 n=$2 spp
  spp=$(sed -n 's/.*"integer pixelsamples" \[\([0-9]*\)\].*/\1/p' "$scene" | head -1)
  local load walls="" renders=""
  load=$(cut -d' ' -f1 /proc/loadavg)
  for ((k = 0; k < n; k++)); do
    local t0 t1 log
    t0=$(date +%s.%N)
    log=$("$B/lfrender" "$scene" -o "$W/out.exr" --threads 2 2>&1)
    t1=$(date +%s.%N)
    walls+="$(echo "$t1 - $t0" | bc)"$'\n'
    renders+="$(echo "$log" | sed -n 's/.*camera paths in \([0-9.]*\) s.*/\1/p' | tail -1)"$'\n'
  done
  printf '%-46s %5s %6d %12.2f %12.2f %s\n' "$scene" "$spp" "$n" "$(printf '%s' "$walls" | median)" \
    "$(printf '%s' "$renders" | median)" "$load"
}
run scenes/lightfield/plenoptic.pbrt "$N"
run scenes/lightfield/camera-array.pbrt "$NBIG"
for s in assignments/*/scenes/*.pbrt; do run "$s" "$N"; done
