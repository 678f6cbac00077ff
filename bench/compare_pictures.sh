#!/usr/bin/env bash
# Compares two picture sets of bench/pictures.sh byte for byte.
# Usage: bench/compare_pictures.sh BEFORE_DIR AFTER_DIR
# Prints one line per picture that differs or is missing, and a count;
# exits 0 when every EXR of BEFORE_DIR is in AFTER_DIR with the same bytes,
# 1 otherwise.
set -euo pipefail
if [ $# -ne 2 ]; then
  echo "usage: bench/compare_pictures.sh BEFORE_DIR AFTER_DIR" >&2
  exit 2
fi
same=0
differ=0
for f in "$1"/*.exr; do
  name=$(basename "$f")
  if cmp -s "$f" "$2/$name"; then
    same=$((same + 1))
  else
    echo "differs: $name"
    differ=$((differ + 1))
  fi
done
echo "$same same, $differ differ or missing"
[ "$differ" -eq 0 ]
