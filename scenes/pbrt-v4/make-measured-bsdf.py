#!/usr/bin/env python3
"""Writes scenes/pbrt-v4/rough-gold.bsdf, the measured BRDF that
measured.pbrt renders: an RGL tensor file (Dupuy & Jakob 2018, the format
pbrt-v4's MeasuredBxDF reads) holding a rough GGX conductor (alpha 0.3)
whose Fresnel reflectance rises from 0.35 at 400 nm to 0.95 at 700 nm (a
gold-like colour), tabulated as the format defines it:
f(wo, wi) = R(u) D(wm) / (4 sigma(wo) cos theta_i), R on the half-vector
grid (the vndf table is uniform, so its warp is the identity), luminance
proportional to R for importance sampling.  Usage: python3 make-measured-bsdf.py"""
import math
import os
import struct

ALPHA = 0.3
NT, NM = 5, 24
WAVELENGTHS = [360.0, 400.0, 500.0, 600.0, 700.0, 830.0]


def fresnel0(lam):
    t = min(max((lam - 400.0) / 300.0, 0.0), 1.0)
    return 0.35 + 0.6 * t


def ggx_d(c):
    if c <= 0:
        return 0.0
    c2 = c * c
    t2 = (1 - c2) / c2
    a2 = ALPHA * ALPHA
    return 1.0 / (math.pi * a2 * c2 * c2 * (1 + t2 / a2) ** 2)


def lam(c):
    c = max(c, 1e-6)
    t2 = (1 - c * c) / (c * c)
    return (-1 + math.sqrt(1 + ALPHA * ALPHA * t2)) / 2


def field(name, dtype, shape, data):
    return (name, dtype, shape, data)


def main():
    theta_i = [t * (80.0 / (NT - 1)) * math.pi / 180 for t in range(NT)]
    ndf, sigma = [], []
    for y in range(2):
        for x in range(NM):
            th = (x / (NM - 1)) ** 2 * math.pi / 2
            ndf.append(ggx_d(math.cos(th)))
            sigma.append(max(math.cos(th), 1e-6) * (1 + lam(math.cos(th))))
    vndf, lum, spectra = [], [], []
    for to in theta_i:
        wo = (math.sin(to), 0.0, math.cos(to))
        sig_o = math.cos(to) * (1 + lam(math.cos(to)))
        rows = []
        for y in range(NM):
            for x in range(NM):
                thm = (x / (NM - 1)) ** 2 * math.pi / 2
                phm = (2 * y / (NM - 1) - 1) * math.pi
                m = (math.sin(thm) * math.cos(phm), math.sin(thm) * math.sin(phm), math.cos(thm))
                d = sum(a * b for a, b in zip(wo, m))
                wiz = 2 * d * m[2] - wo[2]
                g = 0.0
                if wiz > 0 and d > 0:
                    # R = f 4 sigma(wo) cos(theta_i) / D with f = F D G2 / (4 cos_o cos_i)
                    g2 = 1.0 / (1 + lam(wo[2]) + lam(wiz))
                    g = g2 * sig_o / wo[2]
                rows.append((g, d))
        vndf += [1.0] * (NM * NM)
        lum += [r[0] + 1e-3 for r in rows]
        for lam_nm in WAVELENGTHS:
            for g, d in rows:
                f0 = fresnel0(lam_nm)
                fr = f0 + (1 - f0) * (1 - max(d, 0.0)) ** 5  # Schlick
                spectra.append(g * fr)
    desc = b"lensfield scenes/pbrt-v4: GGX 0.3 conductor, gold-like"
    fields = [
        field("description", 1, [len(desc)], desc),
        field("jacobian", 1, [1], bytes([1])),
        field("theta_i", 10, [NT], theta_i),
        field("phi_i", 10, [1], [0.0]),
        field("wavelengths", 10, [len(WAVELENGTHS)], WAVELENGTHS),
        field("ndf", 10, [2, NM], ndf),
        field("sigma", 10, [2, NM], sigma),
        field("vndf", 10, [1, NT, NM, NM], vndf),
        field("luminance", 10, [1, NT, NM, NM], lum),
        field("spectra", 10, [1, NT, len(WAVELENGTHS), NM, NM], spectra),
    ]
    blobs = [f[3] if f[1] == 1 else struct.pack("<%df" % len(f[3]), *f[3]) for f in fields]
    table = 18 + sum(2 + len(f[0]) + 2 + 1 + 8 + 8 * len(f[2]) for f in fields)
    out = bytearray(b"tensor_file\0" + bytes([1, 0]) + struct.pack("<I", len(fields)))
    offset = table
    for f, blob in zip(fields, blobs):
        out += struct.pack("<H", len(f[0])) + f[0].encode() + struct.pack("<HBQ", len(f[2]), f[1], offset)
        out += b"".join(struct.pack("<Q", s) for s in f[2])
        offset += len(blob)
    for blob in blobs:
        out += blob
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "rough-gold.bsdf")
    with open(path, "wb") as fh:
        fh.write(out)
    print("wrote %s (%d bytes)" % (path, len(out)))


if __name__ == "__main__":
    main()
