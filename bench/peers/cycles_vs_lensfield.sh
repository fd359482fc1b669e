#!/usr/bin/env bash
# Camera paths per second, lensfield vs Blender Cycles (Debian's blender,
# headless, CPU) on the equivalent plane + 4 spheres + sun + sky scene at
# 64 spp and 2 threads, interleaved A B A B so machine drift cancels.
# Cycles' time includes its scene sync and BVH build (a few hundred ms at
# this size); lensfield's is the render alone, as it reports it.
#   bash bench/peers/cycles_vs_lensfield.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
command -v blender > /dev/null || { echo "blender is not installed (apt-get install blender)"; exit 1; }
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target lfrender > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
lf=(); cy=()
for i in $(seq "$runs"); do
  lf+=("$(build/bin/lfrender scenes/bench/plane-spheres.pbrt --spp 64 --threads 2 -o "$tmp/lf.exr" 2>&1 | sed -nE 's/.*: ([0-9.]+) M paths\/s.*/\1/p')")
  cy+=("$(blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py -- 64 2 2>&1 | sed -nE 's/^cycles: .*: ([0-9.]+) M paths\/s/\1/p')")
  echo "run $i: lensfield ${lf[-1]} M paths/s, cycles ${cy[-1]} M paths/s"
done
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
l=$(printf '%s\n' "${lf[@]}" | median); c=$(printf '%s\n' "${cy[@]}" | median)
echo "median: lensfield $l, Cycles $c M camera paths/s; ratio $(awk -v a="$l" -v b="$c" 'BEGIN {printf "%.2f", a/b}') ($runs runs, $(nproc) cores, $(date -u +%F))"
