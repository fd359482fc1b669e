#!/usr/bin/env bash
# Differential run of the tools: the same invocations through two builds, then
# a comparison of stdout, stderr, exit codes and every output file (images
# with `idiff -fail 0`, everything else byte for byte).  Used to show that a
# refactor changes no behaviour (issues 20 and 31):
#
#   cp -a build/bin /tmp/before-bin            # before the change
#   bash bench/differential.sh run /tmp/before-bin /tmp/diff-before
#   ... change, rebuild ...
#   bash bench/differential.sh run build/bin /tmp/diff-after
#   bash bench/differential.sh compare /tmp/diff-before /tmp/diff-after
#
# Run from anywhere; the cases run in the repository root.  Timings in the
# tools' output ("in 1.23 s") are masked before comparing.
set -uo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"

run_cases() {
  local BIN OUT
  BIN="$(cd "$1" && pwd)"; OUT="$2"
  rm -rf "$OUT"; mkdir -p "$OUT"; OUT="$(cd "$OUT" && pwd)"
  local W="$OUT/work"; mkdir -p "$W"
  cd "$ROOT" || exit 1
  # A small camera array (5x5 views of 48x40) and plenoptic raw to feed lftool.
  sed -e 's/\[9 9\]/[5 5]/' -e 's/"integer xresolution" \[4608\]/"integer xresolution" [240]/' -e 's/"integer yresolution" \[4608\]/"integer yresolution" [200]/' \
      -e 's#out/lightfield/camera-array.exr#lf.exr#' -e 's#Include "world.pbrt"#Include "'"$ROOT"'/scenes/lightfield/world.pbrt"#' \
      scenes/lightfield/camera-array.pbrt > "$W/array.pbrt"
  printf 'Film "rgb"\n' > "$W/bad1.pbrt"
  printf 'WorldBegin\nShape "sphere" "float radius" [1] "float radus" [2]\n' > "$W/bad2.pbrt"
  printf 'LookAt 0 0 5 0 0 0 0 1 0\nCamera "perspective" "float fov" [40]\nWorldBgin\n' > "$W/bad3.pbrt"
  printf 'Camera "nosuch"\nWorldBegin\n' > "$W/bad4.pbrt"
  printf 'Material "difuse"\nWorldBegin\n' > "$W/bad5.pbrt"
  local n=0
  c() {  # c NAME COMMAND...: run in $W/NAME, outputs under it
    local name="$1"; shift
    local d="$OUT/cases/$name"; mkdir -p "$d/files"
    ( cd "$ROOT" && OUTD="$d/files" W="$W" BIN="$BIN" eval "$*" ) > "$d/stdout" 2> "$d/stderr"
    echo $? > "$d/rc"
    n=$((n + 1))
  }
  local R='$BIN/lfrender' T='$BIN/lftool' L='$BIN/lflens' G='$BIN/lfgrade'
  local Q='--quiet --threads 2 --seed 7'
  for s in scenes/demo.pbrt scenes/bench/*.pbrt scenes/motion/*.pbrt scenes/realistic/*.pbrt \
           scenes/thinlens/*.pbrt scenes/media/*.pbrt scenes/spherical/*.pbrt scenes/loopsubdiv/blobs.pbrt; do
    local b; b="$(basename "$s" .pbrt)"
    c "render-$b" "$R $s -o \$OUTD/img.exr --spp 2 --crop 0 96 0 64 $Q"
    c "explain-$b" "$R $s --explain"
  done
  c render-demo-png "$R scenes/demo.pbrt -o \$OUTD/img.png --spp 1 --crop 100 200 100 180 $Q --tonemap filmic"
  c render-plenoptic "$R scenes/lightfield/plenoptic.pbrt -o \$OUTD/raw.exr --spp 1 --crop 1200 1500 800 1000 $Q"
  c render-white "$R scenes/thinlens/bokeh.pbrt -o \$OUTD/w.exr --spp 1 --crop 0 64 0 64 --white $Q"
  c render-array "$R \$W/array.pbrt -o \$W/lf.exr --spp 2 --aov disparity $Q; cp \$W/lf.exr \$W/lf.disparity.exr \$OUTD/"
  c render-tile0 "$R scenes/demo.pbrt -o \$W/p0.exr --spp 1 --crop 0 64 0 64 --tile 0/2 $Q"
  c render-tile1 "$R scenes/demo.pbrt -o \$W/p1.exr --spp 1 --crop 0 64 0 64 --tile 1/2 $Q"
  c render-merge "$R merge \$W/p0.exr \$W/p1.exr -o \$OUTD/m.exr"
  for i in 1 2 3 4 5; do c "render-bad$i" "$R \$W/bad$i.pbrt -o \$OUTD/x.exr $Q"; done
  c render-badflag "$R scenes/demo.pbrt --spp 0"
  c render-unsupported "$R \$W/bad5.pbrt -o \$OUTD/x.exr --allow-unsupported $Q"
  c render-help "$R --help"
  c tool-info "$T info \$W/lf.exr"
  c tool-decode "$T decode \$W/lf.exr -o \$OUTD/views --format exr"
  c tool-decode-hci "$T decode \$W/lf.exr -o \$OUTD/hci --layout hci"
  c tool-refocus "$T refocus \$W/lf.exr --depth 1.5 -o \$OUTD/r.exr"
  c tool-refocus-d "$T refocus \$W/lf.exr --disparity 0.5 -o \$OUTD/r.exr"
  c tool-stack "$T stack \$W/lf.exr -o \$OUTD/stack"
  c tool-depth "$T depth \$W/lf.exr -o \$OUTD/d.pfm --threads 2"
  c tool-depth-hci "$T depth \$OUTD/../../tool-decode-hci/files/hci -o \$OUTD/d.pfm --threads 2"
  c tool-view "$T view \$W/lf.exr -o \$OUTD/v.exr --u 0.5 --v -0.25 --threads 2"
  c tool-synth "$T synth \$W/lf.exr \$OUTD/s.exr --camerapos 0.01 0.005 0 --lensradius 0.01 --focaldistance 1.5 --samplesperpixel 4 --outputdim 32 32"
  c tool-web "$T export-web \$W/lf.exr -o \$OUTD/web"
  c tool-plen-info "$T info \$OUTD/../../render-plenoptic/files/raw.exr"
  c tool-bad "$T refocus \$W/nosuch.exr --depth 1 -o \$OUTD/x.exr"
  c tool-badflag "$T refocus \$W/lf.exr --dpth 1"
  for lens in scenes/lenses/*.dat; do
    local b; b="$(basename "$lens" .dat)"
    c "lens-info-$b" "$L info $lens"
    c "lens-plot-$b" "$L plot $lens -o \$OUTD/p.svg"
  done
  c lens-bad "$L info \$W/bad1.pbrt"
  c grade-help "$G --help"
  c grade-starter "$G assignments/1-thinlens assignments/1-thinlens/starter --cache \$W/cache --threads 2"
  c grade-missing "$G assignments/1-thinlens \$W/nosuch --cache \$W/cache"
  echo "differential: $n cases in $OUT"
}

mask() { sed -E -e 's/[0-9]+(\.[0-9]+)? ?(s|ms|min)\b/T/g' -e 's#/tmp/[^ :]*#PATH#g' "$1"; }

compare() {
  local A="$1" B="$2" bad=0
  for d in "$A"/cases/*/; do
    local name; name="$(basename "$d")"
    local e="$B/cases/$name"
    if [ ! -d "$e" ]; then echo "MISSING $name"; bad=$((bad + 1)); continue; fi
    cmp -s "$d/rc" "$e/rc" || { echo "RC $name: $(cat "$d/rc") -> $(cat "$e/rc")"; bad=$((bad + 1)); }
    for f in stdout stderr; do
      if ! diff -q <(mask "$d/$f") <(mask "$e/$f") > /dev/null; then
        echo "DIFF $name $f:"; diff <(mask "$d/$f") <(mask "$e/$f") | head -10; bad=$((bad + 1))
      fi
    done
    ( cd "$d/files" && find . -type f | sort ) > /tmp/diff.$$.a
    ( cd "$e/files" && find . -type f | sort ) > /tmp/diff.$$.b
    if ! cmp -s /tmp/diff.$$.a /tmp/diff.$$.b; then
      echo "FILES $name:"; diff /tmp/diff.$$.a /tmp/diff.$$.b | head; bad=$((bad + 1))
    fi
    while read -r f; do
      [ -f "$e/files/$f" ] || continue
      case "$f" in
        *.exr|*.png|*.pfm)
          idiff -fail 0 -failpercent 0 "$d/files/$f" "$e/files/$f" > /dev/null 2>&1 \
            || { echo "IMAGE $name $f"; bad=$((bad + 1)); } ;;
        *) cmp -s "$d/files/$f" "$e/files/$f" || { echo "BYTES $name $f"; bad=$((bad + 1)); } ;;
      esac
    done < /tmp/diff.$$.a
  done
  rm -f /tmp/diff.$$.a /tmp/diff.$$.b
  echo "differential: $bad differences"
  [ "$bad" -eq 0 ]
}

case "${1:-}" in
  run) run_cases "$2" "$3" ;;
  compare) compare "$2" "$3" ;;
  *) echo "usage: bash bench/differential.sh run BIN OUT | compare OUT_A OUT_B" >&2; exit 2 ;;
esac
