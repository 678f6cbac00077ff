#!/usr/bin/env bash
# Scaling of both renderers with the triangle count, the image size and the
# thread count: `rastray bench` on the generated terrain (terrain:N, about
# the same number of pixels per triangle at every size), one process per
# cell so that each cell's peak resident memory is its own.
#
# Usage: bench/scaling.sh [OUT.csv] [--quick]
#   OUT.csv   rows of `rastray bench --csv` (default: scaling.csv)
#   --quick   1e3..1e5 triangles, 640x480 and 1280x720 (a minute or two)
# Environment: RASTRAY (default build/rastray), FRAMES (default 3).
set -euo pipefail
cd "$(dirname "$0")/.."

out=scaling.csv
quick=0
for arg in "$@"; do
  case "$arg" in
    --quick) quick=1 ;;
    -*) echo "bench/scaling.sh: unknown option $arg" >&2; exit 2 ;;
    *) out="$arg" ;;
  esac
done
rastray=${RASTRAY:-build/rastray}
frames=${FRAMES:-3}
[ -x "$rastray" ] || { echo "bench/scaling.sh: $rastray not built (scripts/setup.sh)" >&2; exit 2; }

if [ "$quick" = 1 ]; then
  counts=(1000 10000 100000)
  sizes=("640 480" "1280 720")
  base_size="640 480"
  base_count=100000
else
  counts=(1000 10000 100000 1000000 10000000)
  sizes=("640 480" "1280 720" "1920 1080" "3840 2160")
  base_size="1920 1080"
  base_count=1000000
fi
rm -f "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cell() {  # renderer triangles "W H" threads
  local size=($3) f=$frames warm=1
  # 1e7 triangles take tens of seconds a frame: one frame, no warm-up.
  if [ "$2" -ge 10000000 ]; then f=1; warm=0; fi
  echo "scaling: $1 terrain:$2 ${size[0]}x${size[1]} threads $4" >&2
  "$rastray" bench "terrain:$2" --renderer "$1" --size "${size[0]}" "${size[1]}" --threads "$4" \
    --frames "$f" --warmup "$warm" --work-dir "$work" --csv "$out" >/dev/null ||
    echo "scaling: $1 terrain:$2 ${size[0]}x${size[1]} threads $4 failed (status $?)" >&2
}

for renderer in raster raytrace; do
  for n in "${counts[@]}"; do
    for threads in 1 2; do cell "$renderer" "$n" "$base_size" "$threads"; done
  done
  for size in "${sizes[@]}"; do
    [ "$size" = "$base_size" ] && continue
    cell "$renderer" "$base_count" "$size" 2
  done
done
echo "scaling: rows in $out" >&2
