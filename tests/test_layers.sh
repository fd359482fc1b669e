#!/usr/bin/env bash
# test_layers.sh BIN_DIR - the module layering holds (docs/design.md):
# dependencies point down, checked on the sources' includes and on what the
# tools link.
set -u
bin=$1
cd "$(dirname "$0")/.."
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAILED: $*"; }
# module -> folders it must not include from
rules=(
  "base:image camera scenefile shading render lightfield grade web tools"
  "image:camera scenefile shading render lightfield grade web tools"
  "camera:image scenefile shading render lightfield grade web tools"
  "lightfield:camera scenefile shading render grade web tools"
  "scenefile:image camera shading render lightfield grade web tools"
  "shading:camera render lightfield grade web tools"
  "render:lightfield grade web tools"
  "web:camera scenefile shading render grade tools"
  "grade:web tools"
)
for rule in "${rules[@]}"; do
  mod=${rule%%:*}
  for other in ${rule#*:}; do
    hits=$(grep -lE "#include \"(\.\./)?$other/" "$mod"/*.c "$mod"/*.h "$mod"/*.cpp 2>/dev/null)
    if [ -n "$hits" ]; then bad "$mod/ includes from $other/: $hits"; else ok; fi
  done
done
# Includes across folders are root-relative ("base/lf_error.h"), never "../".
hits=$(grep -rlE '#include "\.\./' base image camera scenefile shading render lightfield grade web tools tests bench fuzz 2>/dev/null)
if [ -n "$hits" ]; then bad "relative includes: $hits"; else ok; fi
# Libraries never print to stdout/stderr or exit (only tools/ do).
hits=$(grep -nE "\b(exit|abort)\(|\bprintf\(|fprintf\(std(out|err)|\bputs\(|perror\(" base/*.c image/*.c image/*.cpp camera/*.c scenefile/*.c shading/*.c render/*.c lightfield/*.c grade/*.c web/*.c 2>/dev/null | grep -v "^\s*//" )
if [ -n "$hits" ]; then bad "a library prints or exits: $hits"; else ok; fi
# Locations are formatted once (lf_loc_format, lf_error_at, lf_warn_at in
# base/lf_error.h), not by hand, in the renderer's folders.
hits=$(grep -n '%s:%d' scenefile/*.c shading/*.c render/*.c 2>/dev/null)
if [ -n "$hits" ]; then bad "hand-written file:line locations: $hits"; else ok; fi
# lensfield:* attribute names are spelled once, in base/lf_keys.h.
hits=$(grep -nE '"lensfield:[a-z_0-9]+"' base/*.c image/*.c image/*.cpp camera/*.c scenefile/*.c shading/*.c render/*.c lightfield/*.c grade/*.c web/*.c tools/*.c 2>/dev/null)
if [ -n "$hits" ]; then bad "attribute names spelled outside base/lf_keys.h: $hits"; else ok; fi
# The tools link only the layers they use.
for t in lflens lftool; do
  if ldd "$bin/$t" | grep -qi embree; then bad "$t links Embree"; else ok; fi
done
if ldd "$bin/lfrender" | grep -qi embree; then ok; else bad "lfrender does not link Embree?"; fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
