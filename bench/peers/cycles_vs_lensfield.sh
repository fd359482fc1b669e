#!/usr/bin/env bash
# Camera paths per second, lensfield vs Blender Cycles (Debian's blender,
# headless, CPU) and, when PBRT names a pbrt-v4 binary, vs pbrt-v4 on the same
# .pbrt file: equivalent scenes at 64 spp, 640x426, 2 threads, the renderers
# interleaved (lensfield, Cycles, pbrt-v4, lensfield, ...) so machine drift
# cancels; medians of RUNS runs.  Cases: pinhole, thinlens, motion, rolling,
# fisheye (the ideal equisolid fisheye in both) (scenes/bench/plane-spheres
# [-CASE].pbrt and the same case of bench/peers/cycles_plane_spheres.py),
# sky and room (scenes/bench/sky.pbrt, room.pbrt) and realistic (double
# Gauss 50 mm, pbrt-v4 only: Cycles has no traced lens; pbrt-v4 has no
# rolling shutter and no ideal fisheye); also fisheye-lens (the traced 10 mm
# fisheye against Cycles' equisolid fisheye fitted to it) and fisheye-poly
# (against Cycles' polynomial fisheye fitted to the traced mapping).
# Default: the seven Cycles cases, plus realistic when PBRT is set.
# Times are each renderer's own render time (see bench/peers/lib.sh); a
# camera path is one pixel sample, paths/s = width x height x spp / time.
#   bash bench/peers/cycles_vs_lensfield.sh [RUNS] [CASE...]
# Environment: BUILD (default build), PBRT, THREADS (2), SPP (64).
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
runs=${1:-3}
shift || true
cases=("$@")
if [ ${#cases[@]} -eq 0 ]; then
    cases=("${CASES_DEFAULT[@]}")
    [ -z "${PBRT:-}" ] || cases+=(realistic)
fi
spp=${SPP:-64}
peers_build
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
machine_line
peers_pbrt_note
mps() { awk -v p="$1" -v t="$2" 'BEGIN {printf "%.3f", p / t / 1e6}'; }
ratio() { [ "$2" = "—" ] && echo "—" || awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }
hdr="| case | lensfield s | lensfield M paths/s | Cycles s | Cycles M paths/s | lensfield/Cycles |"
sep="|---|---|---|---|---|---|"
if [ -n "${PBRT:-}" ]; then
    hdr+=" pbrt-v4 s | pbrt-v4 M paths/s | lensfield/pbrt-v4 |"
    sep+="---|---|---|"
fi
echo
echo "$hdr"
echo "$sep"
for c in "${cases[@]}"; do
    scene=$(scene_of "$c")
    [ -f "$scene" ] || { echo "no scene $scene for case $c" >&2; exit 1; }
    read -r w h <<< "$(scene_res "$scene")"
    paths=$((w * h * spp))
    lf=(); cy=(); pb=()
    for i in $(seq "$runs"); do
        lf+=("$(run_lf "$scene" "$spp" 0 "$tmp/lf.exr")")
        ! cycles_has "$c" || cy+=("$(run_cy "$c" "$spp" 1 "$w" "$h" "$tmp/cy.exr")")
        ! pbrt_has "$c" || pb+=("$(run_pbrt "$scene" "$spp" 0 "$tmp/pbrt.exr")")
    done
    lt=$(printf '%s\n' "${lf[@]}" | median); lm=$(mps "$paths" "$lt")
    ct="—"; cm="—"; pt="—"; pm="—"
    [ ${#cy[@]} -eq 0 ] || { ct=$(printf '%s\n' "${cy[@]}" | median); cm=$(mps "$paths" "$ct"); }
    [ ${#pb[@]} -eq 0 ] || { pt=$(printf '%s\n' "${pb[@]}" | median); pm=$(mps "$paths" "$pt"); }
    row="| $c | $lt | $lm | $ct | $cm | $(ratio "$lm" "$cm") |"
    [ -z "${PBRT:-}" ] || row+=" $pt | $pm | $(ratio "$lm" "$pm") |"
    echo "$row"
done
echo
echo "($runs interleaved runs per case, medians; $spp spp, ${w}x${h}, $THREADS threads; \"—\": the peer has no equivalent)"
