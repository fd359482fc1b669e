# Shared by bench/peers/cycles_vs_lensfield.sh and bench/peers/equal_quality.sh
# (sourced, not run).  Every run_* function renders one image and prints the
# renderer's own render time in seconds on stdout:
#   lensfield  the "N camera paths in T s" line of lfrender (the sample loop)
#   Cycles     the time of bpy.ops.render.render in cycles_plane_spheres.py
#              (scene sync, BVH build and the samples; not Blender's startup)
#   pbrt-v4    the final "(T s)" of its "Rendering:" progress bar (the sample
#              loop, printed to 0.1 s); when that is missing or under 1 s
#              (too coarse), the process wall time (which adds parsing and
#              the BVH build)
# Environment: BUILD (lensfield build directory, default build), PBRT (a
# pbrt-v4 binary; unset: no pbrt column), THREADS (default 2).

BUILD=${BUILD:-build}
THREADS=${THREADS:-2}
LFRENDER=$BUILD/bin/lfrender
CASES_ALL=(pinhole thinlens motion rolling fisheye fisheye-lens sky room realistic)
# the cases a script runs when none is named
CASES_DEFAULT=(pinhole thinlens motion rolling fisheye sky room)

# Configures the Release build and builds the named targets (default lfrender).
peers_build_targets() {
    cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
    cmake --build "$BUILD" --target "${@:-lfrender}" > /dev/null
}

peers_build() {
    command -v blender > /dev/null || { echo "blender is not installed (apt-get install blender)" >&2; exit 1; }
    peers_build_targets lfrender
    if [ -n "${PBRT:-}" ]; then
        command -v "$PBRT" > /dev/null || { echo "PBRT=$PBRT is not an executable" >&2; exit 1; }
    fi
}

# One line saying whether pbrt-v4 takes part, for the top of the output.
peers_pbrt_note() {
    if [ -n "${PBRT:-}" ]; then
        echo "pbrt-v4: $PBRT (--nthreads $THREADS)"
    else
        echo "pbrt-v4: skipped - the PBRT environment variable does not name a pbrt-v4 binary (PBRT=/path/to/pbrt to add the column and the realistic case)"
    fi
}

# Case fisheye: lensfield's ideal equisolid "fisheye" camera against Cycles'
# (like for like); fisheye-lens: the traced 10 mm fisheye prescription
# against Cycles' equisolid fisheye fitted to it; fisheye-poly: the same
# traced lens against Cycles' polynomial fisheye fitted to its whole mapping.
# sky and room: scenes/bench/sky.pbrt, scenes/bench/room.pbrt.
scene_of() {
    case $1 in
        pinhole) echo scenes/bench/plane-spheres.pbrt ;;
        fisheye-poly) echo scenes/bench/plane-spheres-fisheye-lens.pbrt ;;
        sky | room) echo "scenes/bench/$1.pbrt" ;;
        *) echo "scenes/bench/plane-spheres-$1.pbrt" ;;
    esac
}
cycles_has() { [ "$1" != realistic ]; }                      # Cycles has no traced lens
pbrt_has() { [ -n "${PBRT:-}" ] && [ "$1" != rolling ] && [ "$1" != fisheye ] && [ "$1" != fisheye-poly ]; }   # pbrt-v4 has no rolling shutter and no ideal fisheye

# Resolution of a scene file: "W H".
scene_res() {
    local w h
    w=$(sed -nE 's/.*"integer xresolution" \[ *([0-9]+) *\].*/\1/p' "$1" | head -1)
    h=$(sed -nE 's/.*"integer yresolution" \[ *([0-9]+) *\].*/\1/p' "$1" | head -1)
    echo "$w $h"
}

# make_scene SRC W H DST: a copy of SRC at W x H (the film's physical size
# unchanged, so the framing is the same), lens files by absolute path and
# float (not half) EXR output; the result is still plain pbrt-v4 syntax.
make_scene() {
    sed -E -e "s/\"integer xresolution\" \[ *[0-9]+ *\]/\"integer xresolution\" [$2]/" \
        -e "s/\"integer yresolution\" \[ *[0-9]+ *\]/\"integer yresolution\" [$3]/" \
        -e "s#\"\.\./lenses/#\"$PWD/scenes/lenses/#" \
        -e 's/^(Film "rgb")/\1 "bool savefp16" false/' "$1" > "$4"
}

# run_lf SCENE SPP SEED OUT.exr
run_lf() {
    local log
    log=$("$LFRENDER" "$1" --spp "$2" --seed "$3" --threads "$THREADS" -o "$4" 2>&1) || { echo "$log" >&2; return 1; }
    sed -nE 's/.* camera paths in ([0-9.]+) s.*/\1/p' <<< "$log"
}

# run_cy CASE SPP SEED W H OUT.exr
run_cy() {
    local log extra=()
    local c=$1
    [ "$c" != fisheye-poly ] || { extra=(--fisheye-model polynomial); c=fisheye-lens; }
    log=$(blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py -- "$2" "$THREADS" "$c" \
        --seed "$3" --res "$4" "$5" --out "$6" "${extra[@]}" 2>&1) || { echo "$log" >&2; return 1; }
    sed -nE 's/^cycles: [0-9]+ camera paths in ([0-9.]+) s.*/\1/p' <<< "$log" | grep . || { echo "$log" >&2; return 1; }
}

# run_pbrt SCENE SPP SEED OUT.exr
run_pbrt() {
    local log t0 t1 t
    t0=$(date +%s.%N)
    log=$("$PBRT" --nthreads "$THREADS" --spp "$2" --seed "$3" --outfile "$4" "$1" 2>&1) || { echo "$log" >&2; return 1; }
    t1=$(date +%s.%N)
    t=$(tr '\r' '\n' <<< "$log" | sed -nE 's/^Rendering: .*\(([0-9.]+)s\) *$/\1/p' | tail -1)
    awk -v t="${t:-0}" 'BEGIN {exit !(t >= 1)}' || t=$(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.3f", b - a}')
    echo "$t"
}

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

machine_line() {
    echo "machine: $(nproc) cores, $(sed -nE 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1), $(awk '{printf "%.0f GiB", $2/1048576}' <(grep MemTotal /proc/meminfo)); $(date -u '+%F %H:%M UTC'); load average $(cut -d' ' -f1-3 /proc/loadavg)"
}
