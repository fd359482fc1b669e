#!/usr/bin/env bash
# The depth failure-mode benchmark (issue 28; docs/depth.md, "Failure-mode
# benchmark"): light fields rendered by lfrender with exact ground truth,
# each aimed at one way depth estimation fails, scored as the HCI 4D
# light-field benchmark scores.
#
#   bash bench/depth/run.sh [--split tune|heldout|all] [--scenes A,B,...]
#                           [--given-range] [--render-only]
#
# For each scene of bench/depth/split.txt (default: all of them):
#  1. render (cached): lfrender bench/depth/scenes/NAME.pbrt --aov disparity,
#     then lftool decode --layout hci (8-bit sRGB views, parameters.cfg,
#     gt_disp_lowres.pfm), then the scene's "# post:" lines (below).  The
#     cache is OUT/cache/NAME-HASH, HASH the sha1 of the scene file and
#     the files it includes (comments left out, "# post:" lines kept), the
#     textures they read and this script's post version, so a second run
#     only estimates depth.
#  2. `lftool depth DIR -o d.pfm` with no flags (2 threads; DEPTH_FLAGS in
#     the environment are added, e.g. DEPTH_FLAGS=--noisy), timed (wall).
#     The decoded parameters.cfg's disp_min/disp_max (the ground truth's
#     range) are left out, so lftool estimates the range from the views as
#     for any capture without metadata; --given-range keeps them, as the
#     HCI benchmark's folders give them.
#  3. bench/depth/depth_score.c: BadPix 0.07 / 0.03 / 0.01 and MSE x 100
#     over the image minus a 15-px border, the 1st..99th percentile of the
#     estimate and the truth, and OUT/run/NAME/{err,bad,disp}.png.
# Prints the per-scene table and the means of each split (also written to
# OUT/table.md).  OUT = out/depthbench (gitignored), BUILD = build.
#
# Scene post-processing, lines in the scene file's header:
#   # post: noise SIGMA   Gaussian noise of standard deviation SIGMA (in
#                         8-bit code values / 255) on every decoded view,
#                         seeded by the view index (oiiotool --noise)
#   # post: vignette      the outer views dimmed as a plenoptic camera's are,
#                         docs/lightfield-format.md's recipe: in 8-bit sRGB
#                         ring 3 from the centre x 0.75, ring 4 x 0.45, the 3
#                         views at each corner x 0.02 (oiiotool --mulc)
set -euo pipefail
cd "$(dirname "$0")/../.."
here=bench/depth
build=${BUILD:-build}
out=${OUT:-out/depthbench}
post_version=1
split=all scenes="" given_range=0 render_only=0
while [ $# -gt 0 ]; do
    case $1 in
    --split) split=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --given-range) given_range=1; shift ;;
    --render-only) render_only=1; shift ;;
    *) echo "usage: bash bench/depth/run.sh [--split tune|heldout|all] [--scenes A,B] [--given-range] [--render-only]" >&2
       exit 2 ;;
    esac
done
case $split in tune|heldout|all) ;; *) echo "run.sh: --split tune|heldout|all" >&2; exit 2 ;; esac

cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" --target lfrender lftool depth_score > /dev/null
bin=$build/bin

# The scene list: split.txt lines "NAME SPLIT MODE", in order.
list=()
while read -r name half mode; do
    case $name in ''|'#'*) continue ;; esac
    [ "$split" = all ] || [ "$split" = "$half" ] || continue
    if [ -n "$scenes" ]; then
        case ",$scenes," in *",$name,"*) ;; *) continue ;; esac
    fi
    list+=("$name:$half:$mode")
done < "$here/split.txt"
[ ${#list[@]} -gt 0 ] || { echo "run.sh: no scene selected" >&2; exit 2; }

# The files a scene reads: itself, its Includes and image textures (one
# level of Include, paths relative to the scene's folder).
scene_files() {
    local f=$1 dir
    dir=$(dirname "$f")
    echo "$f"
    local inc
    for inc in $(sed -n 's/^ *Include *"\([^"]*\)".*/\1/p' "$f"); do
        echo "$dir/$inc"
        sed -n 's/.*"string filename" *"\([^"]*\)".*/\1/p' "$dir/$inc" | sed "s|^|$dir/|"
    done
    sed -n 's/.*"string filename" *"\([^"]*\.png\)".*/\1/p' "$f" | sed "s|^|$dir/|"
}

render() { # NAME SCENE CACHE
    local name=$1 f=$2 cache=$3 tmp="$3.tmp"
    rm -rf "$tmp" && mkdir -p "$tmp"
    echo "rendering $name ..." >&2
    local t0=$SECONDS
    "$bin/lfrender" "$f" -o "$tmp/raw.exr" --aov disparity --quiet --threads 2
    "$bin/lftool" decode "$tmp/raw.exr" --layout hci -o "$tmp/hci" > /dev/null
    rm -f "$tmp/raw.exr" "$tmp/raw.disparity.exr"
    local n nx
    nx=$(sed -n 's/^num_cams_x *= *//p' "$tmp/hci/parameters.cfg")
    n=$((nx * nx))
    local sigma
    sigma=$(sed -n 's/^# post: noise \([0-9.]*\).*/\1/p' "$f")
    if [ -n "$sigma" ]; then
        for ((k = 0; k < n; k++)); do
            local v
            v=$(printf "%s/hci/input_Cam%03d.png" "$tmp" $k)
            oiiotool "$v" --noise:type=gaussian:stddev="$sigma":seed=$((k + 1)) -d uint8 -o "$v"
        done
    fi
    if grep -q '^# post: vignette' "$f"; then
        local c=$(((nx - 1) / 2)) i j
        for ((j = 0; j < nx; j++)); do
            for ((i = 0; i < nx; i++)); do
                local di=$((i > c ? i - c : c - i)) dj=$((j > c ? j - c : c - j)) g=""
                local ring=$((di > dj ? di : dj))
                local ci=$((i < c ? i : nx - 1 - i)) cj=$((j < c ? j : nx - 1 - j))
                if [ $((ci + cj)) -le 1 ]; then g=0.02
                elif [ $ring -ge 4 ]; then g=0.45
                elif [ $ring -eq 3 ]; then g=0.75
                fi
                [ -z "$g" ] && continue
                local v
                v=$(printf "%s/hci/input_Cam%03d.png" "$tmp" $((j * nx + i)))
                oiiotool "$v" --mulc "$g" -d uint8 -o "$v"
            done
        done
    fi
    echo "rendered $name in $((SECONDS - t0)) s" >&2
    rm -rf "$cache" && mv "$tmp" "$cache"
}

mkdir -p "$out/cache" "$out/run"
rows=()
for item in "${list[@]}"; do
    IFS=: read -r name half mode <<< "$item"
    f=$here/scenes/$name.pbrt
    [ -f "$f" ] || { echo "run.sh: $f missing" >&2; exit 1; }
    # comments do not change a render; "# post:" lines do
    hash=$( (scene_files "$f" | sort -u | while read -r g; do
        case $g in *.pbrt) grep -v '^ *#' "$g" || true; grep '^# post:' "$g" || true ;; *) cat "$g" ;; esac
    done; echo "post $post_version") | sha1sum | cut -c1-12)
    cache=$out/cache/$name-$hash
    [ -f "$cache/hci/gt_disp_lowres.pfm" ] || render "$name" "$f" "$cache"
    [ $render_only = 1 ] && continue

    # the folder lftool reads: the cached views, the cfg with or without the range
    run=$out/run/$name
    rm -rf "$run" && mkdir -p "$run/in"
    for v in "$cache"/hci/input_Cam*.png; do ln -s "$(realpath "$v")" "$run/in/"; done
    if [ $given_range = 1 ]; then
        cp "$cache/hci/parameters.cfg" "$run/in/"
    else
        grep -v '^disp_m' "$cache/hci/parameters.cfg" > "$run/in/parameters.cfg"
    fi
    nx=$(sed -n 's/^num_cams_x *= *//p' "$cache/hci/parameters.cfg")
    centre=$(printf "input_Cam%03d.png" $(((nx * nx - 1) / 2)))
    t0=$(date +%s.%N)
    # shellcheck disable=SC2086 # DEPTH_FLAGS: words, deliberately split
    "$bin/lftool" depth "$run/in" -o "$run/d.pfm" ${DEPTH_FLAGS:-} > "$run/depth.log" 2>&1 || { cat "$run/depth.log" >&2; exit 1; }
    t1=$(date +%s.%N)
    s=$("$bin/depth_score" "$run/d.pfm" "$cache/hci/gt_disp_lowres.pfm" --view "$cache/hci/$centre" \
        --error "$run/err.png" --bad "$run/bad.png" --disp "$run/disp.png")
    secs=$(echo "$t1 - $t0" | bc -l)
    rows+=("$name $half $nx $s $secs $mode")
done
[ $render_only = 1 ] && exit 0

{
    echo "| scene | split | grid | BadPix0.07 % | BadPix0.03 % | BadPix0.01 % | MSE x 100 | time s | estimate p1..p99 | truth p1..p99 | failure mode |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|"
    for r in "${rows[@]}"; do
        read -r name half nx b7 b3 b1 mse dlo dhi glo ghi secs mode <<< "$r"
        printf "| %s | %s | %sx%s | %.2f | %.2f | %.2f | %.3f | %.1f | %.2f..%.2f | %.2f..%.2f | %s |\n" \
            "$name" "$half" "$nx" "$nx" "$b7" "$b3" "$b1" "$mse" "$secs" "$dlo" "$dhi" "$glo" "$ghi" "${mode//_/ }"
    done
    echo
    for h in tune heldout; do
        printf '%s\n' "${rows[@]}" | awk -v h=$h '$2 == h { n++; b7 += $4; b3 += $5; b1 += $6; m += $7; t += $12; if ($4 > w) { w = $4; wn = $1 } }
            END { if (n) printf "mean of %s (%d scenes): BadPix0.07 %.2f %%, BadPix0.03 %.2f %%, BadPix0.01 %.2f %%, MSE x 100 %.3f, time %.1f s; worst BadPix0.07 %.2f %% (%s)\n",
                                h, n, b7 / n, b3 / n, b1 / n, m / n, t / n, w, wn }'
    done
    echo
    echo "range: $([ $given_range = 1 ] && echo "given (parameters.cfg disp_min/disp_max)" || echo "estimated by lftool (cfg range left out)"); error images in $out/run/NAME/{err,bad,disp}.png"
} | tee "$out/table.md"
