#!/usr/bin/env bash
# Measures an exported page (docs/web.md): page weight, time to first frame
# and frames per second of each rendering path, in headless Chromium with the
# test's flags (no GPU: WebGL runs on SwiftShader, on the CPU).
#   bash tests/web/measure.sh DIR [FRAMES]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
dir=$(cd "${1:?usage: measure.sh EXPORTED_DIR [FRAMES]}" && pwd)
frames=${2:-10}
tmp=$(mktemp -d /tmp/lf_web_measure_XXXXXX)
trap 'rm -rf "$tmp"' EXIT
echo "page weight: $(cat "$dir/index.html" "$dir/lf.js" "$dir/data.js" | wc -c) bytes" \
  "(index.html $(wc -c < "$dir/index.html"), lf.js $(wc -c < "$dir/lf.js"), data.js $(wc -c < "$dir/data.js"))"
cat > "$tmp/drive.json" <<JSON
{"chromium": "$(command -v chromium)", "userDataDir": "$tmp/profile", "timeoutSeconds": 600,
 "flags": ["--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  "--disable-quic", "--no-first-run", "--no-default-browser-check", "--disable-background-networking",
  "--disable-component-update", "--disable-sync", "--disable-extensions", "--mute-audio",
  "--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1"],
 "runs": [{"name": "webgl2", "url": "file://$dir/index.html", "path": "webgl2", "checks": "load", "bench": $frames},
          {"name": "stack", "url": "file://$dir/index.html?renderer=stack", "path": "stack", "checks": "load", "bench": $frames}]}
JSON
node "$here/drive.js" "$tmp/drive.json"
