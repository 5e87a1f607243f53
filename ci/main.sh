#!/usr/bin/env bash
# Command 1 of the README: install what is missing, build, and run the main
# job on the scenes shipped in scenes/: each is rendered into OUT (default
# out/). Idempotent.
#
# Scenes may name files in the cache (${cache}/... in a mesh path, see
# scenes/README.md): ci/fetch-corpus.sh fills it first (the mesh ladder and
# the teapot tessellated from POV-Ray's teapot.inc).
source "$(dirname "$0")/common.sh"
OUT="${1:-$ROOT/out}"
mkdir -p "$OUT/renders"
CACHE="${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}"

step "fetching the mesh corpus and the tessellated teapot into $CACHE/corpus (ci/fetch-corpus.sh)"
ci/fetch-corpus.sh "$RAYAUDIT"

render() {
  local scene="$1" name
  name="$(basename "$scene" .json)"
  echo "rayaudit render $scene -o $OUT/renders/$name.png"
  "$RAYAUDIT" render "$scene" -o "$OUT/renders/$name.png"
}

step "rendering scenes/*.json into $OUT/renders"
for scene in scenes/*.json; do render "$scene"; done

step "rendering the mesh ladder, scenes/corpus/*.json"
for scene in scenes/corpus/*.json; do render "$scene"; done

step "done: outputs are in $OUT"
