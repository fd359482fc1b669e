#!/usr/bin/env bash
# Cost per camera path, independent of the machine's load: instructions per
# path from callgrind (the total at 5 spp minus the total at 1 spp, over the
# 4 x W x H extra paths, one thread, so start-up, BVH build and image output
# cancel) and rays per path from lfrender's summary, for each bench/peers
# case at 160x106.  With BEFORE=/path/to/other/lfrender the same for that
# binary, and the change; paths per second scale as the inverse of
# instructions per path at equal instructions per cycle (docs/performance.md).
#   bash bench/peers/cost_per_path.sh [CASE...]     (default: the seven cases)
# Environment: BUILD (build), BEFORE (unset: no before column), RES (160x106).
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
command -v valgrind > /dev/null || { echo "valgrind is not installed (apt-get install valgrind)" >&2; exit 1; }
res=${RES:-160x106}
w=${res%x*}; h=${res#*x}
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=("${CASES_DEFAULT[@]}")
peers_build_targets lfrender
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# instr BIN SCENE SPP: instructions of one single-threaded render
instr() {
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$1" "$2" --spp "$3" --threads 1 --seed 1 \
        -o "$tmp/out.exr" 2>&1 | sed -nE 's/.*Collected : ([0-9]+).*/\1/p'
}
# cost BIN SCENE: "instructions_per_path rays_per_path", or "- -" when BIN cannot render SCENE
cost() {
    local log rpp i1 i5
    log=$("$1" "$2" --spp 5 --threads 2 --seed 1 -o "$tmp/out.exr" 2>&1) || { echo "- -"; return; }
    # "N camera paths in T s: P M paths/s, R M rays/s"
    rpp=$(sed -nE 's/.* ([0-9.]+) M paths\/s, ([0-9.]+) M rays\/s.*/\1 \2/p' <<< "$log" | awk '{ printf "%.2f", $2 / $1 }')
    i1=$(instr "$1" "$2" 1)
    i5=$(instr "$1" "$2" 5)
    awk -v a="$i1" -v b="$i5" -v n=$((4 * w * h)) -v r="${rpp:-?}" 'BEGIN { printf "%.0f %s", (b - a) / n, r }'
}

echo "cost per camera path, ${w}x${h}, callgrind (5 spp minus 1 spp), one thread; $(date -u '+%F %H:%M UTC')"
if [ -n "${BEFORE:-}" ]; then
    echo "before: $BEFORE"
    echo
    echo "| case | before: instructions per path | rays per path | now: instructions per path | rays per path | change |"
    echo "|---|---|---|---|---|---|"
else
    echo
    echo "| case | instructions per path | rays per path |"
    echo "|---|---|---|"
fi
for c in "${cases[@]}"; do
    make_scene "$(scene_of "$c")" "$w" "$h" "$tmp/$c.pbrt"
    read -r ni nr <<< "$(cost "$LFRENDER" "$tmp/$c.pbrt")"
    if [ -n "${BEFORE:-}" ]; then
        read -r bi br <<< "$(cost "$BEFORE" "$tmp/$c.pbrt")"
        change=$(awk -v a="$bi" -v b="$ni" 'BEGIN { if (a == "-") print "—"; else printf "%+.1f%%", 100 * (b - a) / a }')
        echo "| $c | $bi | $br | $ni | $nr | $change |"
    else
        echo "| $c | $ni | $nr |"
    fi
done
