#!/usr/bin/env bash
# Where lfrender's time goes on a bench/peers case: a sampling profile
# (perf record, 2 threads, the whole process) grouped by
# bench/peers/profile_categories.py into Embree traversal, our intersection
# code, sample generation, camera ray generation, shading, lights, ...
#   bash bench/peers/profile.sh [CASE] [SPP]     (default pinhole 16; env BUILD, THREADS)
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
c=${1:-pinhole}
spp=${2:-16}
peers_build_targets lfrender
command -v perf > /dev/null || { echo "perf is not installed (linux-perf); valgrind --tool=callgrind is the fallback" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene=$(scene_of "$c")
cmd=("$LFRENDER" "$scene" --spp "$spp" --threads "$THREADS" -o "$tmp/out.exr")
perf record -q -o "$tmp/perf.data" "${cmd[@]}" 2> "$tmp/log" ||
    { cat "$tmp/log" >&2; echo "perf record failed (perf_event_paranoid?); valgrind --tool=callgrind is the fallback" >&2; exit 1; }
echo "perf record ${cmd[*]/#$tmp\//} ($(sed -nE 's/.*(camera paths in [0-9.]+ s: [0-9.]+ M paths\/s).*/\1/p' "$tmp/log"))"
echo
perf report -i "$tmp/perf.data" --no-children --sort dso,sym --stdio 2> /dev/null | python3 bench/peers/profile_categories.py
