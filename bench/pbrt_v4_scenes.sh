#!/bin/bash
# bench/pbrt_v4_scenes.sh DIR [LFRENDER] - what lfrender makes of a copy of
# pbrt-v4's example scenes (github.com/mmp/pbrt-v4-scenes), one markdown
# table row per scene file (a .pbrt with WorldBegin), as in the table of
# docs/scene-format.md:
#   renders                  lfrender --explain builds it
#   --allow-unsupported      only with the flag; the notes say what is dropped
#   fails                    not even then; the notes give the error
# DIR is never written: the scenes are read through a tree of symbolic
# links under a temporary folder, where the files a scene names and the
# copy lacks (meshes, textures, spectra, volumes: the repository keeps the
# big ones in Git LFS) are stubbed: a one-triangle PLY, a 2x2 image, a flat
# spectrum, lensfield's own measured BSDF (scenes/pbrt-v4/rough-gold.bsdf)
# for a .bsdf, the lens of that name from scenes/lenses (else dgauss.50mm)
# for a .dat lens file, a 2x2x2 "density" grid of 0.5 for a .nvdb (written
# by bin/pbrt_v4_stub_nvdb next to LFRENDER; without it an empty file, on
# which a nanovdb medium fails with "has no grid"), an empty Include (a
# scene whose parameters continue after an emptied Include fails to
# parse).  So a row judges the scene's text, not its data.  RENDER=1 also renders a 32x32 crop at 1 spp to check the build
# through to pixels.  Example:
#   bench/pbrt_v4_scenes.sh ~/pbrt-v4-scenes build/bin/lfrender > rows.md
set -u
src=${1:?usage: pbrt_v4_scenes.sh DIR [LFRENDER]}
lfrender=${2:-$(dirname "$0")/../build/bin/lfrender}
src=$(cd "$src" && pwd)
repo=$(cd "$(dirname "$0")/.." && pwd)
lfrender=$(cd "$(dirname "$lfrender")" && pwd)/$(basename "$lfrender")
work=$(mktemp -d "${TMPDIR:-/tmp}/pbrt_v4_scenes.XXXXXX")
[ "${KEEP:-0}" = 1 ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work/tree" "$work/stub"
cp -rs "$src/." "$work/tree/"

# stubs, made once
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$work/stub/stub.ply"
gzip -n -c "$work/stub/stub.ply" >"$work/stub/stub.ply.gz"
printf '400 1\n700 1\n' >"$work/stub/stub.spd"
printf 'Film "rgb" "integer xresolution" 2 "integer yresolution" 2\nWorldBegin\nLightSource "infinite" "rgb L" [0.5 0.5 0.5]\n' >"$work/stub/img.pbrt"
for ext in exr png pfm; do
    "$lfrender" "$work/stub/img.pbrt" -o "$work/stub/stub.$ext" --quiet >/dev/null 2>&1
done
nvdb_stub=/dev/null
if "$(dirname "$lfrender")/pbrt_v4_stub_nvdb" "$work/stub/stub.nvdb" 2>/dev/null; then nvdb_stub=$work/stub/stub.nvdb; fi
python3 - "$work/stub/stub.tga" <<'PY' 2>/dev/null
import sys
hdr = bytes([0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2, 0, 24, 0])
open(sys.argv[1], 'wb').write(hdr + bytes([128] * 12))
PY

stub_for() { # path -> the stub to link there, or nothing
    case "$1" in
    *.ply) echo "$work/stub/stub.ply" ;;
    *.ply.gz) echo "$work/stub/stub.ply.gz" ;;
    *.spd) echo "$work/stub/stub.spd" ;;
    *.exr) echo "$work/stub/stub.exr" ;;
    *.png | *.jpg | *.jpeg) echo "$work/stub/stub.png" ;;
    *.pfm) echo "$work/stub/stub.pfm" ;;
    *.tga) echo "$work/stub/stub.tga" ;;
    *.bsdf) echo "$repo/scenes/pbrt-v4/rough-gold.bsdf" ;;
    *.dat) if [ -f "$repo/scenes/lenses/$(basename "$1")" ]; then echo "$repo/scenes/lenses/$(basename "$1")"; else echo "$repo/scenes/lenses/dgauss.50mm.dat"; fi ;;
    *.nvdb) echo "$nvdb_stub" ;;
    *.pbrt | *.pbrt.gz) echo /dev/null ;;
    esac
}

# every file name the scene folders mention, stubbed where missing (names
# are looked up next to the top-level scene, as pbrt-v4 resolves them)
cd "$work/tree" || exit 1
grep -RhoE '"(string filename|string mapname|string normalmap|string lensfile|spectrum [A-Za-z_]+)"[[:space:]]*\[?[[:space:]]*"[^"]+"|^[[:space:]]*(Include|Import)[[:space:]]+"[^"]+"' \
    --include='*.pbrt' . 2>/dev/null | sed -E 's/.*"([^"]+)"$/\1/' | sort -u >"$work/names"
for d in */; do
    while read -r name; do
        case "$name" in /*) continue ;; esac
        stub=$(stub_for "$name")
        [ -n "$stub" ] || continue
        if [ ! -e "$d$name" ]; then
            mkdir -p "$(dirname "$d$name")"
            if [ "$stub" = /dev/null ]; then : >"$d$name"; else cp "$stub" "$d$name"; fi
        fi
    done <"$work/names"
done

summary() { # a log -> the reasons, one line
    grep -E ':[0-9]+:[0-9]+: |not supported|cannot open|No such' "$1" | grep -v ' errors\? in ' | sed -E 's/^lfrender: //; s/^[^ ]*:[0-9]+:[0-9]+: (warning: )?//' |
        sed -E 's/ \(--allow-unsupported[^)]*\)//; s/; (left out|rendered as|the shape)[^;]*$//' | sort | uniq -c |
        sed -E 's/^ *([0-9]+) (.*)/\2 (x\1)/; s/ \(x1\)$//' | head -8 | paste -sd ';' | sed 's/;/; /g; s/|/\\|/g'
}

echo "| scene | status | what is dropped, or why it fails |"
echo "|---|---|---|"
find . -name '*.pbrt' | sort | while read -r f; do
    grep -q '^[[:space:]]*WorldBegin' "$f" || continue
    dir=$(dirname "$f") base=$(basename "$f")
    name=${f#./}
    extra=()
    [ "${RENDER:-0}" = 1 ] && extra=(--spp 1 --crop 0 32 0 32 -o "$work/out.exr") || extra=(--explain)
    if (cd "$dir" && "$lfrender" "$base" "${extra[@]}" --quiet) >"$work/log" 2>&1; then
        w=$(summary "$work/log")
        echo "| $name | renders | ${w} |"
    elif (cd "$dir" && "$lfrender" "$base" "${extra[@]}" --quiet --allow-unsupported) >"$work/log2" 2>&1; then
        echo "| $name | --allow-unsupported | $(summary "$work/log2") |"
    else
        echo "| $name | fails | $(summary "$work/log2") |"
    fi
done
