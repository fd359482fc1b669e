#!/usr/bin/env bash
# Where the error comes from, by path depth, lensfield against Blender
# Cycles (no clock involved): the case is rendered with maximum depth D =
# 1, 2, 3, 8 (pbrt's maxdepth, Cycles' max bounces: the same paths), each
# renderer against its own reference at that depth (REF_SPP, seed 1000),
# SEEDS seeds at SPP samples.  e(D)^2 - e(D-1)^2 is the variance that the
# bounces beyond D-1 add (covariances between depths ignored), which
# separates direct lighting (D = 1: the camera ray, light sampling and the
# BSDF-sampled hits of the first vertex) from the indirect light where
# Russian roulette acts.
#   bash bench/peers/depth_split.sh [CASE]      (default pinhole)
# Environment: BUILD (build), THREADS (2), RES (160x106), REF_SPP (512),
# SPP (16), SEEDS (3), DEPTHS ("1 2 3 8"), OUT (out/peers-depth).
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
c=${1:-pinhole}
res=${RES:-160x106}
w=${res%x*}; h=${res#*x}
ref_spp=${REF_SPP:-512}
spp=${SPP:-16}
seeds=${SEEDS:-3}
out=${OUT:-out/peers-depth}
peers_build
cmake --build "$BUILD" --target bench_variance > /dev/null
BV=$BUILD/bin/bench_variance
mkdir -p "$out"
machine_line
echo "depth split, case $c: ${w}x${h}, $spp spp, $seeds seeds, references $ref_spp spp"
echo
echo "| max depth D | lensfield rel. RMSE | lensfield e(D)^2 - e(D-1)^2 | rays per path | lensfield, pbrt-v4 roulette | its e(D)^2 - e(D-1)^2 | Cycles rel. RMSE | Cycles e(D)^2 - e(D-1)^2 |"
echo "|---|---|---|---|---|---|---|---|"
pl=0; pc=0; pp=0
for d in ${DEPTHS:-1 2 3 8}; do
    make_scene "$(scene_of "$c")" "$w" "$h" "$out/$c-$d.pbrt"
    sed -i -E "s/\"integer maxdepth\" \[ *[0-9]+ *\]/\"integer maxdepth\" [$d]/" "$out/$c-$d.pbrt"
    row=$("$BV" "$out/$c-$d.pbrt" --ref-spp "$ref_spp" --spp "$spp" --seeds "$seeds" --threads "$THREADS" | tail -1)
    el=$(cut -d'|' -f3 <<< "$row" | tr -d ' '); rl=$(cut -d'|' -f6 <<< "$row" | tr -d ' ')
    sed -E 's/^(Integrator "path")/\1 "string russianroulette" "pbrt"/' "$out/$c-$d.pbrt" > "$out/$c-$d-pbrtrr.pbrt"
    ep=$("$BV" "$out/$c-$d-pbrtrr.pbrt" --ref-spp "$ref_spp" --spp "$spp" --seeds "$seeds" --threads "$THREADS" | tail -1 |
        cut -d'|' -f3 | tr -d ' ')
    cyargs=(-- "$ref_spp" "$THREADS" "$c" --seed 1000 --res "$w" "$h" --bounces "$d" --out "$out/$c-$d-cy-ref.exr")
    blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py "${cyargs[@]}" > /dev/null 2>&1
    imgs=()
    for s in $(seq "$seeds"); do
        blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py -- "$spp" "$THREADS" "$c" --seed "$s" \
            --res "$w" "$h" --bounces "$d" --out "$out/$c-$d-cy-$s.exr" > /dev/null 2>&1
        imgs+=("$out/$c-$d-cy-$s.exr")
    done
    ec=$("$BV" --rmse "$out/$c-$d-cy-ref.exr" "${imgs[@]}" |
        awk -v n="$spp" -v r="$ref_spp" '{for (i = 1; i <= NF; i++) if ($i == "RMSE") s += $(i + 1)} END {printf "%.5f", s / NR / sqrt(1 + n / r)}')
    echo "| $d | $el | $(awk -v a="$el" -v b="$pl" 'BEGIN {printf "%.6f", a * a - b * b}') | $rl | $ep | $(awk -v a="$ep" -v b="$pp" 'BEGIN {printf "%.6f", a * a - b * b}') | $ec | $(awk -v a="$ec" -v b="$pc" 'BEGIN {printf "%.6f", a * a - b * b}') |"
    pl=$el; pc=$ec; pp=$ep
done
echo
echo "(relative RMSE: mean over $seeds seeds against the renderer's own $ref_spp-spp reference at the same depth, over its mean, corrected for the reference's noise)"
