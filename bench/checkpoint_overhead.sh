#!/usr/bin/env bash
# Cost of fault tolerance: the bench scene rendered plainly, with checkpoints
# at the default-style interval (60 s: none fall inside a short render, so
# this measures the bookkeeping) and every second (the write itself), as
# A B C A B C runs; medians and ratios.
#   bash bench/checkpoint_overhead.sh [RUNS] [SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
spp=${2:-64}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target lfrender > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene=scenes/bench/plane-spheres.pbrt
t() { # CPU seconds (user + system) of one run: stable on a shared machine,
       # and what checkpointing adds is CPU work (copying tiles, encoding EXR)
  local TIMEFORMAT='%U %S'
  { time build/bin/lfrender "$scene" --spp "$spp" --threads 2 -o "$tmp/o.exr" --quiet "$@" ; } 2>&1 | tail -1 |
    awk '{printf "%.3f\n", $1 + $2}'
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
plain=(); c60=(); c1=()
for i in $(seq "$runs"); do
  plain+=("$(t)")
  c60+=("$(t --checkpoint-every 60)")
  c1+=("$(t --checkpoint-every 1)")
done
p=$(printf '%s\n' "${plain[@]}" | median)
a=$(printf '%s\n' "${c60[@]}" | median)
b=$(printf '%s\n' "${c1[@]}" | median)
echo "CPU time: plain: $p s; checkpoint every 60 s: $a s ($(awk -v x="$a" -v y="$p" 'BEGIN{printf "%+.1f%%", (x/y-1)*100}')); every 1 s: $b s ($(awk -v x="$b" -v y="$p" 'BEGIN{printf "%+.1f%%", (x/y-1)*100}'))"
echo "($runs runs each, $spp spp, 2 threads, $(nproc) cores, $(date -u +%F))"
