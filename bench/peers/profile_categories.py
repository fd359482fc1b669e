#!/usr/bin/env python3
"""Group a flat profile of lfrender into where-the-time-goes categories.
Reads `perf report --no-children --sort dso,sym --stdio` text on stdin;
each lensfield symbol is put in the category of the source file that defines
it (found by scanning the tree), other libraries by name.
  perf report -i perf.data --no-children --sort dso,sym --stdio | python3 bench/peers/profile_categories.py
"""
import os
import re
import sys
from collections import defaultdict

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
BY_FILE = [  # (path prefix, category)
    ("camera/", "camera ray generation (camera/)"),
    ("base/transform.c", "transforms (camera-to-world, base/transform.c)"),
    ("base/sampler.c", "sample generation (Owen-scrambled Sobol, base/sampler.c)"),
    ("base/filter.c", "sample generation (Owen-scrambled Sobol, base/sampler.c)"),
    ("render/scene.c", "intersection: our side (sphere test, hit setup, ray offsets; render/scene.c)"),
    ("render/integrator.c", "path integrator (render/integrator.c)"),
    ("shading/bsdf.c", "shading: BSDFs and materials"),
    ("shading/material.c", "shading: BSDFs and materials"),
    ("shading/texture.c", "shading: BSDFs and materials"),
    ("render/lights.c", "light selection and sampling (render/lights.c, base/distrib.c)"),
    ("base/distrib.c", "light selection and sampling (render/lights.c, base/distrib.c)"),
    ("render/renderer.c", "tile loop and film (render/renderer.c, with what it inlines)"),
]
ORDER = ["Embree BVH traversal (libembree3)"] + list(dict.fromkeys(c for _, c in BY_FILE)) + [
    "libm (sin, cos, exp ...)", "startup: dynamic linking (ld.so)", "kernel", "image output (zlib, OpenEXR)", "other"]
LINE = re.compile(r"^\s*([0-9.]+)%\s+(\S+)\s+\[(.)\]\s+(.+?)\s*$")


def source_index():
    idx = {}
    for d in ("base", "render", "camera", "image"):
        for name in os.listdir(os.path.join(ROOT, d)):
            if not name.endswith(".c"):
                continue
            path = f"{d}/{name}"
            with open(os.path.join(ROOT, path), errors="replace") as f:
                for line in f:  # definitions and declarations start in column 0
                    if line[:1].isalpha() or line.startswith("_"):
                        for m in re.finditer(r"\b(\w+)\s*\(", line):
                            if not m.group(1).startswith("__"):
                                idx.setdefault(m.group(1), path)
    return idx


def category(dso, sym, idx):
    if "embree" in dso:
        return "Embree BVH traversal (libembree3)"
    if dso.startswith("libm"):
        return "libm (sin, cos, exp ...)"
    if dso.startswith("ld-linux"):
        return "startup: dynamic linking (ld.so)"
    if "kernel" in dso:
        return "kernel"
    if dso.startswith("libz") or "OpenEXR" in dso:
        return "image output (zlib, OpenEXR)"
    if dso == "lfrender":
        path = idx.get(sym.split(".")[0])
        if path:
            for prefix, cat in BY_FILE:
                if path.startswith(prefix):
                    return cat
    return "other"


def main():
    idx = source_index()
    share = defaultdict(float)
    top = defaultdict(list)
    for line in sys.stdin:
        m = LINE.match(line)
        if not m:
            continue
        pct, dso, sym = float(m.group(1)), m.group(2), m.group(4)
        c = category(dso, sym, idx)
        share[c] += pct
        if not sym.startswith("0x"):
            top[c].append((pct, sym.split(".")[0]))
    print("| where | share of samples | largest symbols |")
    print("|---|---|---|")
    for c in ORDER:
        if share[c] >= 0.05:
            syms = ", ".join(f"`{s}` {p:.1f}%" for p, s in sorted(top[c], reverse=True)[:3])
            print(f"| {c} | {share[c]:.1f}% | {syms} |")


if __name__ == "__main__":
    main()
