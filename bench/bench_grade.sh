#!/usr/bin/env bash
# Grading time per submission with references cached (docs/grading.md).
# Builds one correct submission per assignment (seed 3), grades each once
# with an empty cache (references rendered) and then N times with the cache
# warm, and prints the median warm wall time of the whole lfgrade process and
# the grader's own time for the submission (the progress line's figure: what
# each further submission of a batch costs).
#   bash bench/bench_grade.sh [BUILD_DIR] [N]
set -euo pipefail
B=${1:-build}/bin
N=${2:-5}
W=$(mktemp -d /tmp/lf_bench_grade.XXXXXX)
trap 'rm -rf "$W"' EXIT
root=$(pwd)
render() { "$B/lfrender" "$root/assignments/$1" -o "$2" --seed 3 --quiet --threads 2; }
mkdir -p "$W"/{1,2,3,4}
render 1-thinlens/scenes/bokeh.pbrt "$W/1/bokeh.png"; render 1-thinlens/scenes/flatfield.pbrt "$W/1/flatfield.exr"
printf '## Answers\nx\n## Commands\nlfrender\n' > "$W/1/Submission.md"
render 2-realistic/scenes/dgauss.pbrt "$W/2/dgauss.png"; render 2-realistic/scenes/fisheye.pbrt "$W/2/fisheye.png"
printf '## Answers\nx\n## Autofocus\nfilm_distance_mm = 41.1\n## Commands\nlfrender\n' > "$W/2/Submission.md"
render 3-motion/scenes/blur.pbrt "$W/3/blur.png"; render 3-motion/scenes/rolling.pbrt "$W/3/rolling.png"
printf '## Answers\nx\n## Commands\nlfrender\n' > "$W/3/Submission.md"
render 4-lightfield/scenes/lightfield.pbrt "$W/4/lightfield.exr"
render 4-lightfield/scenes/plenoptic.pbrt "$W/4/plenoptic.exr"
SYN="--camerapos 0.03 0.05 0 --lensradius 0.1 --focaldistance 2.5 --samplesperpixel 64 --outputdim 96 72 --outputfov 30"
"$B/lftool" synth "$W/4/lightfield.exr" "$W/4/novel.png" $SYN > /dev/null
"$B/lftool" refocus "$W/4/plenoptic.exr" --depth 0.3 -o "$W/4/refocused.png" > /dev/null
printf '## Answers\nx\n## Commands\nlftool synth lightfield.exr novel.png %s\nlftool refocus plenoptic.exr --depth 0.3 -o refocused.png\n' "$SYN" > "$W/4/Submission.md"
printf '%-14s %10s %12s %14s %8s\n' assignment "cold (s)" "warm med (s)" "in-process (s)" score
i=0
for a in 1-thinlens 2-realistic 3-motion 4-lightfield; do
  i=$((i+1))
  t0=$(date +%s.%N); "$B/lfgrade" $a "$W/$i" --cache "$W/cache" --threads 2 2> "$W/log" ; t1=$(date +%s.%N)
  cold=$(echo "$t1 - $t0" | bc)
  times=()
  for k in $(seq "$N"); do
    t0=$(date +%s.%N); "$B/lfgrade" $a "$W/$i" --cache "$W/cache" --threads 2 2> "$W/log"; t1=$(date +%s.%N)
    times+=("$(echo "$t1 - $t0" | bc)")
  done
  med=$(printf '%s\n' "${times[@]}" | sort -n | sed -n "$(( (N + 1) / 2 ))p")
  score=$(sed -n 's/.*: \([0-9]*\/[0-9]*\) .*/\1/p' "$W/log" | head -1)
  inproc=$(sed -n 's/.*, \([0-9.]*\) s)$/\1/p' "$W/log" | head -1)
  printf '%-14s %10.2f %12.3f %14s %8s\n' $a "$cold" "$med" "$inproc" "$score"
done
