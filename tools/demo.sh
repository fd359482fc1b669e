#!/usr/bin/env bash
# Set up and run the demo: install dependencies, build, render scenes/demo.pbrt
# into out/demo.exr (linear, with metadata) and out/demo.png (tonemapped).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
mkdir -p out
build/bin/lfrender scenes/demo.pbrt -o out/demo.exr "$@"
build/bin/lfrender scenes/demo.pbrt -o out/demo.png --quiet "$@"
echo "demo: wrote out/demo.exr and out/demo.png"
