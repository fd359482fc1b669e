#!/usr/bin/env bash
# Camera paths per second of this lfrender against another one (BEFORE),
# wall clock, on every bench/peers case at the scenes' own 640x426: the two
# binaries interleaved (before, now, before, now, ...) RUNS times, medians
# and their ratio.  The load-independent companion is cost_per_path.sh.
#   BEFORE=/path/to/lfrender bash bench/peers/paths_vs_before.sh [CASE...]
# Environment: BUILD (build), BEFORE (required), RUNS (3), SPP (16), THREADS (2).
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
[ -n "${BEFORE:-}" ] || { echo "BEFORE must name the other lfrender" >&2; exit 2; }
runs=${RUNS:-3}
spp=${SPP:-16}
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=("${CASES_DEFAULT[@]}")
peers_build_targets lfrender
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rate() { # BIN SCENE: M paths/s, or - when BIN cannot render it
    "$1" "$2" --spp "$spp" --threads "$THREADS" --seed 1 -o "$tmp/out.exr" 2>&1 |
        sed -nE 's/.* ([0-9.]+) M paths\/s.*/\1/p' | grep . || echo -
}
median() { printf '%s\n' "$@" | grep -v '^-$' | sort -g | awk '{a[NR]=$1} END {if (!NR) print "-"; else print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
machine_line
echo "paths per second, $spp spp, $THREADS threads, medians of $runs interleaved runs; before: $BEFORE"
echo
echo "| case | before M paths/s | now M paths/s | now / before |"
echo "|---|---|---|---|"
for c in "${cases[@]}"; do
    make_scene "$(scene_of "$c")" 640 426 "$tmp/$c.pbrt"
    b=() n=()
    for _ in $(seq "$runs"); do
        b+=("$(rate "$BEFORE" "$tmp/$c.pbrt")")
        n+=("$(rate "$LFRENDER" "$tmp/$c.pbrt")")
    done
    mb=$(median "${b[@]}") mn=$(median "${n[@]}")
    ratio=$(awk -v a="$mb" -v b="$mn" 'BEGIN { if (a == "-" || b == "-") print "—"; else printf "%.2f", b / a }')
    echo "| $c | $mb | $mn | $ratio |"
done
