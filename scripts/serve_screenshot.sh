#!/usr/bin/env bash
# Makes docs/serve.png, the README's picture of `rastray serve`: the
# explorer on the Cornell box (hybrid, 640x480, 4 spp) after a click on the
# glass sphere, through the page's own ?selftest hook, in headless Chromium.
# Usage: scripts/serve_screenshot.sh [BUILD_DIR] (default build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
work=$(mktemp -d)
trap 'kill "$server" 2>/dev/null || true; wait "$server" 2>/dev/null || true; rm -rf "$work"' EXIT
"$build/rastray" serve scenes/cornell-box.gltf scenes/transparent-layers.gltf scenes/textured-plane.gltf \
  --port 0 >"$work/serve.out" 2>"$work/serve.err" &
server=$!
for _ in $(seq 100); do grep -q http "$work/serve.out" && break; sleep 0.1; done
url=$(grep -o 'http://[^ ]*' "$work/serve.out")
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
  --disable-component-update --disable-sync --user-data-dir="$work/profile" --window-size=1500,950 \
  --hide-scrollbars --virtual-time-budget=120000 --screenshot="$PWD/docs/serve.png" \
  "${url}?renderer=hybrid&size=640,480&spp=4&selftest=click:387,349" 2>/dev/null
echo "wrote docs/serve.png"
