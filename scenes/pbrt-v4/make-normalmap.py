#!/usr/bin/env python3
"""Writes scenes/pbrt-v4/textures/domes-normal.png: a 64 x 64 tangent-space
normal map of a 2 x 2 grid of domes (spherical caps) on a flat ground, 8-bit
RGB with the usual encoding code = round(255 (n + 1) / 2); pbrt-v4 (and
lensfield) read normal maps as linear values, x along +u, y along +v (the
image's rows go down as v goes up).  Usage: python3 make-normalmap.py"""
import math
import os
import struct
import zlib

N, TILE, R = 64, 32, 12.0


def normal(px, py):
    # texel centre within its tile; y up the image = +v
    x = (px % TILE) + 0.5 - TILE / 2
    y = -((py % TILE) + 0.5 - TILE / 2)
    r2 = x * x + y * y
    if r2 >= R * R:
        return (0.0, 0.0, 1.0)
    # cap of a sphere of radius 1.4 R: flatter than a hemisphere
    rs = 1.4 * R
    z = math.sqrt(rs * rs - r2)
    n = math.sqrt(r2 + z * z)
    return (x / n, y / n, z / n)


rows = b""
for py in range(N):
    row = bytearray([0])  # filter type 0
    for px in range(N):
        for c in normal(px, py):
            row.append(max(0, min(255, round(255 * (c + 1) / 2))))
    rows += bytes(row)


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", N, N, 8, 2, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b"")
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "textures", "domes-normal.png")
with open(out, "wb") as f:
    f.write(png)
