#!/usr/bin/env bash
# Equal-quality comparison, lensfield vs Blender Cycles (and pbrt-v4 when PBRT
# names a binary): for each case every renderer renders its OWN converged
# reference (REF_SPP samples, seed 1000), then a ladder of spp timed,
# interleaved (lensfield, Cycles, pbrt-v4 at each rung, RUNS times, run i
# with seed i; median time); the error of each rung is the RMSE against
# that renderer's reference, over the RUNS seeds (root mean square), divided
# by the reference's mean (so the renderers' different units and exposures
# compare).  Several seeds matter where a few pixels carry the error (the
# sky case's small bright emitter: its antialiased edge pixels).  bench/peers/eq_report.py fits e^2 = a/spp
# and t = t0 + b spp and reports the time each renderer needs to reach a
# common relative RMSE (TARGET), its efficiency 1/(RMSE^2 t) and the ratios.
# The scenes are scenes/bench/plane-spheres[-CASE].pbrt, sky.pbrt and
# room.pbrt at RES (default 160x106, a quarter of the paths/s benchmark's
# 640x426 each way, same film; the framing follows the pixel aspect, 1.509
# instead of 1.502, the same for every renderer) so that 2048-spp
# references, 16x the top rung of the ladder, fit with all seven cases in
# about 15 minutes on 2 quiet cores.
#   bash bench/peers/equal_quality.sh [CASE...]
# CASE as in cycles_vs_lensfield.sh (default: pinhole thinlens motion rolling
# fisheye sky room, plus realistic when PBRT is set; fisheye-lens and
# fisheye-poly on request).
# Environment: BUILD (build), PBRT, THREADS (2), RES (160x106), REF_SPP
# (2048), LADDER ("1 4 16 64 128"), RUNS (2), TARGET (0.02), OUT (out/peers-eq:
# images and measurements.tsv; re-report with
# python3 bench/peers/eq_report.py < OUT/measurements.tsv), REUSE_REFS (1:
# keep references already in OUT, e.g. after changing only the ladder).
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
res=${RES:-160x106}
w=${res%x*}; h=${res#*x}
ref_spp=${REF_SPP:-2048}
read -r -a ladder <<< "${LADDER:-1 4 16 64 128}"
runs=${RUNS:-2}
target=${TARGET:-0.02}
out=${OUT:-out/peers-eq}
cases=("$@")
if [ ${#cases[@]} -eq 0 ]; then
    cases=("${CASES_DEFAULT[@]}")
    [ -z "${PBRT:-}" ] || cases+=(realistic)
fi
top=${ladder[-1]}
[ "$ref_spp" -ge $((16 * top)) ] || echo "warning: REF_SPP $ref_spp < 16 x the top rung $top: the reference's own noise is a larger share" >&2
peers_build
mkdir -p "$out"
tsv=$out/measurements.tsv
: > "$tsv"
machine_line
peers_pbrt_note
echo "equal quality: ${w}x${h}, references $ref_spp spp (seed 1000), ladder ${ladder[*]} spp (seeds 1..$runs), $runs interleaved timing runs, $THREADS threads"

# Mean of R, G, B over the image.
img_mean() { oiiotool "$1" --ch R,G,B --printstats | sed -nE 's/.*Stats Avg: ([^(]*).*/\1/p' | awk '{printf "%.9g", ($1 + $2 + $3) / 3}'; }
# RMS difference over all pixels and R, G, B, of A*sa and B*sb.
img_rms() {
    oiiotool "$1" --ch R,G,B --mulc "${3:-1}" "$2" --ch R,G,B --mulc "${4:-1}" --sub --mulc 1000 --dup --mul --printstats |
        sed -nE 's/.*Stats Avg: ([^(]*).*/\1/p' | awk '{printf "%.9g", sqrt(($1 + $2 + $3) / 3) / 1000}'
}
render() { # RENDERER CASE SCENE SPP SEED OUT
    case $1 in
        lf) run_lf "$3" "$4" "$5" "$6" ;;
        cy) run_cy "$2" "$4" "$5" "$w" "$h" "$6" ;;
        pbrt) run_pbrt "$3" "$4" "$5" "$6" ;;
    esac
}

echo "meta	$target	$w	$h" >> "$tsv"
for c in "${cases[@]}"; do
    src=$(scene_of "$c")
    [ -f "$src" ] || { echo "no scene $src for case $c" >&2; exit 1; }
    scene=$out/$c.pbrt
    make_scene "$src" "$w" "$h" "$scene"
    rs=(lf)
    ! cycles_has "$c" || rs+=(cy)
    ! pbrt_has "$c" || rs+=(pbrt)
    if [ ${#rs[@]} -eq 1 ]; then
        echo "$c: skipped (no peer renders it: Cycles has no traced lens, and PBRT is unset)"
        continue
    fi
    for r in "${rs[@]}"; do
        ref=$out/$c-$r-ref.exr
        if [ "${REUSE_REFS:-0}" = 1 ] && [ -f "$ref" ]; then continue; fi
        t=$(render "$r" "$c" "$scene" "$ref_spp" 1000 "$ref")
        echo "$c: $r reference, $ref_spp spp, $t s" >&2
    done
    declare -A tms=()
    for i in $(seq "$runs"); do # run i renders with seed i: the error is over all runs' seeds
        for n in "${ladder[@]}"; do
            for r in "${rs[@]}"; do
                tms[$r.$n]+="$(render "$r" "$c" "$scene" "$n" "$i" "$out/$c-$r-$n-s$i.exr") "
            done
        done
    done
    for r in "${rs[@]}"; do
        ref=$out/$c-$r-ref.exr
        mean=$(img_mean "$ref")
        for n in "${ladder[@]}"; do
            t=$(tr ' ' '\n' <<< "${tms[$r.$n]}" | grep . | median)
            # RMS over the seeds: the square root of the mean squared error
            rms=$(for i in $(seq "$runs"); do img_rms "$out/$c-$r-$n-s$i.exr" "$ref"; echo; done |
                awk 'NF { s += $1 * $1; k++ } END { printf "%.9g", sqrt(s / k) }')
            printf 'rung\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$c" "$r" "$n" "$t" "$rms" "$mean" "$ref_spp" >> "$tsv"
        done
    done
    for r in "${rs[@]:1}"; do # the references side by side, each over its own mean
        a=$out/$c-lf-ref.exr; b=$out/$c-$r-ref.exr
        e=$(img_rms "$a" "$b" "$(awk -v m="$(img_mean "$a")" 'BEGIN {print 1 / m}')" "$(awk -v m="$(img_mean "$b")" 'BEGIN {print 1 / m}')")
        printf 'cross\t%s\t%s\t%s\t%s\n' "$c" lf "$r" "$e" >> "$tsv"
    done
    unset tms
done
echo
python3 bench/peers/eq_report.py < "$tsv"
echo
echo "(relative RMSE = RMSE over pixels, R, G, B and the $runs seeds against the renderer's own $ref_spp-spp reference, over the reference's mean, corrected for the reference's noise by 1/sqrt(1 + spp/$ref_spp); times are each renderer's own render time, medians of $runs; images and measurements.tsv in $out)"
