#!/usr/bin/env bash
# What accuracy costs in time (issue 9; docs/accuracy.md).  Renders small
# fixed scenes with each camera model and effect at a ladder of samples per
# pixel and reports the relative RMS error against a converged reference
# (same scene and settings, high spp, another seed) against the render's CPU
# time (process CPU time of the render alone, every thread counted: robust to
# other jobs on a shared machine; set-up time is in the CSV too).
#
#   bash bench/accuracy.sh [--quick]        BUILD=build-acc bash bench/accuracy.sh
#
# Groups (one plot panel each; each curve against its own reference unless said):
#   models        pinhole, thinlens, realistic traced and polynomial (dgauss50 scene)
#   pupil bounds  realistic traced, exit-pupil bounds on / off (wide22: 1.2% of
#                 rear-disk rays get through); both against the bounded reference
#   dispersion    dgauss100 with "bool dispersion" false / true
#   motion        the wheel with 1, 4, 16 motion segments against a 64-segment reference
#   plenoptic     pixels per microlens (16 microlenses across; resolution follows)
#   thin≈<lens>   the traced lens, and a thinlens with the lens's EFL and working
#                 f-number at its front principal plane, both against the traced
#                 reference; the thin lens after exposure normalisation
# References are cached in bench/.cache/ keyed by the scene text and settings
# (delete the folder after changing the renderer).  Output: docs/accuracy/
# accuracy.csv, accuracy.svg, summary.md (--quick: accuracy-quick.*).
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0
[ "${1:-}" = "--quick" ] && quick=1
build=${BUILD:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" --target bench_accuracy > /dev/null
helper="$build/bin/bench_accuracy"
cache=bench/.cache
mkdir -p "$cache" docs/accuracy
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

if [ $quick = 1 ]; then
  W=64; H=43; ladder="1 4 16"; ref_spp=256; suffix=-quick; thin_lenses="dgauss.50mm"
else
  W=96; H=64; ladder="1 4 16 64 256"; ref_spp=2048; suffix=; thin_lenses="dgauss.50mm dgauss.100mm telephoto.250mm wide.22mm"
fi
threads=2
csv=docs/accuracy/accuracy$suffix.csv
echo "group,curve,setting,spp,setup_cpu_s,render_cpu_s,rel_rmse" > "$csv"

# ---- scene variants ----
# with_camera SCENE CAMERA_TEXT [PRE_LOOKAT] : SCENE with its Camera statement
# replaced and the resolution set to W x H (relative paths stay valid: the
# helper parses the variant "as" the original file).
with_camera() {
  awk -v cam="$2" -v pre="${3:-}" -v w="$W" -v h="$H" '
    /^LookAt/ && pre != "" { print pre }
    /^Camera/ { skip = 1; print cam; next }
    skip && /^[A-Z]/ { skip = 0 }
    skip { next }
    { gsub(/"integer xresolution" \[[0-9]+\]/, "\"integer xresolution\" [" w "]");
      gsub(/"integer yresolution" \[[0-9]+\]/, "\"integer yresolution\" [" h "]"); print }' "$1"
}
resized() { with_camera "$1" "$(awk '/^Camera/{p=1} p&&/^Film/{exit} p' "$1")"; }

key() { { cat "$1"; echo "spp=$2 seed=$3 as=$4"; } | sha1sum | cut -c1-16; }

# reference SCENE_VARIANT AS -> path of the cached reference (rendered if missing)
reference() {
  local k; k=$(key "$1" "$ref_spp" 7919 "$2")
  local ref="$cache/ref-$k.exr"
  if [ ! -f "$ref" ]; then
    echo "  reference $(basename "$2") ($ref_spp spp) -> $ref" >&2
    "$helper" render "$1" --as "$2" --spp "$ref_spp" --seed 7919 --threads $threads -o "$ref.tmp.exr" > /dev/null
    mv "$ref.tmp.exr" "$ref"
  fi
  echo "$ref"
}

# ladder GROUP CURVE SETTING VARIANT AS REF [--normalise]: one CSV row per spp
ladder() {
  local group=$1 curve=$2 setting=$3 scene=$4 as=$5 ref=$6 norm=${7:-}
  for spp in $ladder; do
    local out="$tmp/img.exr" best="" t
    for rep in 1 2; do # the lower CPU time of two runs (same seed: same image)
      t=$("$helper" render "$scene" --as "$as" --spp "$spp" --seed 1 --threads $threads -o "$out")
      if [ -z "$best" ] || awk -v a="$t" -v b="$best" 'BEGIN { split(a, x, " "); split(b, y, " "); exit !(x[2] < y[2]) }'; then best=$t; fi
      [ $quick = 1 ] && break
    done
    local e; e=$("$helper" compare "$out" "$ref" $norm)
    read -r setup render _ <<< "$best"
    echo "$group,$curve,$setting,$spp,$setup,$render,$e" >> "$csv"
    printf '  %-14s %-26s %4s spp  %8.3f s  rel RMSE %s\n' "$group" "$curve" "$spp" "$render" "$e" >&2
  done
}

lens_cam() { # LENSFILE APERTURE FOCUS EXTRA
  printf 'Camera "realistic" "string lensfile" "../lenses/%s" "float aperturediameter" [%s] "float focusdistance" [%s] %s' "$1" "$2" "$3" "$4"
}

# ---- models: the dgauss50 scene through each camera ----
echo "models" >&2
S=scenes/realistic/dgauss50.pbrt
for model in traced polynomial; do
  with_camera $S "$(lens_cam dgauss.50mm.dat 17.1 6.13 "\"string lensmodel\" \"$model\"")" > "$tmp/m-$model.pbrt"
  ref=$(reference "$tmp/m-$model.pbrt" $S)
  ladder models "realistic $model" "$model" "$tmp/m-$model.pbrt" $S "$ref"
  [ $model = traced ] && traced_ref=$ref
done
# thin lens and pinhole with the lens's first-order data (EFL, working f/, film size)
efl=$("$helper" attr "$traced_ref" lensfield:lens_efl_mm)
wfn=$("$helper" attr "$traced_ref" lensfield:lens_working_fnumber)
fw=$(awk -v w=$W -v h=$H 'BEGIN { a = h / w; printf "%.4f", sqrt(43.27 * 43.27 / (1 + a * a)) }')
fh=$(awk -v w=$W -v h=$H -v fw="$fw" 'BEGIN { printf "%.4f", fw * h / w }')
fov=$(awk -v f="$efl" -v fh="$fh" 'BEGIN { printf "%.4f", 2 * atan2(fh / 2, f) * 180 / 3.14159265358979 }')
with_camera $S "Camera \"perspective\" \"float fov\" [$fov]" > "$tmp/m-pinhole.pbrt"
ladder models "pinhole" pinhole "$tmp/m-pinhole.pbrt" $S "$(reference "$tmp/m-pinhole.pbrt" $S)"
with_camera $S "Camera \"thinlens\" \"float focallength\" [$efl] \"float fstop\" [$wfn] \"float focusdistance\" [6.0] \"float sensorsize\" [$fw $fh]" > "$tmp/m-thin.pbrt"
ladder models "thinlens" thinlens "$tmp/m-thin.pbrt" $S "$(reference "$tmp/m-thin.pbrt" $S)"

# ---- exit-pupil bounds on / off (wide angle) ----
echo "pupil bounds" >&2
S=scenes/realistic/wide22.pbrt
cam=$(awk '/^Camera/{p=1} p&&/^Film/{exit} p' $S | tr '\n' ' ')
with_camera $S "$cam" > "$tmp/pb-on.pbrt"
with_camera $S "$cam \"bool pupilbounds\" false" > "$tmp/pb-off.pbrt"
ref=$(reference "$tmp/pb-on.pbrt" $S)
ladder "pupil bounds" "bounds on" on "$tmp/pb-on.pbrt" $S "$ref"
ladder "pupil bounds" "bounds off (rear disk)" off "$tmp/pb-off.pbrt" $S "$ref"

# ---- dispersion ----
echo "dispersion" >&2
S=scenes/realistic/dgauss100-dispersion.pbrt
for d in false true; do
  with_camera $S "$(lens_cam dgauss.100mm.dat 34.2 9.1 "\"bool dispersion\" $d")" > "$tmp/d-$d.pbrt"
  ladder dispersion "dispersion $d" "$d" "$tmp/d-$d.pbrt" $S "$(reference "$tmp/d-$d.pbrt" $S)"
done

# ---- motion segments (reference: 64 segments) ----
echo "motion" >&2
S=scenes/motion/wheel.pbrt
segs() { resized $S | sed "s/\"integer motionsegments\" \[[0-9]*\]/\"integer motionsegments\" [$1]/"; }
W0=$W; H0=$H; H=$W # the wheel is square
segs 64 > "$tmp/w64.pbrt"
ref=$(reference "$tmp/w64.pbrt" $S)
for n in 1 4 16; do
  segs $n > "$tmp/w$n.pbrt"
  ladder motion "$n segments" "$n" "$tmp/w$n.pbrt" $S "$ref"
done
W=$W0; H=$H0

# ---- plenoptic: pixels per microlens at 16 microlenses across ----
echo "plenoptic" >&2
S=scenes/lightfield/plenoptic.pbrt
for ppm in 4 8 16; do
  W=$((ppm * 16)); H=$((ppm * 16 * 2 / 3))
  resized $S | sed 's/"integer microlenses" \[[0-9]*\]/"integer microlenses" [16]/' > "$tmp/p$ppm.pbrt"
  ladder plenoptic "$ppm px/microlens" "$ppm" "$tmp/p$ppm.pbrt" $S "$(reference "$tmp/p$ppm.pbrt" $S)"
done
W=$W0; H=$H0

# ---- the thin lens as an approximation of each compound lens ----
for lens in $thin_lenses; do
  echo "thin≈$lens" >&2
  case $lens in
    dgauss.50mm) S=scenes/realistic/dgauss50.pbrt ;;
    dgauss.100mm) S=scenes/realistic/dgauss100-dispersion.pbrt ;;
    telephoto.250mm) S=scenes/realistic/telephoto250.pbrt ;;
    wide.22mm) S=scenes/realistic/wide22.pbrt ;;
  esac
  cam=$(awk '/^Camera/{p=1} p&&/^Film/{exit} p' $S | tr '\n' ' ' | sed 's/"bool dispersion" true//')
  diag=$(grep -o '"float diagonal" \[[0-9.]*\]' $S | grep -o '[0-9.]*' || echo 35)
  with_camera $S "$cam" > "$tmp/t-traced.pbrt"
  ref=$(reference "$tmp/t-traced.pbrt" $S)
  efl=$("$helper" attr "$ref" lensfield:lens_efl_mm)
  wfn=$("$helper" attr "$ref" lensfield:lens_working_fnumber)
  focus=$("$helper" attr "$ref" lensfield:focus_distance_m)
  h_mm=$("$helper" attr "$ref" lensfield:lens_front_principal_from_film_mm)
  fw=$(awk -v w=$W -v h=$H -v d="$diag" 'BEGIN { a = h / w; printf "%.4f", sqrt(d * d / (1 + a * a)) }')
  fh=$(awk -v w=$W -v h=$H -v fw="$fw" 'BEGIN { printf "%.4f", fw * h / w }')
  # the thin lens at H, focused on the same plane: object distance from H
  zo=$(awk -v D="$focus" -v s="$h_mm" 'BEGIN { printf "%.5f", D - s / 1000 }')
  shift=$(awk -v s="$h_mm" 'BEGIN { printf "%.5f", s / 1000 }')
  with_camera $S "Camera \"thinlens\" \"float focallength\" [$efl] \"float fstop\" [$wfn] \"float focusdistance\" [$zo] \"float sensorsize\" [$fw $fh]" "Translate 0 0 -$shift" > "$tmp/t-thin.pbrt"
  ladder "thin≈$lens" "traced $lens" traced "$tmp/t-traced.pbrt" $S "$ref"
  ladder "thin≈$lens" "thinlens f=$(printf %.1f "$efl") f/$(printf %.2f "$wfn")" thin "$tmp/t-thin.pbrt" $S "$ref" --normalise
done

svg=docs/accuracy/accuracy$suffix.svg
summary=docs/accuracy/summary$suffix.md
{
  echo "Command: \`BUILD=$build bash bench/accuracy.sh${1:+ $1}\`; $(date -u +%F), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')), load average $(cut -d' ' -f1-3 /proc/loadavg); ${W}x${H} px, spp ladder $ladder, references $ref_spp spp (seed 7919), ladder seed 1, $threads threads, render CPU time."
  echo
  "$helper" report "$csv" "$svg"
} > "$summary"
cat "$summary"
echo "wrote $csv, $svg, $summary" >&2
