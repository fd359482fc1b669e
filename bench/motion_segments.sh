#!/usr/bin/env bash
# Accuracy vs cost of piecewise-linear motion (docs/motion.md):
# the rotating wheel (scenes/motion/wheel.pbrt) with 1, 2, 4, 9, 16 motion
# segments against a 64-segment reference at the same seed and spp (so the
# difference is the geometry, not the noise), and the render time of each;
# then the wheel moving (keyframed, and as a rigid Embree instance: the
# default without "motionsegments") vs the same wheel static (median of
# RUNS, interleaved A B C A B C).
#   bash bench/motion_segments.sh [RUNS]      (LF_BUILD_DIR: build directory, default build)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
build=${LF_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" --target lfrender > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
render() { # scene out -> seconds
  "$build/bin/lfrender" "$1" -o "$2" --threads 2 --seed 1 2>&1 | sed -nE 's/.* in ([0-9.]+) s:.*/\1/p'
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
scene_with() { sed "s/\"integer motionsegments\" \[[0-9]*\]/\"integer motionsegments\" [$1]/" scenes/motion/wheel.pbrt > "$tmp/wheel$1.pbrt"; }
scene_with 64
render "$tmp/wheel64.pbrt" "$tmp/ref.exr" > /dev/null
echo "| segments | RMS error vs 64 segments | render time (s, median of $runs) |"
echo "|---|---|---|"
for n in 1 2 4 9 16; do
  scene_with "$n"
  ts=$(for i in $(seq "$runs"); do render "$tmp/wheel$n.pbrt" "$tmp/w$n.exr"; done | median)
  rms=$( (idiff -a "$tmp/w$n.exr" "$tmp/ref.exr" 2>&1 || true) | sed -nE 's/.*RMS error = ([0-9.e+-]+).*/\1/p' | head -1)
  echo "| $n | ${rms:-0} | $ts |"
done
# moving vs static: the same wheel without its ActiveTransform EndTime rotation,
# against the wheel moving on keyframed vertices (explicit 4 segments) and
# moving as a rigid Embree instance (the default: no "motionsegments").
grep -v -E 'ActiveTransform|Rotate 30' scenes/motion/wheel.pbrt > "$tmp/static.pbrt"
sed 's/ "integer motionsegments" \[[0-9]*\]//' scenes/motion/wheel.pbrt > "$tmp/instance.pbrt"
scene_with 4
keyed=(); inst=(); static=()
for i in $(seq "$runs"); do
  keyed+=("$(render "$tmp/wheel4.pbrt" "$tmp/m.exr")")
  inst+=("$(render "$tmp/instance.pbrt" "$tmp/i.exr")")
  static+=("$(render "$tmp/static.pbrt" "$tmp/s.exr")")
done
k=$(printf '%s\n' "${keyed[@]}" | median); n=$(printf '%s\n' "${inst[@]}" | median)
s=$(printf '%s\n' "${static[@]}" | median)
rms=$( (idiff -a "$tmp/i.exr" "$tmp/ref.exr" 2>&1 || true) | sed -nE 's/.*RMS error = ([0-9.e+-]+).*/\1/p' | head -1)
echo "static: $s s"
echo "moving, keyframed (4 segments): $k s, ratio $(awk -v a="$k" -v b="$s" 'BEGIN {printf "%.2f", a/b}')"
echo "moving, rigid instance (default): $n s, ratio $(awk -v a="$n" -v b="$s" 'BEGIN {printf "%.2f", a/b}'), RMS error vs 64 segments ${rms:-0}"
echo "machine: $(nproc) cores, $(date -u +%F)"
