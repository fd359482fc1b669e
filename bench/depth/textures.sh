#!/usr/bin/env bash
# Regenerates the benchmark's image textures (bench/depth/textures/*.png,
# committed; the scenes read them): grey 128 x 128 value noise, octaves of
# uniform noise upsampled (Catmull-Rom) and averaged, fixed seeds, so the
# files are reproducible with the same OpenImageIO.  Scenes tint them with
# a "scale" texture and lower their contrast with a "mix" against a constant.
#   stone:  octaves 8, 32, 128 px  (natural texture at every scale)
#   grain:  octaves 32, 128 px     (fine texture)
#   blotch: octaves 4, 16 px       (smooth, weak texture: plaster, painted walls)
set -euo pipefail
cd "$(dirname "$0")/textures"
noise() { # OUT SEED OCTAVE... : the mean of the octaves
    local out=$1 seed=$2 n=0 args=()
    shift 2
    for s in "$@"; do
        args+=(--pattern "noise:type=uniform:min=0:max=1:seed=$seed:mono=1" "${s}x${s}" 1 --resize:filter=catmull-rom 128x128)
        [ $n = 0 ] || args+=(--add)
        n=$((n + 1)) seed=$((seed + 1))
    done
    oiiotool "${args[@]}" --mulc "$(echo "1 / $n" | bc -l)" -d uint8 -o "$out"
}
noise stone.png 1 8 32 128
noise grain.png 11 32 128
noise blotch.png 21 4 16
