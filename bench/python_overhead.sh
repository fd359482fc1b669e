#!/usr/bin/env bash
# What a Python call costs against the CLI (issue 34, docs/python.md):
#   depth:  `lftool depth RAW -o D.pfm`  vs  lf.open(RAW).depth() + lf.write_disparity
#   render: `lfrender SCENE -o O.exr`    vs  lf.render(SCENE) + lf.write
# on a 9 x 9 camera array of 96 x 96 views rendered here, and
# scenes/demo.pbrt cropped to 96 x 64 at 16 spp; runs interleaved (CLI,
# Python, CLI, ...), medians of wall and CPU seconds (user + system, all
# threads); then the fixed cost of one binding call (a 1 x 2 light field of
# 1 x 1 views refocused).  Both sides run the same library code, so the
# difference is process start and dynamic linking (CLI) against ctypes, the
# worker thread and numpy wrapping (Python).
#   bash bench/python_overhead.sh [RUNS] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-7}
threads=${2:-2}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target lfrender lftool lensfield > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/array.pbrt" <<PBRT
LookAt 0 0 0  0 0 1  0 1 0
Camera "lightfield" "float fov" [30] "integer camerasperdim" [9 9]
    "float cameragridbounds" [-0.08 0.08 -0.08 0.08]
Film "rgb" "integer xresolution" [864] "integer yresolution" [864]
Sampler "zsobol" "integer pixelsamples" [1]
Integrator "path" "integer maxdepth" [2]
WorldBegin
Include "$PWD/scenes/lightfield/world.pbrt"
PBRT
build/bin/lfrender "$tmp/array.pbrt" --quiet -o "$tmp/array.exr"
LENSFIELD_LIBRARY=build/lib/liblensfield.so PYTHONPATH=python /usr/bin/python3 - "$tmp" "$runs" "$threads" <<'PY'
import os, resource, statistics, subprocess, sys, time
import numpy as np
import lensfield as lf

tmp, runs, threads = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
raw = f"{tmp}/array.exr"
crop = (272, 368, 181, 245)

def cli(*args):
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)

def py(fn):
    c0, t0 = time.process_time(), time.perf_counter()
    fn()
    return time.perf_counter() - t0, time.process_time() - c0

def depth_py():
    d, (d0, d1) = lf.open(raw).depth(threads=threads, return_range=True)
    lf.write_disparity(f"{tmp}/py.pfm", d, d0, d1)

def render_py():
    img, meta = lf.render("scenes/demo.pbrt", spp=16, seed=1, crop=crop, threads=threads)
    lf.write(f"{tmp}/py.exr", img, meta)

cases = {
    "depth (9x9 views of 96x96)": (
        lambda: cli("build/bin/lftool", "depth", raw, "-o", f"{tmp}/cli.pfm", "--threads", str(threads)),
        lambda: py(depth_py)),
    "render (demo, 96x64, 16 spp)": (
        lambda: cli("build/bin/lfrender", "scenes/demo.pbrt", "--spp", "16", "--seed", "1", "--quiet",
                    "--crop", *map(str, crop), "--threads", str(threads), "-o", f"{tmp}/cli.exr"),
        lambda: py(render_py)),
}
print(f"{runs} runs each, {threads} threads; medians (seconds)")
print(f"{'':30s} {'CLI wall':>9s} {'Py wall':>9s} {'ratio':>6s} {'CLI cpu':>9s} {'Py cpu':>9s}")
for name, (c, p) in cases.items():
    p()  # warm: the library's first calls (OpenEXR, Embree) load code
    cw, cc, pw, pc = [], [], [], []
    for _ in range(runs):
        w, u = c(); cw.append(w); cc.append(u)
        w, u = p(); pw.append(w); pc.append(u)
    m = statistics.median
    print(f"{name:30s} {m(cw):9.3f} {m(pw):9.3f} {m(pw) / m(cw):6.2f} {m(cc):9.3f} {m(pc):9.3f}")
# the binding's fixed cost per call
L = lf.LightField.from_array(np.ones((1, 2, 1, 1, 3), np.float32))
for _ in range(100):
    L.refocus(disparity=0)
n = 2000
t0 = time.perf_counter()
for _ in range(n):
    L.refocus(disparity=0)
print(f"one binding call (refocus of 1 x 2 views of 1 x 1 px): {(time.perf_counter() - t0) / n * 1e6:.0f} us")
PY
