#!/usr/bin/env bash
# The sensor stage (Film "raw", docs/sensor.md "Cost"): its cost per megapixel
# (bench_sensor), and the demo's render time with Film "raw" and Film "rgb"
# (the same scene, medians of 3 runs; the rgb variant drops the sensor lines).
#   bench/sensor.sh [BUILD_DIR]   (default build)
set -euo pipefail
build=${1:-build}
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
"$build/bin/bench_sensor"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sed -e 's/Film "raw"/Film "rgb"/' -e 's/"string cfa" "rggb" "string sensor" "ideal"//' \
    scenes/sensor/demo-raw.pbrt > "$tmp/demo-rgb.pbrt"
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
timeit() { # wall seconds of one lfrender run, including writing the output
    local s e
    s=$(date +%s.%N); "$build/bin/lfrender" "$@" --quiet; e=$(date +%s.%N)
    echo "$e - $s" | bc -l
}
for film in raw rgb; do
    scene=scenes/sensor/demo-raw.pbrt; [ $film = rgb ] && scene=$tmp/demo-rgb.pbrt
    t=$(for i in 1 2 3; do timeit "$scene" --spp 4 -o "$tmp/out-$film.exr"; done | median)
    printf 'demo 640x426, 4 spp, Film "%s" -> .exr: %.3f s (render, sensor for raw, write)\n' "$film" "$t"
done
