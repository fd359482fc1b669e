#!/usr/bin/env bash
# Error per sample, lensfield against Blender Cycles, with no clock involved:
# so it can be measured on a busy machine.  For each case, each renderer
# renders its own reference (REF_SPP, seed 1000) and SEEDS images at each
# spp of LADDER (seeds 1..SEEDS); the table gives the mean relative RMSE
# (RMSE over pixels and R, G, B against the renderer's own reference, over
# the reference's mean) and, for lensfield, the rays traced per camera path
# (bench_variance).  lensfield runs with its defaults and with pbrt-v4's
# Russian roulette ("string russianroulette" "pbrt", the rule before issue
# 21) for comparison.  Resolution RES as in equal_quality.sh.
#   bash bench/peers/error_per_sample.sh [CASE...]
# Environment: BUILD (build), THREADS (2), RES (160x106), REF_SPP (1024),
# LADDER ("16 64"), SEEDS (3), OUT (out/peers-eps).
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
res=${RES:-160x106}
w=${res%x*}; h=${res#*x}
ref_spp=${REF_SPP:-1024}
ladder=${LADDER:-16 64}
seeds=${SEEDS:-3}
out=${OUT:-out/peers-eps}
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=("${CASES_DEFAULT[@]}")
peers_build
cmake --build "$BUILD" --target bench_variance > /dev/null
BV=$BUILD/bin/bench_variance
mkdir -p "$out"
machine_line
echo "error per sample: ${w}x${h}, references $ref_spp spp (seed 1000), $seeds seeds per rung, $THREADS threads"
echo
echo "| case | spp | lensfield rel. RMSE | rays per path | lensfield, pbrt-v4 roulette | rays per path | Cycles rel. RMSE | Cycles / lensfield error |"
echo "|---|---|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
    src=$(scene_of "$c")
    make_scene "$src" "$w" "$h" "$out/$c.pbrt"
    sed -E 's/^(Integrator "path")/\1 "string russianroulette" "pbrt"/' "$out/$c.pbrt" > "$out/$c-pbrtrr.pbrt"
    declare -A lf=() lfr=() pb=() pbr=() cy=()
    "$BV" "$out/$c.pbrt" --ref-spp "$ref_spp" --save-ref "$out/$c-lf-ref.exr" --spp "$ladder" --seeds "$seeds" \
        --threads "$THREADS" > "$out/$c-lf.txt"
    "$BV" "$out/$c-pbrtrr.pbrt" --ref "$out/$c-lf-ref.exr" --ref-spp "$ref_spp" --spp "$ladder" --seeds "$seeds" --threads "$THREADS" \
        > "$out/$c-pbrtrr.txt"
    while IFS='|' read -r _ n e _ _ r _; do
        n=${n// /}; [[ $n =~ ^[0-9]+$ ]] || continue
        lf[$n]=${e// /}; lfr[$n]=${r// /}
    done < "$out/$c-lf.txt"
    while IFS='|' read -r _ n e _ _ r _; do
        n=${n// /}; [[ $n =~ ^[0-9]+$ ]] || continue
        pb[$n]=${e// /}; pbr[$n]=${r// /}
    done < "$out/$c-pbrtrr.txt"
    run_cy "$c" "$ref_spp" 1000 "$w" "$h" "$out/$c-cy-ref.exr" > /dev/null
    for n in $ladder; do
        imgs=()
        for s in $(seq "$seeds"); do
            run_cy "$c" "$n" "$s" "$w" "$h" "$out/$c-cy-$n-$s.exr" > /dev/null
            imgs+=("$out/$c-cy-$n-$s.exr")
        done
        # the reference's own noise adds e^2 n / ref_spp (as bench_variance corrects for lensfield)
        cy[$n]=$("$BV" --rmse "$out/$c-cy-ref.exr" "${imgs[@]}" |
            awk -v n="$n" -v r="$ref_spp" '{for (i = 1; i <= NF; i++) if ($i == "RMSE") s += $(i + 1)} END {printf "%.5f", s / NR / sqrt(1 + n / r)}')
        echo "| $c | $n | ${lf[$n]} | ${lfr[$n]} | ${pb[$n]} | ${pbr[$n]} | ${cy[$n]} | $(awk -v a="${cy[$n]}" -v b="${lf[$n]}" 'BEGIN {printf "%.2f", a / b}') |"
    done
    unset lf lfr pb pbr cy
done
echo
echo "(relative RMSE: mean over $seeds seeds of the RMSE over pixels and R, G, B against the renderer's own $ref_spp-spp reference, over its mean, corrected for the reference's noise; lensfield's with pbrt-v4 roulette is measured against lensfield's default reference)"
