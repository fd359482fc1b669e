#!/usr/bin/env bash
# Set up and run the demo: install dependencies, build, render scenes/demo.pbrt
# into out/demo.exr (linear, with metadata) and out/demo.png (tonemapped).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
mkdir -p out
# Rendered once, as a mergeable part (exact sums); `lfrender merge` writes
# both formats from it, bit for bit what a render to each would give.
build/bin/lfrender scenes/demo.pbrt --part -o out/demo.part.exr "$@"
build/bin/lfrender merge out/demo.part.exr -o out/demo.exr
build/bin/lfrender merge out/demo.part.exr -o out/demo.png
rm -f out/demo.part.exr
echo "demo: wrote out/demo.exr and out/demo.png"
