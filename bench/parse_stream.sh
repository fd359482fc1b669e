#!/usr/bin/env bash
# Scene files are read as streams (issue 32): peak memory of lfrender on a
# .pbrt.gz whose one line holds 3 GB of comment, and parse speed of a 50 MB
# scene with an inline triangle mesh.  Figures and command: docs/testing.md.
#
#   bash bench/parse_stream.sh [BUILD_DIR] [OTHER_BUILD_DIR]
#
# BUILD_DIR (default build) needs bin/lfrender and bin/bench_parse; an
# OTHER_BUILD_DIR (say, a build of the commit before) is measured the same way.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dirs=("$(cd "${1:-$root/build}" && pwd)")
[ $# -lt 2 ] || dirs+=("$(cd "$2" && pwd)")
tmp=$(mktemp -d /tmp/lf_parse_stream_XXXXXX)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
python3 - <<'PY'
import struct, zlib
head = (b'LookAt 0 0 -3  0 0 0  0 1 0\nCamera "perspective"\n'
        b'Film "rgb" "integer xresolution" [16] "integer yresolution" [12]\n'
        b'Sampler "zsobol" "integer pixelsamples" [1]\nWorldBegin\n'
        b'LightSource "infinite" "rgb L" [0.5 0.5 0.5]\n')
# 3 GiB of comment on one line, as repeated full-flush deflate blocks (3 MB)
c = zlib.compressobj(9, zlib.DEFLATED, -15)
parts, crc, size = [b'\x1f\x8b\x08\x00\0\0\0\0\x00\xff'], 0, 0
def add(data, times=1):
    global crc, size
    block = c.compress(data) + c.flush(zlib.Z_FULL_FLUSH)
    for _ in range(times):
        parts.append(block); crc = zlib.crc32(data, crc); size += len(data)
add(head + b'#')
add(b' ' * (1 << 20), 3072)
add(b'\nShape "sphere"\n')
parts.append(c.flush() + struct.pack('<II', crc & 0xffffffff, size & 0xffffffff))
open('line3g.pbrt.gz', 'wb').write(b''.join(parts))
# a 50 MB scene: an 800 x 800 vertex grid inline (P, N, uv, indices)
n = 800
with open('mesh50.pbrt', 'w') as f:
    f.write(head.decode() + 'Shape "trianglemesh"\n  "point3 P" [\n')
    for j in range(n):
        f.write(' '.join('%.6f %.6f %.6f' % (i / n, j / n, 0.01 * ((i * j) % 7)) for i in range(n)) + '\n')
    f.write(']\n  "normal N" [\n')
    for j in range(n):
        f.write(' '.join('0 0 1' for i in range(n)) + '\n')
    f.write(']\n  "point2 uv" [\n')
    for j in range(n):
        f.write(' '.join('%.5f %.5f' % (i / n, j / n) for i in range(n)) + '\n')
    f.write(']\n  "integer indices" [\n')
    for j in range(n - 1):
        f.write(' '.join('%d %d %d %d %d %d' % (j * n + i, j * n + i + 1, (j + 1) * n + i + 1,
                                              j * n + i, (j + 1) * n + i + 1, (j + 1) * n + i)
                         for i in range(n - 1)) + '\n')
    f.write(']\n')
PY
ls -l line3g.pbrt.gz mesh50.pbrt | awk '{print $5, $9}'
for d in "${dirs[@]}"; do
  echo "== $d"
  /usr/bin/time -f '%M KB peak RSS, %e s' "$d/bin/lfrender" line3g.pbrt.gz --explain 2>&1 >/dev/null | tail -1 |
    sed 's/^/lfrender --explain on the 3 GiB-line .pbrt.gz (3 MB): /'
  /usr/bin/time -f '%M KB peak RSS' "$d/bin/bench_parse" mesh50.pbrt 5 2>&1
done
