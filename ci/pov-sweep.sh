#!/usr/bin/env bash
# The POV-Ray differential sweep of the corpus: every OBJ in the corpus cache (ladder/,
# assimp-obj/, embree/) rendered as a bare .obj scene (the defaults: camera
# framing it, a light at the camera, 320 x 240) with our tracer and with
# POV-Ray 3.7, and every differing pixel explained (`rayaudit compare
# --accept-explained`). An OBJ our loader refuses (the assimp corpus has
# deliberately odd files) is listed as not a scene. Exit 1 if a pixel has no
# known cause. Usage: ci/pov-sweep.sh [RAYAUDIT] [OUT]   (the dragon takes ~1 min)
set -uo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
RAYAUDIT="${1:-$ROOT/build/release/rayaudit}"
OUT="${2:-$ROOT/out/pov-sweep}"
CACHE="${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}"
mkdir -p "$OUT"
failed=0 compared=0 refused=0
for obj in "$CACHE"/corpus/{ladder,assimp-obj,embree}/*.obj; do
  [ -f "$obj" ] || continue
  name="$(basename "$(dirname "$obj")")-$(basename "$obj" .obj)"
  rc=0
  log="$(nice "$RAYAUDIT" compare "$obj" --accept-explained --json "$OUT/$name.json" --diff "$OUT/$name-diff.png" 2>&1)" || rc=$?
  case $rc in
    0) compared=$((compared + 1)); echo "$name: $(printf '%s\n' "$log" | grep -E '^(identical: true|every differing)' | head -1)" ;;
    2) refused=$((refused + 1)); echo "$name: not a scene: $(printf '%s\n' "$log" | tail -1)" ;;
    *) compared=$((compared + 1)); failed=1; echo "$name: FAILED (exit $rc)"; printf '%s\n' "$log" | grep -E 'none of the known|error' | sed 's/^/  /' ;;
  esac
done
echo "corpus sweep: $compared OBJ files compared, $refused refused by the loader; outputs in $OUT"
exit $failed
