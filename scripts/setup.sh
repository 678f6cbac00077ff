#!/usr/bin/env bash
# Installs every Debian package rastray's build, tests and benchmarks need
# (non-interactive, idempotent), then configures and builds into build/.
# Usage: scripts/setup.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config
  libembree-dev libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenimageio-dev openimageio-tools libopencv-core-dev libopenexr-dev
  libtbb-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  graphviz  # dot: scripts/architecture_graph.sh draws the library graph (docs/ARCHITECTURE.md)
  chromium  # the real-browser tests (crossval report, `rastray serve` page, headless), which CI must run, not skip
  libhwy-dev  # Highway: portable SIMD with run-time dispatch (shading, resolve, PNG encoding)
  libcpp-httplib-dev  # the HTTP server of `rastray serve`, the browser explorer
  curl  # the serve examples of docs/SERVE.md and README.md, run by tests/docs
  nodejs  # bench/explorer_previews.sh drives headless Chromium over the DevTools protocol
  libosmesa6-dev embree-tools  # performance peers of `rastray bench --peers`: Mesa llvmpipe, Embree's viewer
  assimp-testmodels  # real-world glTF models: the CAD-like 2CylinderEngine.glb that `rastray bench` measures
  clang libfuzzer-14-dev libclang-rt-14-dev  # scripts/fuzz.sh: libFuzzer targets (fuzz/, -DRASTRAY_FUZZ=ON) need clang
  libdraco-dev draco libmeshoptimizer-dev gltfpack  # compressed glTF: Draco and meshopt decoders; encoders make the test files
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib  # the Python module (python/) and its tests
  python3-venv python3-wheel  # `pip install ./python` into a virtual environment (docs/PYTHON.md, tests/python/test_install.py)
  povray  # an independent Whitted ray tracer: the shadow-mask comparison (docs/SHADOWS.md)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build build -j"$(nproc)"

# `import rastray` for the interpreter the module was built for: a .pth
# file in its user site-packages points at build/python (delete the file
# to undo; in a virtual environment, `pip install ./python` instead:
# docs/PYTHON.md).
if [ -f build/python/interpreter.txt ] && [ -d build/python/rastray ]; then
  python=$(cat build/python/interpreter.txt)
  site=$("$python" -c 'import site; print(site.getusersitepackages())')
  mkdir -p "$site"
  echo "$PWD/build/python" > "$site/rastray-build.pth"
  echo "setup: $python imports rastray from $PWD/build/python ($site/rastray-build.pth)" >&2
fi
