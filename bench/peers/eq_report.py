#!/usr/bin/env python3
"""Tables for bench/peers/equal_quality.sh from its measurements (a TSV on
stdin; plain Python, no numpy).

Input lines, tab-separated:
  rung  CASE RENDERER SPP TIME_S RMS REF_MEAN REF_SPP   (one per ladder rung)
  cross CASE RENDERER_A RENDERER_B REL_RMSE            (references compared)
  meta  TARGET [W H]                                    (the common rel. RMSE;
                                                        the image size)

For each rung the relative error is e = RMS / REF_MEAN (RMS over all pixels
and the R, G, B channels, from idiff; REF_MEAN the reference's mean over the
same).  The ladder image and the reference come from different seeds, so
their errors add: E[e_measured^2] = e^2 + e_ref^2, and with e^2 ~ 1/N
(unbiased Monte Carlo) e_ref^2 = e^2 N / N_ref; the table shows
e = e_measured / sqrt(1 + N / N_ref).
Fits, per case and renderer, over the ladder:
  e^2 = a N^k        (least squares in log-log; k = -1 is the plain Monte
                      Carlo rate, below -1 the stratification of the Sobol
                      points still paying off at these sample counts)
  t   = t0 + b N     (least squares; t0 is the fixed cost: sync, BVH, setup)
  time to reach e = X: t0 + b N_X, N_X interpolated linearly in log e^2 vs
  log N between the two rungs that bracket X (or from the nearest two,
  marked *, when X lies outside the ladder);
  efficiency 1/(e^2 t) per rung (constant if e^2 ~ 1/t).
The summary also shows what explains each ratio: the error per sample (e at
the rung nearest 64 spp) and the camera paths per second of the fitted cost
per sample, W H / b (with W H from the meta line).
"""
import math
import sys
from collections import OrderedDict

NAMES = {"lf": "lensfield", "cy": "Cycles", "pbrt": "pbrt-v4"}


def lsq_line(xs, ys):
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    if sxx == 0:
        return my, 0.0
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    return my - b * mx, b


def main():
    rungs = OrderedDict()
    cross = []
    target = 0.02
    pixels = None
    for line in sys.stdin:
        f = line.rstrip("\n").split("\t")
        if f[0] == "rung":
            case, r, spp, t, rms, mean, nref = f[1], f[2], int(f[3]), float(f[4]), float(f[5]), float(f[6]), int(f[7])
            e = max(rms, 1e-12) / mean / math.sqrt(1 + spp / nref)
            t = max(t, 1e-3)
            rungs.setdefault(case, OrderedDict()).setdefault(r, []).append((spp, t, e))
        elif f[0] == "cross":
            cross.append((f[1], f[2], f[3], float(f[4])))
        elif f[0] == "meta":
            target = float(f[1])
            if len(f) >= 4:
                pixels = int(f[2]) * int(f[3])

    print("| case | renderer | spp | time s | rel. RMSE | 1/(RMSE^2 t) |")
    print("|---|---|---|---|---|---|")
    fits = OrderedDict()
    for case, by_r in rungs.items():
        for r, pts in by_r.items():
            pts.sort()
            for spp, t, e in pts:
                print(f"| {case} | {NAMES.get(r, r)} | {spp} | {t:.3f} | {e:.4f} | {1 / (e * e * t):.0f} |")
            ns = [p[0] for p in pts]
            es2 = [p[2] ** 2 for p in pts]
            la, k = lsq_line([math.log(n) for n in ns], [math.log(e2) for e2 in es2])
            t0, b = lsq_line(ns, [p[1] for p in pts])
            if t0 < 0 or b <= 0:  # noise: fall back to a line through the origin
                t0, b = 0.0, sum(p[0] * p[1] for p in pts) / sum(n * n for n in ns)
            lx = math.log(target ** 2)
            seg = next((i for i in range(len(pts) - 1) if math.log(es2[i + 1]) <= lx), len(pts) - 2)
            x0, x1 = math.log(ns[seg]), math.log(ns[seg + 1])
            y0, y1 = math.log(es2[seg]), math.log(es2[seg + 1])
            n_x = math.exp(x0 + (lx - y0) * (x1 - x0) / (y1 - y0)) if y1 < y0 else float("inf")
            top = pts[-1]
            mid = min(pts, key=lambda p: abs(math.log(p[0] / 64)))
            fits.setdefault(case, OrderedDict())[r] = dict(
                slope=k, n_x=n_x, t_x=t0 + b * n_x, extrapolated=not (ns[0] <= n_x <= ns[-1]),
                eff_top=1 / (top[2] ** 2 * top[1]), e_mid=mid[2], n_mid=mid[0],
                mpaths=pixels / b / 1e6 if pixels else None)
    print()
    peers = [r for r in ("cy", "pbrt") if any(r in f for f in fits.values())]
    hdr = f"| case | lensfield: spp, s to rel. RMSE {target:g} | 1/(RMSE^2 t) at top rung |"
    sep = "|---|---|---|"
    for r in peers:
        hdr += f" {NAMES[r]}: spp, s to {target:g} | 1/(RMSE^2 t) at top rung | lensfield speed-up ({NAMES[r]} time / lensfield time) |"
        sep += "---|---|---|"
    hdr += " slope k of log RMSE^2 vs log spp |"
    sep += "---|"
    print(hdr)
    print(sep)
    cell = lambda f: f"{f['n_x']:.0f}, {f['t_x']:.2f}{'*' if f['extrapolated'] else ''}"
    for case, fr in fits.items():
        lf = fr.get("lf")
        row = f"| {case} | {cell(lf)} | {lf['eff_top']:.0f} |" if lf else f"| {case} | — | — |"
        for r in peers:
            f = fr.get(r)
            if f:
                ratio = f"{f['t_x'] / lf['t_x']:.2f}" if lf else "—"
                row += f" {cell(f)} | {f['eff_top']:.0f} | {ratio} |"
            else:
                row += " — | — | — |"
        row += " " + ", ".join(f"{NAMES.get(r, r)} {f['slope']:.2f}" for r, f in fr.items()) + " |"
        print(row)
    print("(* extrapolated: outside the ladder's range of spp)")
    print()
    print("What explains each ratio: error per sample and cost per sample")
    print()
    hdr, sep = "| case | spp | lensfield rel. RMSE |", "|---|---|---|"
    for r in peers:
        hdr += f" {NAMES[r]} rel. RMSE | lensfield error / {NAMES[r]} error |"
        sep += "---|---|"
    if pixels:
        hdr += " lensfield M paths/s |"
        sep += "---|"
        for r in peers:
            hdr += f" {NAMES[r]} M paths/s | lensfield / {NAMES[r]} paths/s |"
            sep += "---|---|"
    print(hdr)
    print(sep)
    for case, fr in fits.items():
        lf = fr.get("lf")
        if not lf:
            continue
        row = f"| {case} | {lf['n_mid']} | {lf['e_mid']:.4f} |"
        for r in peers:
            f = fr.get(r)
            row += f" {f['e_mid']:.4f} | {lf['e_mid'] / f['e_mid']:.2f} |" if f else " — | — |"
        if pixels:
            row += f" {lf['mpaths']:.2f} |"
            for r in peers:
                f = fr.get(r)
                row += f" {f['mpaths']:.2f} | {lf['mpaths'] / f['mpaths']:.2f} |" if f else " — | — |"
        print(row)
    if pixels:
        print("(paths/s from the fitted cost per sample over the ladder, start-up and BVH build excluded)")
    if cross:
        print()
        print("References side by side (each divided by its own mean): relative RMSE between them")
        for case, ra, rb, e in cross:
            print(f"  {case}: {NAMES.get(ra, ra)} vs {NAMES.get(rb, rb)} {e:.4f}")


if __name__ == "__main__":
    main()
