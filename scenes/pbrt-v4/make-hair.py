#!/usr/bin/env python3
"""Writes scenes/pbrt-v4/hair.pbrt: three tufts of hair fibres, one per way
pbrt-v4's Material "hair" takes its absorption (melanin concentrations,
a reflectance colour, sigma_a).  Each fibre is a thin ribbon of triangles
with uv: u along the fibre, v across it, so the material's h = 2 v - 1
runs across the width as on pbrt's curves (on a Shape "curve" the renderer
supplies the same uv).  Usage: python3 make-hair.py"""
import math
import os
import random

random.seed(30)
SEGMENTS, STRANDS, WIDTH = 8, 45, 0.015


def strand(x0, z0, lean, length):
    pts, uvs = [], []
    for i in range(SEGMENTS + 1):
        t = i / SEGMENTS
        # rises, then droops forward (towards the camera, -z) like a comb-over
        x = x0 + lean * t * t
        y = 0.05 + length * math.sin(t * 1.2) / math.sin(1.2)
        z = z0 - 0.6 * t * t
        for side in (-1, 1):
            pts.append((x + side * WIDTH / 2, y, z))
            uvs.append((t, 0.5 + 0.5 * side))
    idx = []
    for i in range(SEGMENTS):
        a = 2 * i
        idx += [a, a + 1, a + 3, a, a + 3, a + 2]
    return pts, uvs, idx


def tuft(cx):
    P, UV, I = [], [], []
    for _ in range(STRANDS):
        r, a = 0.25 * math.sqrt(random.random()), 2 * math.pi * random.random()
        pts, uvs, idx = strand(cx + r * math.cos(a), r * math.sin(a), random.uniform(-0.3, 0.3), random.uniform(0.8, 1.1))
        base = len(P)
        P += pts
        UV += uvs
        I += [base + k for k in idx]
    return P, UV, I


def emit(f, P, UV, I):
    f.write('  Shape "trianglemesh"\n    "integer indices" [%s]\n' % " ".join(map(str, I)))
    f.write('    "point3 P" [%s]\n' % " ".join("%.3f %.3f %.3f" % p for p in P))
    f.write('    "point2 uv" [%s]\n' % " ".join("%.3f %.3f" % uv for uv in UV))


HEADER = """# lensfield example: Material "hair" (issue 30), pbrt-v4's HairBxDF
# (Chiang et al. 2016).  Written by make-hair.py.  Left: "eumelanin" 1.3
# and "pheomelanin" (brown); middle: "reflectance" (a blonde colour,
# inverted to sigma_a as pbrt-v4 does); right: "sigma_a" (dark red).
LookAt 0 0.8 -3.2   0 0.6 0   0 1 0
Camera "perspective" "float fov" [38]
Film "rgb" "integer xresolution" [360] "integer yresolution" [220]
    "string filename" "out/pbrt-v4-hair.exr"
Sampler "zsobol" "integer pixelsamples" [64]
Integrator "path" "integer maxdepth" [12]

WorldBegin

LightSource "infinite" "rgb L" [0.25 0.25 0.3]
LightSource "distant" "point3 from" [1 3 -2] "point3 to" [0 0 0] "blackbody L" [5500] "float scale" [3]

AttributeBegin
  Material "diffuse" "rgb reflectance" [0.4 0.4 0.4]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5]
AttributeEnd
"""

MATERIALS = [
    'Material "hair" "float eumelanin" [1.3] "float pheomelanin" [0.3] "float beta_m" [0.3] "float beta_n" [0.3]',
    'Material "hair" "rgb reflectance" [0.85 0.65 0.35] "float beta_m" [0.25] "float alpha" [2]',
    'Material "hair" "rgb sigma_a" [0.6 2.8 3.5] "float eta" [1.55]',
]


def main():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "hair.pbrt")
    with open(path, "w") as f:
        f.write(HEADER)
        for k, cx in enumerate((-0.9, 0.0, 0.9)):
            f.write("\nAttributeBegin\n  %s\n" % MATERIALS[k])
            emit(f, *tuft(cx))
            f.write("AttributeEnd\n")
    print("wrote", path)


if __name__ == "__main__":
    main()
