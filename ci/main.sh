#!/usr/bin/env bash
# Command 1 of the README: install what is missing, build, and run the main
# job on the scenes shipped in scenes/, into OUT (default out/): every scene
# rendered (OUT/renders), every method audited against exact arithmetic
# (OUT/audit), every scene POV-Ray can express compared with POV-Ray 3.7
# (OUT/pov) and checked against its golden image (OUT/golden-diffs on a
# difference), and the quick benchmark written to OUT/bench/bench.json
# (Google Benchmark's JSON; the console table in OUT/bench/table.txt).
# Idempotent; exits 1 if a comparison, golden check or benchmark row fails,
# after running them all.
#
# Scenes may name files in the cache (${cache}/... in a mesh path, see
# scenes/README.md): ci/fetch-corpus.sh fills it first (the mesh ladder and
# the teapot tessellated from POV-Ray's teapot.inc).
source "$(dirname "$0")/common.sh"
OUT="${1:-$ROOT/out}"
mkdir -p "$OUT/renders" "$OUT/audit" "$OUT/pov"
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

step "auditing every method against exact arithmetic into $OUT/audit"
echo "rayaudit audit --rays 200000 --json $OUT/audit/audit.json --csv $OUT/audit/audit.csv"
"$RAYAUDIT" audit --rays 200000 --json "$OUT/audit/audit.json" --csv "$OUT/audit/audit.csv" | tee "$OUT/audit/table.txt"

failed=0
compare() {
  local scene="$1" name rc=0 log
  name="$(basename "$scene" .json)"
  echo "rayaudit compare $scene --json $OUT/pov/$name.json --diff $OUT/pov/$name-diff.png"
  log="$("$RAYAUDIT" compare "$scene" --skip-inexpressible --json "$OUT/pov/$name.json" \
           --diff "$OUT/pov/$name-diff.png" 2>&1)" || rc=$?
  printf '%s\n' "$log" | grep -E '^(skipped|identical|pixel \(|within)|differs|error' | sed 's/^/  /' || true
  if [ "$rc" != 0 ] && [ "$rc" != 77 ]; then echo "  FAILED (exit $rc)"; failed=1; fi
}
step "comparing with POV-Ray 3.7 into $OUT/pov (the dragon takes about 12 s: POV-Ray parses its 871k-triangle mesh2)"
for scene in scenes/*.json scenes/corpus/*.json; do compare "$scene"; done

step "checking the golden images (diffs into $OUT/golden-diffs)"
"$RAYAUDIT" golden check --skip-unavailable --diff-dir "$OUT/golden-diffs" || { rc=$?; [ "$rc" = 77 ] || failed=1; }

step "benchmarks, --quick (about 2 minutes on 2 idle cores), into $OUT/bench"
mkdir -p "$OUT/bench"
echo "rayaudit bench --quick --json $OUT/bench/bench.json"
rc=0
"$RAYAUDIT" bench --quick --json "$OUT/bench/bench.json" > "$OUT/bench/table.txt" || rc=$?
# The peers' hit-count agreement and where the JSON went.
grep -E '^(embree|cgal) .* differ$|^wrote ' "$OUT/bench/table.txt" | sed 's/^/  /' || true
if [ "$rc" != 0 ]; then echo "  FAILED (exit $rc)"; failed=1; fi

step "done: outputs are in $OUT"
exit $failed
