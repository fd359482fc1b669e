#!/usr/bin/env bash
# Speed of the whole `lftool depth DIR -o d.pfm` command (reading the
# views, the grid check, the views' gains, the depth, writing the map) on
# a 9 x 9 x 512^2 folder, 2 threads (issue 28 point 5: at most 10 s;
# figures in docs/depth.md, "Speed").
#
#   bash bench/lf_depth_speed.sh [DIR] [RUNS]
#       DIR default ../shared/lfdata/hci/backgammon, RUNS default 3
#   REF=/path/to/another/lftool bash bench/lf_depth_speed.sh ...
#       times that binary too (runs alternate) and compares the two maps
#       byte for byte (cmp): a speed change must not change the output.
#
# Prints the load average before the runs, each run's wall and CPU time
# (user + sys, all threads) and the medians.  The machine is shared: quote
# the load average with the figures.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-../shared/lfdata/hci/backgammon}
runs=${2:-3}
build=${BUILD:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" --target lftool > /dev/null
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
TIMEFORMAT='%R %U %S'
declare -A walls cpus
bins=("$build/bin/lftool")
[ -n "${REF:-}" ] && bins+=("$REF")
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for ((r = 1; r <= runs; r++)); do
    for i in "${!bins[@]}"; do
        t=$({ time "${bins[$i]}" depth "$dir" -o "$out/d$i.pfm" --threads 2 > /dev/null; } 2>&1)
        read -r wall user sys <<< "$t"
        cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN {printf "%.2f", u + s}')
        walls[$i]+="$wall "
        cpus[$i]+="$cpu "
        echo "run $r ${bins[$i]}: wall $wall s, CPU $cpu s"
    done
done
median() { tr ' ' '\n' | grep -v '^$' | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
for i in "${!bins[@]}"; do
    echo "${bins[$i]}: median of $runs: wall $(echo "${walls[$i]}" | median) s, CPU $(echo "${cpus[$i]}" | median) s"
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
if [ -n "${REF:-}" ]; then
    if cmp -s "$out/d0.pfm" "$out/d1.pfm"; then echo "maps identical (cmp)"; else echo "maps DIFFER"; exit 1; fi
fi
