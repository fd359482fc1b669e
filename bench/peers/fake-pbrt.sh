#!/usr/bin/env bash
# A stand-in for a pbrt-v4 binary, ONLY for smoke-testing the pbrt code path of
# bench/peers/*.sh on a machine without pbrt-v4 (it has no internet to fetch
# it): it takes the pbrt-v4 flags the scripts use (--nthreads N --spp N
# --seed S --outfile FILE SCENE.pbrt), renders with lensfield's lfrender and
# prints a pbrt-v4-style "Rendering: [+++] (T s)" progress line so the time
# parsing is exercised.  Figures measured through it are lensfield's, not
# pbrt-v4's.
#   PBRT=bench/peers/fake-pbrt.sh BUILD=build bash bench/peers/cycles_vs_lensfield.sh 1 pinhole realistic
set -euo pipefail
build=${BUILD:-build}
args=()
scene=
while [ $# -gt 0 ]; do
    case $1 in
        --nthreads) args+=(--threads "$2"); shift 2 ;;
        --spp) args+=(--spp "$2"); shift 2 ;;
        --seed) args+=(--seed "$2"); shift 2 ;;
        --outfile) args+=(-o "$2"); shift 2 ;;
        --quiet) shift ;;
        -*) echo "fake-pbrt: unsupported flag $1" >&2; exit 1 ;;
        *) scene=$1; shift ;;
    esac
done
[ -n "$scene" ] || { echo "fake-pbrt: no scene" >&2; exit 1; }
echo "pbrt version 4 (fake: bench/peers/fake-pbrt.sh running lensfield's lfrender)"
log=$("$build/bin/lfrender" "$scene" "${args[@]}" 2>&1) || { echo "$log" >&2; exit 1; }
t=$(sed -nE 's/.* camera paths in ([0-9.]+) s.*/\1/p' <<< "$log")
printf 'Rendering: [++++++++++++] (%.1fs|0.0s)  \rRendering: [++++++++++++++++++++++++] (%.1fs)       \n' "$t" "$t"
