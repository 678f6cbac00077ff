#!/usr/bin/env bash
# Draws the library graph of docs/ARCHITECTURE.md from the CMake build as
# it is: `cmake --graphviz` lists each target and the targets it links,
# `dot` (Debian graphviz, installed by scripts/setup.sh) lays it out.
# Usage: scripts/architecture_graph.sh [OUT.svg]   (default docs/images/architecture.svg)
# Configures (does not build) the build tree $BUILD_DIR (default build/).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/images/architecture.svg}"
build="${BUILD_DIR:-build}"
command -v dot >/dev/null || { echo "architecture_graph: dot not found (apt-get install graphviz)" >&2; exit 2; }
mkdir -p "$build/graph"
# cmake reads the options file from the build tree.
cp scripts/architecture_graph.cmake "$build/CMakeGraphVizOptions.cmake"
cmake -S . -B "$build" --graphviz="$build/graph/rastray.dot" >/dev/null
# Top-down, the command on top: edges point from a library to what it uses.
sed -e 's/^digraph "rastray" {/digraph "rastray" {\n  rankdir=TB; node [fontname="Helvetica"];/' \
  "$build/graph/rastray.dot" >"$build/graph/rastray-top-down.dot"
dot -Tsvg "$build/graph/rastray-top-down.dot" -o "$out"
echo "architecture_graph: $out (from $build/graph/rastray.dot)"
