#!/usr/bin/env python3
"""Do two renders of the plane-and-spheres scene frame the same view?  For
each EXR: the radius of the image circle (the lit disc, pixels from the
image centre) and the centroid and area of each of the four coloured spheres
(pixels whose colour is dominated by the sphere's hue).  Plain Python: the
pixels come from `oiiotool --dumpdata`.
  python3 bench/peers/fisheye_framing.py LABEL=A.exr LABEL=B.exr ...
With --fit [LFLENS]: the traced field angle theta(r) of scenes/bench/
plane-spheres-fisheye-lens.pbrt's lens (lflens info, default build/bin/lflens),
the equisolid lens and polynomial that bench/peers/cycles_plane_spheres.py
uses for Cycles, and how far each is from the traced mapping.
"""
import math
import re
import subprocess
import sys

PIX = re.compile(r"\s*Pixel \((\d+), (\d+)\):\s*(\S+) (\S+) (\S+)")
# (name, test on r, g, b): ratios well beyond the sky's (0.35, 0.5, 0.8)
SPHERES = [("red", lambda r, g, b: r > 2.5 * g and r > 2.5 * b),
           ("green", lambda r, g, b: g > 2.5 * r and g > 2.5 * b),
           ("blue", lambda r, g, b: b > 3.0 * r and b > 2.5 * g),
           ("yellow", lambda r, g, b: r > 2.5 * b and g > 2.5 * b and 0.7 < r / max(g, 1e-9) < 1.4)]


def load(path):
    out = subprocess.run(["oiiotool", "--dumpdata", path], capture_output=True, text=True, check=True).stdout
    px, w, h = [], 0, 0
    for line in out.splitlines():
        m = PIX.match(line)
        if m:
            x, y = int(m[1]), int(m[2])
            px.append((x, y, float(m[3]), float(m[4]), float(m[5])))
            w, h = max(w, x + 1), max(h, y + 1)
    return w, h, px


def measure(path):
    w, h, px = load(path)
    cx, cy = w / 2, h / 2
    dark = min((math.hypot(x + 0.5 - cx, y + 0.5 - cy) for x, y, r, g, b in px if r + g + b <= 0), default=None)
    acc = {n: [0, 0.0, 0.0] for n, _ in SPHERES}
    for x, y, r, g, b in px:
        if r + g + b <= 0:
            continue
        for n, test in SPHERES:
            if test(r, g, b):
                a = acc[n]
                a[0] += 1
                a[1] += x + 0.5
                a[2] += y + 0.5
    return w, h, dark, {n: (a[0], a[1] / a[0], a[2] / a[0]) if a[0] else (0, 0, 0) for n, a in acc.items()}


def solve(a, b):
    n = len(b)
    m = [row[:] + [v] for row, v in zip(a, b)]
    for c in range(n):
        p = max(range(c, n), key=lambda k: abs(m[k][c]))
        m[c], m[p] = m[p], m[c]
        for k in range(n):
            if k != c:
                f = m[k][c] / m[c][c]
                m[k] = [x - f * y for x, y in zip(m[k], m[c])]
    return [m[i][n] / m[i][i] for i in range(n)]


def fit(lflens):
    import json
    film_w = 28.0 * 640 / math.hypot(640, 426)

    def theta(r):  # half the traced horizontal field of a 3:2 film r mm half-wide
        out = subprocess.run([lflens, "info", "scenes/lenses/fisheye.10mm.dat", "--aperture", "2", "--focus", "6",
                              "--diagonal", str(2 * r * math.sqrt(13) / 3), "--json"],
                             capture_output=True, text=True, check=True).stdout
        return math.radians(json.loads(out)["fov_traced_deg"][0] / 2), json.loads(out)["image_circle_mm"]

    pts = [(r, theta(r)[0]) for r in [0.5 * i for i in range(1, 27)] + [13.43]]
    circle_r = theta(13.43)[1] / 2  # a film wider than the circle
    th_w = theta(film_w / 2)[0]
    f = (film_w / 2) / (2 * math.sin(th_w / 2))
    fov = 4 * math.asin(circle_r / (2 * f))
    k = solve([[sum(r ** (i + j + 2) for r, _ in pts) for j in range(4)] for i in range(4)],
              [sum(r ** (i + 1) * t for r, t in pts) for i in range(4)])
    poly = lambda r: sum(k[i] * r ** (i + 1) for i in range(4))
    equi = lambda r: 2 * math.asin(min(1.0, r / (2 * f)))
    print(f"film {film_w:.3f} mm wide; image circle {2 * circle_r:.3f} mm; theta at the half width {math.degrees(th_w):.2f} deg")
    print("r mm: traced theta deg, r/theta mm (equidistant f), equisolid theta deg, polynomial theta deg")
    for r, t in pts[1::2]:
        print(f"  {r:5.2f}: {math.degrees(t):7.3f} {r / t:7.4f} {math.degrees(equi(r)):7.3f} {math.degrees(poly(r)):7.3f}")
    print(f"equisolid: f {f:.3f} mm, field {math.degrees(fov):.2f} deg; largest difference "
          f"{max(abs(math.degrees(equi(r) - t)) for r, t in pts):.2f} deg")
    print(f"polynomial (theta = k1 r + ... + k4 r^4): k = {', '.join(f'{c:.6e}' for c in k)}; largest difference "
          f"{max(abs(math.degrees(poly(r) - t)) for r, t in pts):.3f} deg")


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--fit":
        fit(sys.argv[2] if len(sys.argv) > 2 else "build/bin/lflens")
        return
    for arg in sys.argv[1:]:
        label, _, path = arg.partition("=")
        w, h, dark, sph = measure(path)
        circle = f"image circle radius {dark:.1f} px" if dark is not None else "no dark corners"
        print(f"{label}: {w}x{h}, {circle} (corner at {math.hypot(w / 2, h / 2):.1f} px)")
        print("  spheres (centroid x, y in px; area in px): " +
              "; ".join(f"{n} {c[1]:.1f}, {c[2]:.1f}, {c[0]}" for n, c in sph.items()))


if __name__ == "__main__":
    main()
