#!/usr/bin/env bash
# Command 1 of the README: install what is missing, build, and run the main
# job on the scenes shipped in scenes/: each is rendered into OUT (default
# out/). Idempotent.
source "$(dirname "$0")/common.sh"
OUT="${1:-$ROOT/out}"
mkdir -p "$OUT/renders"

step "rendering scenes/*.json into $OUT/renders"
for scene in scenes/*.json; do
  name="$(basename "$scene" .json)"
  echo "rayaudit render $scene -o $OUT/renders/$name.png"
  "$RAYAUDIT" render "$scene" -o "$OUT/renders/$name.png"
done

step "done: outputs are in $OUT"
