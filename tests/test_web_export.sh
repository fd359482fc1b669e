#!/usr/bin/env bash
# lftool export-web end to end (docs/web.md): render a small camera-array
# light field with lfrender (5 x 5 cameras of 96 x 96, a randomly textured
# card at 1 m in front of a randomly textured wall at 3 m), export it, serve
# it with lftool serve, and drive Debian's Chromium headless, without
# network, through the page with real mouse and key events
# (tests/web/drive.js): clicks must focus where they land (a measured
# local-contrast increase, and the disparity of what was clicked), a drag
# must change parallax by what the disparities predict, and the page must
# log no errors.  Runs the WebGL 2 path, the focal-stack fallback (asked for
# with ?renderer=stack, and chosen by itself in a browser without WebGL), and
# the page over http://.  Chromium and Node are required (tools/install-deps.sh
# installs them): without them the test fails.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$(cd "${1:?usage: test_web_export.sh BUILD_BIN_DIR}" && pwd)
passed=0 failed=0
ok() { passed=$((passed + 1)); echo "ok   $*"; }
bad() { failed=$((failed + 1)); echo "FAIL $*"; }
finish() { echo "$passed passed, $failed failed"; [ "$failed" -eq 0 ]; exit; }

chromium=${LF_CHROMIUM:-$(command -v chromium || true)}
node=$(command -v node || command -v nodejs || true)
[ -n "$chromium" ] || { bad "chromium is not installed (tools/install-deps.sh installs Debian's chromium)"; finish; }
[ -n "$node" ] || { bad "node is not installed (tools/install-deps.sh installs nodejs)"; finish; }

tmp=$(mktemp -d /tmp/lf_web_XXXXXX)
server=""
cleanup() {
  if [ -n "$server" ] && kill -0 "$server" 2>/dev/null; then kill -INT "$server"; wait "$server" 2>/dev/null; fi
  rm -rf "$tmp"
}
trap cleanup EXIT

# ---- the capture: binary random textures (no repeating pattern, so image
# shifts are unambiguous), one texel about 3 px in the image at both depths
(cd "$tmp" && awk 'BEGIN { srand(7)
  for (k = 0; k < 2; k++) { n = k ? 16 : 32; f = k ? "near.pgm" : "far.pgm"
    print "P2\n" n " " n "\n255" > f
    for (i = 0; i < n * n; i++) print (rand() < 0.5 ? 40 : 230) > f } }')
cat > "$tmp/scene.pbrt" <<'SCENE'
LookAt 0 0 0  0 0 1  0 1 0
Camera "lightfield" "float fov" [30] "integer camerasperdim" [5 5]
    "float cameragridbounds" [-0.03 0.03 -0.03 0.03]
Film "rgb" "integer xresolution" [480] "integer yresolution" [480]
Sampler "zsobol" "integer pixelsamples" [16]
Integrator "path" "integer maxdepth" [1]
PixelFilter "box"
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Texture "far" "spectrum" "imagemap" "string filename" "far.pgm" "string filter" "point"
Texture "near" "spectrum" "imagemap" "string filename" "near.pgm" "string filter" "point"
AttributeBegin
  Material "diffuse" "texture reflectance" "far"
  Shape "bilinearmesh" "point3 P" [-0.96 -0.96 3  0.96 -0.96 3  -0.96 0.96 3  0.96 0.96 3]
      "point2 uv" [0 0 1 0 0 1 1 1]
AttributeEnd
AttributeBegin
  Material "diffuse" "texture reflectance" "near"
  Shape "bilinearmesh" "point3 P" [-0.30 -0.14 1  -0.02 -0.14 1  -0.30 0.14 1  -0.02 0.14 1]
      "point2 uv" [0 0 1 0 0 1 1 1]
AttributeEnd
SCENE
if (cd "$tmp" && "$bin/lfrender" scene.pbrt -o raw.exr --quiet); then ok "lfrender renders the 5x5 camera array"; else bad "lfrender"; finish; fi

# ---- export: CLI errors, then the page
"$bin/lftool" export-web "$tmp/raw.exr" > /dev/null 2>&1
[ $? -eq 2 ] && ok "export-web without -o is a usage error (2)" || bad "export-web without -o should exit 2"
"$bin/lftool" export-web "$tmp/raw.exr" -o "$tmp/x" --format exr > /dev/null 2>&1
[ $? -eq 2 ] && ok "export-web --format exr is a usage error (2)" || bad "export-web --format exr should exit 2"
if "$bin/lftool" export-web "$tmp/raw.exr" -o "$tmp/page" --format png; then ok "export-web writes the page"; else bad "export-web"; finish; fi
for f in index.html lf.js data.js; do
  [ -s "$tmp/page/$f" ] && ok "page has $f" || bad "page lacks $f"
done
n=$(ls -A "$tmp/page" | wc -l)
[ "$n" -eq 3 ] && ok "page folder holds exactly its 3 files" || bad "page folder holds $n files: $(ls -A "$tmp/page")"
if grep -Eiq '(src|href)=["'"'"']?(https?:)?//|@import|url\(["'"'"']?(https?:)?//|fetch\(' "$tmp/page/index.html" "$tmp/page/lf.js"; then
  bad "page refers to an external resource"
else
  ok "no external URLs or fetch() in index.html and lf.js"
fi
weight=$(cat "$tmp/page"/* | wc -c)
echo "     page weight $weight bytes (index.html + lf.js + data.js, PNG atlases)"

# ---- serve: 127.0.0.1 only, nothing outside the folder, stops on SIGINT
"$bin/lftool" serve "$tmp/page" --port 0 > "$tmp/serve.log" 2>&1 &
server=$!
port=""
for _ in $(seq 100); do
  port=$(sed -n 's|.*http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$tmp/serve.log")
  [ -n "$port" ] && break
  sleep 0.1
done
http() { # http PATH -> status line
  exec 3<>"/dev/tcp/127.0.0.1/$port" || return 1
  printf 'GET %s HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n' "$1" >&3
  head -n 1 <&3 | tr -d '\r'
  exec 3<&-
}
echo secret > "$tmp/outside.txt"
if [ -n "$port" ]; then
  ok "serve listens on 127.0.0.1:$port"
  [[ "$(http /)" == *" 200 "* ]] && ok "serve: / gives index.html" || bad "serve: / failed"
  [[ "$(http /data.js)" == *" 200 "* ]] && ok "serve: /data.js" || bad "serve: /data.js failed"
  [[ "$(http /nothing.js)" == *" 404 "* ]] && ok "serve: a missing file is 404" || bad "serve: missing file not 404"
  for p in /../outside.txt /%2e%2e/outside.txt /a/../../outside.txt "/..%2foutside.txt"; do
    [[ "$(http "$p")" == *" 403 "* ]] && ok "serve: $p is refused (403)" || bad "serve: $p not refused"
  done
else
  bad "serve did not start: $(cat "$tmp/serve.log")"
fi

# ---- the browser
fpx=$(awk 'BEGIN { print 48 / (sin(15 * atan2(0, -1) / 180) / cos(15 * atan2(0, -1) / 180)) }')
dnear=$(awk -v f="$fpx" 'BEGIN { print f * 0.015 / 1 }')
dfar=$(awk -v f="$fpx" 'BEGIN { print f * 0.015 / 3 }')
flags='"--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  "--disable-quic", "--no-first-run", "--no-default-browser-check", "--disable-background-networking",
  "--disable-component-update", "--disable-sync", "--disable-extensions", "--mute-audio",
  "--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1"'
runs='{"name": "webgl2", "url": "file://'$tmp'/page/index.html", "path": "webgl2|stack", "checks": "full", "bench": 20},
  {"name": "stack", "url": "file://'$tmp'/page/index.html?renderer=stack", "path": "stack", "checks": "full"},
  {"name": "no-webgl", "url": "file://'$tmp'/page/index.html", "path": "stack", "checks": "load",
   "extraFlags": ["--disable-3d-apis"]}'
[ -n "$port" ] && runs="$runs"', {"name": "http", "url": "http://127.0.0.1:'$port'/", "origin": "http://127.0.0.1:'$port'/",
  "path": "webgl2|stack", "checks": "load"}'
cat > "$tmp/drive.json" <<JSON
{"chromium": "$chromium", "userDataDir": "$tmp/profile", "timeoutSeconds": 400,
 "flags": [$flags],
 "near": {"s": 22, "t": 48, "d": $dnear}, "far": {"s": 72, "t": 48, "d": $dfar}, "radius": 10,
 "runs": [$runs]}
JSON
"$node" "$root/tests/web/drive.js" "$tmp/drive.json" | tee "$tmp/drive.log"
summary=$(tail -n 1 "$tmp/drive.log")
p=$(echo "$summary" | sed -n 's/^browser: \([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
f=$(echo "$summary" | sed -n 's/^browser: \([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
if [ -n "$p" ]; then
  passed=$((passed + p)) failed=$((failed + f))
else
  bad "the browser driver did not finish"
fi

if [ -n "$server" ]; then
  kill -INT "$server"
  wait "$server"
  rc=$?
  server=""
  [ $rc -eq 0 ] && ok "serve stops on SIGINT with exit code 0" || bad "serve exit code $rc after SIGINT"
fi
finish
