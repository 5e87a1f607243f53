#!/usr/bin/env bash
# The nightly differential job against POV-Ray, one command: install what is
# missing, build, then compare POV-Ray 3.7 with our tracer on random scenes
# (`rayaudit compare --random N --seed S --out DIR`, every differing pixel
# explained, each unexplained one shrunk to a minimal scene in DIR) for
# several seeds, and sweep every OBJ of the corpus (ci/pov-sweep.sh).
# Usage: ci/nightly.sh [OUT] [N] [SEEDS...]   (default out/nightly, 200, seeds 1 2 3;
# about 3 minutes per 200 scenes on 2 shared cores, the sweep about 1 minute;
# each step prints its seconds). Exit 1 if anything is unexplained.
source "$(dirname "$0")/common.sh"
OUT="${1:-$ROOT/out/nightly}"
N="${2:-200}"
shift $(( $# > 2 ? 2 : $# ))
SEEDS=("$@")
[ ${#SEEDS[@]} -gt 0 ] || SEEDS=(1 2 3)
mkdir -p "$OUT"

step "fetching the mesh corpus into ${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}/corpus (ci/fetch-corpus.sh)"
ci/fetch-corpus.sh "$RAYAUDIT"

failed=0
for seed in "${SEEDS[@]}"; do
  step "random batch: rayaudit compare --random $N --seed $seed --out $OUT/random-$seed"
  rc=0 started=$SECONDS
  nice "$RAYAUDIT" compare --random "$N" --seed "$seed" --out "$OUT/random-$seed" \
    >"$OUT/random-$seed.log" 2>/dev/null || rc=$?
  grep -Ev ': identical$' "$OUT/random-$seed.log" || true
  echo "seed $seed: $((SECONDS - started)) s"
  [ "$rc" = 0 ] || failed=1
done

step "corpus sweep: every OBJ in the cache against POV-Ray (ci/pov-sweep.sh)"
started=$SECONDS
ci/pov-sweep.sh "$RAYAUDIT" "$OUT/pov-sweep" || failed=1
echo "corpus sweep: $((SECONDS - started)) s"

step "done: outputs in $OUT"
exit $failed
