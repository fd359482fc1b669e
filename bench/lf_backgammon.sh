#!/usr/bin/env bash
# Depth and view synthesis on the HCI 4D light-field benchmark scene
# "backgammon" (issue 16; results and method in docs/depth.md).
#
#   bash bench/lf_backgammon.sh [DIR]        default DIR: ../shared/lfdata/hci/backgammon
#
# Depth (lf_lightfield_depth, no range given: estimated from the data) on the 9 x 9
# views, 2 threads, median of 3 runs (wall and process CPU time); BadPix
# 0.07 / 0.03 / 0.01 and MSE x 100 against gt_disp_lowres.pfm with a 15-px
# border, as the benchmark's toolkit scores.  Views: from the 5 x 5 views
# with even indices, the 16 views with both indices odd, mean PSNR in 8-bit
# sRGB with a 15-px border.  The previous methods (82-slice focal stack,
# plane blend at disparity 0) are scored alongside (--baseline).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-../shared/lfdata/hci/backgammon}
build=${BUILD:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" --target bench_lf_backgammon > /dev/null
"$build/bin/bench_lf_backgammon" "$dir" --threads 2 --runs 3 --baseline
