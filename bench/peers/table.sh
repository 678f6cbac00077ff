#!/usr/bin/env bash
# Issue 12's table of ratios: every target cell run by `rastray bench
# --peers` (ours and the peer in alternation, in one run), gathered in a
# CSV and printed as a Markdown table.
#
#   rasterizer vs llvmpipe: Cornell box, the CAD-like engine
#     (assimp-testmodels' 2CylinderEngine) and a generated 1M-triangle
#     terrain, 1920x1080, 1 spp and 4 spp (ours with --shading-rate pixel,
#     llvmpipe with 4x MSAA), 1 and 2 threads;
#   ray caster vs Embree's viewer: the engine and the Cornell box at
#     1024x1024, 1 spp, 1 and 2 threads.
# Like-for-like frames: the rasterizer with --shadows none (llvmpipe draws
# no shadows); the ray caster with --lights none --max-depth 0, the work of
# the viewer's eyelight shader (one primary ray per pixel, eye light, no
# shadow, mirror or glass rays: without it the Cornell box's frame would
# also trace its 4.3 million secondary rays).
#
# Usage: bench/peers/table.sh [OUT.csv] [--quick]   (--quick: 640x480, one round)
# Environment: RASTRAY (default build/rastray), FRAMES (5), ROUNDS (3).
set -euo pipefail
cd "$(dirname "$0")/../.."

out=peers.csv
quick=0
for arg in "$@"; do
  case "$arg" in
    --quick) quick=1 ;;
    -*) echo "bench/peers/table.sh: unknown option $arg" >&2; exit 2 ;;
    *) out="$arg" ;;
  esac
done
rastray=${RASTRAY:-build/rastray}
frames=${FRAMES:-5}
rounds=${ROUNDS:-3}
size=(1920 1080)
raysize=(1024 1024)
if [ "$quick" = 1 ]; then size=(640 480); raysize=(320 320); rounds=1; fi
engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
[ -x "$rastray" ] || { echo "bench/peers/table.sh: $rastray not built (scripts/setup.sh)" >&2; exit 2; }
[ -f "$engine" ] || { echo "bench/peers/table.sh: $engine missing (Debian assimp-testmodels; scripts/setup.sh)" >&2; exit 2; }
work=${WORK_DIR:-bench-work}
rm -f "$out"

cell() {  # scene renderer spp threads W H
  local rate=() like=()
  [ "$3" -gt 1 ] && rate=(--shading-rate pixel)
  if [ "$2" = raster ]; then like=(--shadows none); else like=(--lights none --max-depth 0); fi
  echo "table: $2 $1 $5x$6 spp $3 threads $4" >&2
  "$rastray" bench "$1" --renderer "$2" --size "$5" "$6" --spp "$3" "${rate[@]}" --threads "$4" \
    "${like[@]}" --frames "$frames" --peers --rounds "$rounds" --peers-csv "$out" --work-dir "$work" >/dev/null
}

for scene in scenes/cornell-box.gltf "$engine" terrain:1000000; do
  for spp in 1 4; do
    for threads in 1 2; do cell "$scene" raster "$spp" "$threads" "${size[@]}"; done
  done
done
for scene in "$engine" scenes/cornell-box.gltf; do
  for threads in 1 2; do cell "$scene" raytrace 1 "$threads" "${raysize[@]}"; done
done

# scene,renderer,width,height,spp,threads,rastray_median_ms,rastray_cpu_ms,peer,peer_median_ms,
# peer_min_ms,peer_max_ms,peer_cpu_ms,ratio,cpu_ratio
echo "| scene | renderer | size | spp | threads | rastray ms | peer | peer ms (min–max) | ratio |"
echo "|---|---|---|---|---|---|---|---|---|"
tail -n +2 "$out" | awk -F, '{
  n = split($1, parts, "/"); scene = parts[n]
  printf "| %s | %s | %dx%d | %d | %d | %.1f | %s | %.1f (%.1f–%.1f) | %.2f× |\n",
         scene, $2, $3, $4, $5, $6, $7, $9, $10, $11, $12, $14 }'
