#!/usr/bin/env bash
# Renders the picture check set: 49 `--float` EXRs covering both
# renderers and hybrid, 1 to 25 spp at sample and pixel rate, deep output,
# wireframe, shadow maps and rays, transparency, the CAD engine, generated
# terrains and the stiff scenes far from the origin. A change meant to keep
# the pictures renders the set with the binary before and after it and
# compares them byte for byte (bench/compare_pictures.sh); every speed round
# of issue 20 was checked this way (docs/PERFORMANCE.md).
#
# Usage: bench/pictures.sh RASTRAY OUT_DIR
#   RASTRAY   the binary to render with (e.g. build/rastray, or a copy of
#             main's kept aside before the change)
#   OUT_DIR   where the EXRs go (NAME.exr, NAME.err: its stderr); the
#             terrains are generated once into OUT_DIR/work
# Needs the CAD engine of Debian's assimp-testmodels (scripts/setup.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ne 2 ]; then
  echo "usage: bench/pictures.sh RASTRAY OUT_DIR" >&2
  exit 2
fi
rastray=$(realpath "$1")
out=$2
mkdir -p "$out/work"
engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
# The generated terrains, written by `rastray bench terrain:N` (one frame).
terrain() {
  "$rastray" bench "terrain:$1" --size "$2" "$3" --frames 1 --work-dir "$out/work" >/dev/null
  echo "$out/work/terrain-$1-$2x$3.glb"
}
terr200k=$(terrain 200000 64 64)
terr1m=$(terrain 1000000 1920 1080)
failed=0
r() {
  local name=$1
  shift
  if ! "$rastray" render "$@" --float --threads 2 -o "$out/$name.exr" >/dev/null 2>"$out/$name.err"; then
    echo "pictures: $name failed: $(head -1 "$out/$name.err")" >&2
    failed=1
  fi
}
r c1 scenes/cornell-box.gltf --size 320 180 --spp 1 --shadows none
r c1big scenes/cornell-box.gltf --size 1920 1080 --spp 1 --shadows none
r c1m scenes/cornell-box.gltf --size 320 180 --spp 1
r c1p scenes/cornell-box.gltf --size 321 183 --spp 1 --shading-rate pixel
r c2 scenes/cornell-box.gltf --size 211 97 --spp 2 --shadows none
r c4s scenes/cornell-box.gltf --size 320 180 --spp 4
r c4p scenes/cornell-box.gltf --size 320 180 --spp 4 --shading-rate pixel
r c4pn scenes/cornell-box.gltf --size 640 360 --spp 4 --shading-rate pixel --shadows none
r c16p scenes/cornell-box.gltf --size 130 70 --spp 16 --shading-rate pixel
r vc scenes/vertex-colors.gltf --size 160 120 --spp 4
r vc1 scenes/vertex-colors.gltf --size 160 120 --spp 1
r tex scenes/textured-plane.gltf --size 160 120 --spp 4
r tl scenes/transparent-layers.gltf --size 160 120 --spp 4
r tl1 scenes/transparent-layers.gltf --size 160 120 --spp 1
r fbs scenes/floor-box-sphere.gltf --size 160 120 --spp 1
r eng "$engine" --size 320 240 --spp 1
r eng4 "$engine" --size 320 240 --spp 4 --shading-rate pixel
r terr "$terr200k" --size 480 270 --spp 1
r terr4 "$terr200k" --size 480 270 --spp 4 --shading-rate pixel
r tri scenes/three-triangles.gltf --size 97 61 --spp 4
r tri1 scenes/three-triangles.gltf --size 97 61 --spp 1
r sliver scenes/stiff/sliver-fan-aspect-1e6.gltf --size 160 120 --spp 1
r deep4 scenes/cornell-box.gltf --size 97 61 --spp 4 --deep
r deep1 scenes/cornell-box.gltf --size 97 61 --spp 1 --deep
r hyb scenes/cornell-box.gltf --size 160 120 --spp 1 --renderer hybrid
r hyb4 scenes/cornell-box.gltf --size 160 120 --spp 4 --shading-rate pixel --renderer hybrid
r rt scenes/cornell-box.gltf --size 160 120 --spp 1 --renderer raytrace
r wire scenes/cornell-box.gltf --size 130 67 --spp 4 --wireframe
r wire1 scenes/cornell-box.gltf --size 130 67 --spp 1 --wireframe
r far scenes/stiff/far-node-1e6.gltf --size 160 120 --spp 1
r graz scenes/stiff/grazing-textured-89.9.gltf --size 160 120 --spp 1
r eyel scenes/cornell-box.gltf --size 160 120 --spp 1 --lights none
r spot scenes/stiff/light-spot.gltf --size 160 120 --spp 2
r c25p scenes/cornell-box.gltf --size 97 61 --spp 25 --shading-rate pixel
r c25s scenes/cornell-box.gltf --size 97 61 --spp 25 --shadows none
r c8p scenes/cornell-box.gltf --size 200 100 --spp 8 --shading-rate pixel --shadows none
r c4pbig scenes/cornell-box.gltf --size 1920 1080 --spp 4 --shading-rate pixel --shadows none
r rtc scenes/cornell-box.gltf --size 200 150 --spp 1 --renderer raytrace
r rtc4 scenes/cornell-box.gltf --size 160 120 --spp 4 --renderer raytrace
r hybm scenes/cornell-box.gltf --size 200 150 --spp 1 --renderer hybrid
r rtfar scenes/stiff/far-node-1e6.gltf --size 160 120 --spp 1 --renderer raytrace
r hybfar scenes/stiff/far-node-1e6.gltf --size 160 120 --spp 1 --renderer hybrid
r rtspot scenes/stiff/light-spot.gltf --size 160 120 --spp 2 --renderer raytrace
r rttl scenes/transparent-layers.gltf --size 160 120 --spp 4 --renderer raytrace
r rtfbs scenes/floor-box-sphere.gltf --size 160 120 --spp 1 --renderer raytrace
r cm1024 scenes/cornell-box.gltf --size 320 240 --spp 1 --shadow-map-size 1024
r cm2048 scenes/cornell-box.gltf --size 320 240 --spp 1 --shadow-map-size 2048
r fbsm scenes/floor-box-sphere.gltf --size 160 120 --spp 1 --shadow-map-size 2048
r terr1m "$terr1m" --size 960 540 --spp 1
exit $failed
