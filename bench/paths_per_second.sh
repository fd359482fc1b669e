#!/usr/bin/env bash
# Camera paths per second on the demo scene (640x426, plane + 4 spheres,
# sun + sky, maxdepth 8) at 64 spp on 2 threads: the median of N runs.
#   bash bench/paths_per_second.sh [RUNS] [SCENE]
# Writes one line per run and the median; docs/performance.md quotes it.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
scene=${2:-scenes/demo.pbrt}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target lfrender > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rates=()
for i in $(seq "$runs"); do
  line=$(build/bin/lfrender "$scene" --spp 64 --threads 2 -o "$tmp/bench.exr" 2>&1 | grep "camera paths in")
  echo "run $i: $line"
  rates+=("$(echo "$line" | sed -E 's/.*: ([0-9.]+) M paths\/s.*/\1/')")
done
median=$(printf '%s\n' "${rates[@]}" | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}')
echo "median: $median M camera paths/s ($runs runs, 64 spp, 2 threads, $scene) on $(nproc) cores, $(date -u +%F)"
