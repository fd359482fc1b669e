#!/usr/bin/env bash
# Does Cycles' fisheye frame what lensfield's traced 10 mm fisheye frames?
# Renders scenes/bench/plane-spheres-fisheye-lens.pbrt with lensfield (and its flat
# field, --white, to divide out the lens's vignetting) and the Cycles fisheye
# case twice (equisolid, the issue's model, and the polynomial fitted to the
# whole traced mapping), plus the pinhole case of both as a control; prints
# the image-circle radius and the spheres' centroids and areas of each
# (bench/peers/fisheye_framing.py), the relative RMSE between lensfield's
# vignetting-corrected image and each Cycles image (each over its own mean),
# and writes docs/images/peers-fisheye.png.
#   bash bench/peers/fisheye_framing.sh      (env: BUILD, SPP=256, RES=320x213)
set -euo pipefail
cd "$(dirname "$0")/../.."
. bench/peers/lib.sh
spp=${SPP:-256}
res=${RES:-320x213}
w=${res%x*}; h=${res#*x}
peers_build
cmake --build "$BUILD" --target lflens > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
make_scene scenes/bench/plane-spheres-fisheye-lens.pbrt "$w" "$h" "$tmp/fisheye.pbrt"
make_scene scenes/bench/plane-spheres.pbrt "$w" "$h" "$tmp/pinhole.pbrt"
run_lf "$tmp/fisheye.pbrt" "$spp" 1 "$tmp/lf.exr" > /dev/null
"$LFRENDER" "$tmp/fisheye.pbrt" --white --spp "$spp" --threads "$THREADS" -o "$tmp/white.exr" --quiet
run_cy fisheye-lens "$spp" 1 "$w" "$h" "$tmp/cy-equisolid.exr" > /dev/null
run_cy fisheye-poly "$spp" 1 "$w" "$h" "$tmp/cy-poly.exr" > /dev/null
run_lf "$tmp/pinhole.pbrt" "$spp" 1 "$tmp/lf-pinhole.exr" > /dev/null
run_cy pinhole "$spp" 1 "$w" "$h" "$tmp/cy-pinhole.exr" > /dev/null
# lensfield over its flat field; the flat field floored at 5% of its peak so
# the rim of the image circle (where both fall to 0) stays finite and dark
wmax=$(oiiotool "$tmp/white.exr" --printstats | sed -nE 's/.*Stats Max: ([^(]*).*/\1/p' | awk '{print ($1 > $2 ? ($1 > $3 ? $1 : $3) : ($2 > $3 ? $2 : $3))}')
oiiotool "$tmp/lf.exr" "$tmp/white.exr" --maxc "$(awk -v m="$wmax" 'BEGIN {print 0.05 * m}')" --div -o "$tmp/lf-flat.exr"
echo "fisheye framing, ${w}x${h}, $spp spp (predicted image circle: 26.878 mm on a $(awk -v w="$w" -v h="$h" 'BEGIN {printf "%.3f", 28 * w / sqrt(w * w + h * h)}') mm wide film = $(awk -v w="$w" -v h="$h" 'BEGIN {printf "%.1f", 13.439 / (28 * w / sqrt(w * w + h * h)) * w}') px radius)"
python3 bench/peers/fisheye_framing.py "lensfield fisheye=$tmp/lf.exr" "Cycles equisolid=$tmp/cy-equisolid.exr" \
    "Cycles polynomial=$tmp/cy-poly.exr" "lensfield pinhole=$tmp/lf-pinhole.exr" "Cycles pinhole=$tmp/cy-pinhole.exr"
mean() { oiiotool "$1" --printstats | sed -nE 's/.*Stats Avg: ([^(]*).*/\1/p' | awk '{printf "%.9g", ($1 + $2 + $3) / 3}'; }
rel() { # relative RMSE between A/mean(A) and B/mean(B)
    oiiotool "$1" --mulc "$(awk -v m="$(mean "$1")" 'BEGIN {print 1 / m}')" "$2" --mulc "$(awk -v m="$(mean "$2")" 'BEGIN {print 1 / m}')" \
        --sub --mulc 1000 --dup --mul --printstats | sed -nE 's/.*Stats Avg: ([^(]*).*/\1/p' | awk '{printf "%.4f", sqrt(($1 + $2 + $3) / 3) / 1000}'
}
echo "relative RMSE, each image over its own mean: lensfield/flat field vs Cycles equisolid $(rel "$tmp/lf-flat.exr" "$tmp/cy-equisolid.exr"), vs Cycles polynomial $(rel "$tmp/lf-flat.exr" "$tmp/cy-poly.exr"); control, pinhole lensfield vs Cycles $(rel "$tmp/lf-pinhole.exr" "$tmp/cy-pinhole.exr")"
echo "mean radiance: lensfield/flat field $(mean "$tmp/lf-flat.exr"), Cycles equisolid $(mean "$tmp/cy-equisolid.exr"), polynomial $(mean "$tmp/cy-poly.exr")"
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
panel() { # IN LABEL OUT: exposure-normalised to mean 0.5, sRGB, labelled
    local s
    s=$(awk -v m="$(mean "$1")" 'BEGIN {print 0.5 / m}')
    if [ -f "$font" ]; then
        oiiotool "$1" --mulc "$s" --colorconvert linear sRGB --text:x=6:y=16:size=13:color=1,1,1:font="$font" "$2" -d uint8 -o "$3"
    else
        oiiotool "$1" --mulc "$s" --colorconvert linear sRGB -d uint8 -o "$3"
    fi
}
panel "$tmp/lf.exr" "lensfield, traced 10 mm fisheye" "$tmp/p1.png"
panel "$tmp/lf-flat.exr" "lensfield / its flat field" "$tmp/p2.png"
panel "$tmp/cy-equisolid.exr" "Cycles equisolid 10.64 mm" "$tmp/p3.png"
panel "$tmp/cy-poly.exr" "Cycles polynomial fit" "$tmp/p4.png"
mkdir -p docs/images
oiiotool "$tmp/p1.png" "$tmp/p2.png" "$tmp/p3.png" "$tmp/p4.png" --mosaic:pad=4 2x2 -d uint8 -o docs/images/peers-fisheye.png
echo "wrote docs/images/peers-fisheye.png"
