#!/usr/bin/env bash
# Camera paths per second, lensfield vs Blender Cycles (Debian's blender,
# headless, CPU) on equivalent scenes at 64 spp and 2 threads, interleaved
# A B A B so machine drift cancels.  Cases: pinhole (default), thinlens,
# motion, rolling, fisheye - scenes/bench/plane-spheres[-CASE].pbrt and
# bench/peers/cycles_plane_spheres.py CASE.  Cycles' time includes its scene
# sync and BVH build (a few hundred ms); lensfield's is the render alone, as
# it reports it.
#   bash bench/peers/cycles_vs_lensfield.sh [RUNS] [CASE...]
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
shift || true
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(pinhole)
command -v blender > /dev/null || { echo "blender is not installed (apt-get install blender)"; exit 1; }
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target lfrender > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
echo "| case | lensfield M paths/s | Cycles M paths/s | ratio |"
echo "|---|---|---|---|"
for c in "${cases[@]}"; do
  scene=scenes/bench/plane-spheres.pbrt
  [ "$c" = pinhole ] || scene=scenes/bench/plane-spheres-$c.pbrt
  lf=(); cy=()
  for i in $(seq "$runs"); do
    lf+=("$(build/bin/lfrender "$scene" --spp 64 --threads 2 -o "$tmp/lf.exr" 2>&1 | sed -nE 's/.*: ([0-9.]+) M paths\/s.*/\1/p')")
    cy+=("$(blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py -- 64 2 "$c" 2>&1 | sed -nE 's/^cycles: .*: ([0-9.]+) M paths\/s/\1/p')")
  done
  l=$(printf '%s\n' "${lf[@]}" | median); y=$(printf '%s\n' "${cy[@]}" | median)
  echo "| $c | $l | $y | $(awk -v a="$l" -v b="$y" 'BEGIN {printf "%.2f", a/b}') |"
done
echo "($runs interleaved runs per case, 64 spp, 2 threads, $(nproc) cores, $(date -u +%F))"
