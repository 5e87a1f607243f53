#!/usr/bin/env bash
# The nightly differential job against POV-Ray, one command: install what is
# missing, build, then compare POV-Ray 3.7 with our tracer on random scenes
# (`rayaudit compare --random N --seed S --out DIR`, every differing pixel
# explained, each unexplained one shrunk to a minimal scene in DIR) for
# several seeds, and sweep every OBJ of the corpus (ci/pov-sweep.sh).
# Usage: ci/nightly.sh [OUT] [N] [SEEDS...]   (default out/nightly, 200, seeds 1 2 3;
# about 3 minutes per 200 scenes on 2 shared cores, the sweep about 1 minute;
# each step prints its seconds). Then the exact method's audit at 1e8 rays
# per family and precision, in EXACT_SHARDS shards (default 8, run one after
# another, each about 1/8 of ~9 hours on 2 cores; set EXACT_RAYS to change
# 1e8), merged and checked for 0 in every error column. Last, every test
# under ASan + UBSan (ASAN_SCOPE=all ci/asan.sh, about 35 minutes).
# Exit 1 if anything is unexplained, the exact method errs or a test fails.
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

EXACT_RAYS="${EXACT_RAYS:-100000000}"
EXACT_SHARDS="${EXACT_SHARDS:-8}"
step "exact method: rayaudit audit --methods exact --rays $EXACT_RAYS in $EXACT_SHARDS shards"
started=$SECONDS
shards=()
for k in $(seq 1 "$EXACT_SHARDS"); do
  nice "$RAYAUDIT" audit --methods exact --rays "$EXACT_RAYS" --shard "$k/$EXACT_SHARDS" \
    --json "$OUT/exact-shard-$k.json" >"$OUT/exact-shard-$k.log" 2>&1 || failed=1
  shards+=("$OUT/exact-shard-$k.json")
done
if "$RAYAUDIT" audit merge "${shards[@]}" --json "$OUT/exact-audit.json" --csv "$OUT/exact-audit.csv"; then
  # Every error column of every cell is 0 (wrong = false hits + false misses + BAD-T).
  /usr/bin/python3 - "$OUT/exact-audit.json" <<'PY' || failed=1
import json, sys
cols = ("false_hits", "false_misses", "wrong_t", "nan_inf", "leaks", "double_hits")
bad = [(c["subject"], c["family"], c["sweep"], k, c["stats"][k])
       for c in json.load(open(sys.argv[1]))["cells"] for k in cols if c["stats"][k]]
for b in bad: print("exact audit: %s %s@%s: %s = %d" % b)
print("exact audit: %s" % ("0 errors in every cell" if not bad else "%d nonzero error counts" % len(bad)))
sys.exit(1 if bad else 0)
PY
else
  failed=1
fi
echo "exact audit: $((SECONDS - started)) s"

step "every test under ASan + UBSan (ASAN_SCOPE=all ci/asan.sh; the commit CI runs the unit suites)"
started=$SECONDS
ASAN_SCOPE=all ci/asan.sh >"$OUT/asan.log" 2>&1 || { failed=1; tail -60 "$OUT/asan.log"; }
grep -E "tests passed|tests failed" "$OUT/asan.log" || true
echo "asan: $((SECONDS - started)) s"

step "done: outputs in $OUT"
exit $failed
