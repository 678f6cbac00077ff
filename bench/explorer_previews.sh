#!/usr/bin/env bash
# Previews per second in the explorer while the camera orbits: `rastray
# serve` on a scene, and headless Chromium opening the page with the
# self-test step orbit:MS, which holds the mouse button down and moves the
# mouse 4 CSS pixels every 16 ms through the page's own handlers for MS
# milliseconds of real time (no virtual time: bench/explorer_previews.mjs
# drives Chromium over the DevTools protocol), counting the 1-spp previews
# that reached the screen. Prints the self-test's line, e.g.
#   selftest ok: orbit 61 previews in 5.01 s: 12.2 previews/s
# Usage: bench/explorer_previews.sh [BUILD_DIR] [SCENE] [QUERY]
#   (defaults: build, scenes/cornell-box.gltf, renderer=raster&size=640,480)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
scene=${2:-scenes/cornell-box.gltf}
query=${3:-renderer=raster&size=640,480}
work=$(mktemp -d)
trap 'kill "$server" 2>/dev/null || true; wait "$server" 2>/dev/null || true; rm -rf "$work"' EXIT
"$build/rastray" serve "$scene" --port 0 >"$work/serve.out" 2>"$work/serve.err" &
server=$!
for _ in $(seq 100); do grep -q http "$work/serve.out" && break; sleep 0.1; done
url=$(grep -o 'http://[^ ]*' "$work/serve.out")
line=$(node --experimental-websocket --no-warnings bench/explorer_previews.mjs \
  "${url}?${query}&selftest=orbit:5000" "$work/profile") || {
  echo "explorer_previews: $line" >&2
  exit 1
}
echo "$line"
