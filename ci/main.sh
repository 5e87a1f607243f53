#!/usr/bin/env bash
# Command 1 of the README: install what is missing, build, and run the main
# job on the scenes shipped in scenes/, into OUT (default out/): every scene
# rendered (OUT/renders), every method and peer audited against exact
# arithmetic (OUT/audit), every scene POV-Ray can express compared with POV-Ray 3.7
# (OUT/pov) and checked against its golden image (OUT/golden-diffs on a
# difference), crack maps drawn (OUT/crack-maps), the quick benchmark
# written to OUT/bench/bench.json (Google Benchmark's JSON; the console
# table in OUT/bench/table.txt) and everything gathered into one page,
# OUT/report/index.html with OUT/report/report.json (rayaudit report). Each
# stage is announced and timed (OUT/stages.tsv, shown in the report's
# header). Idempotent; exits 1 if a comparison, golden check or benchmark
# row fails, after running them all.
#
# Scenes may name files in the cache (${cache}/... in a mesh path, see
# scenes/README.md): ci/fetch-corpus.sh fills it first (the mesh ladder and
# the teapot tessellated from POV-Ray's teapot.inc).
source "$(dirname "$0")/common.sh"
OUT="${1:-$ROOT/out}"
mkdir -p "$OUT/renders" "$OUT/audit" "$OUT/pov" "$OUT/golden"
CACHE="${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}"

# Stage timing: each stage() closes the previous one into OUT/stages.tsv.
STAGES="$OUT/stages.tsv"
printf 'install + build\t%s\n' "$SECONDS" >"$STAGES"
stage_name="" stage_start=$SECONDS
stage() {
  if [ -n "$stage_name" ]; then printf '%s\t%s\n' "$stage_name" "$((SECONDS - stage_start))" >>"$STAGES"; fi
  stage_name="$1" stage_start=$SECONDS
  step "$2"
}
# "[3/14] " on each item of a long stage.
count_of() { echo "$#"; }

stage "corpus" "fetching the mesh corpus and the tessellated teapot into $CACHE/corpus (ci/fetch-corpus.sh)"
ci/fetch-corpus.sh "$RAYAUDIT"

render() {
  local scene="$1" name
  name="$(basename "$scene" .json)"
  echo "rayaudit render $scene -o $OUT/renders/$name.png"
  "$RAYAUDIT" render "$scene" -o "$OUT/renders/$name.png"
}

stage "render" "rendering scenes/*.json and the mesh ladder scenes/corpus/*.json into $OUT/renders"
n=0 total=$(count_of scenes/*.json scenes/corpus/*.json)
for scene in scenes/*.json scenes/corpus/*.json; do n=$((n + 1)); printf '[%d/%d] ' "$n" "$total"; render "$scene"; done

stage "audit" "auditing every method and peer (Embree, CGAL, POV-Ray's mesh2 test) and whole tracers against exact arithmetic into $OUT/audit"
echo "rayaudit audit --methods all --rays 200000 --tracers bvh,sphere,none,embree,embree-robust,cgal-aabb --json $OUT/audit/audit.json --csv $OUT/audit/audit.csv"
"$RAYAUDIT" audit --methods all --rays 200000 --tracers bvh,sphere,none,embree,embree-robust,cgal-aabb --json "$OUT/audit/audit.json" --csv "$OUT/audit/audit.csv" | tee "$OUT/audit/table.txt"

failed=0
compare() {
  local scene="$1" name rc=0 log
  name="$(basename "$scene" .json)"
  echo "rayaudit compare $scene --json $OUT/pov/$name.json --diff $OUT/pov/$name-diff.png"
  log="$("$RAYAUDIT" compare "$scene" --skip-inexpressible --explain --json "$OUT/pov/$name.json" \
           --diff "$OUT/pov/$name-diff.png" --ours "$OUT/pov/$name-ours.png" --pov "$OUT/pov/$name-pov.png" 2>&1)" || rc=$?
  printf '%s\n' "$log" | grep -E '^(skipped|identical|pixel \(|within)|differs|error' | sed 's/^/  /' || true
  if [ "$rc" != 0 ] && [ "$rc" != 77 ]; then echo "  FAILED (exit $rc)"; failed=1; fi
}
stage "compare" "comparing with POV-Ray 3.7 into $OUT/pov (the dragon takes about 12 s: POV-Ray parses its 871k-triangle mesh2)"
n=0
for scene in scenes/*.json scenes/corpus/*.json; do n=$((n + 1)); printf '[%d/%d] ' "$n" "$total"; compare "$scene"; done

stage "pov-random" "differential test against POV-Ray: 12 random scenes, seed 1 (rayaudit compare --random; ci/nightly.sh runs 3 x 200)"
echo "rayaudit compare --random 12 --seed 1 --out $OUT/pov-random"
rc=0
"$RAYAUDIT" compare --random 12 --seed 1 --out "$OUT/pov-random" 2>/dev/null | sed 's/^/  /' || rc=$?
[ "$rc" = 0 ] || { echo "  FAILED: unexplained differences, minimal scenes in $OUT/pov-random"; failed=1; }

stage "golden" "checking the golden images (diffs into $OUT/golden-diffs)"
"$RAYAUDIT" golden check --skip-unavailable --diff-dir "$OUT/golden-diffs" --json "$OUT/golden/golden.json" ||
  { rc=$?; [ "$rc" = 77 ] || failed=1; }

stage "crack maps" "crack maps: the audit's sphere and the ladder's elephant at offsets 1..1e7, each triangle method in float, into $OUT/crack-maps"
"$RAYAUDIT" crack-maps -o "$OUT/crack-maps" | tail -n 1

stage "bench" "benchmarks, --quick (about 2 minutes on 2 idle cores), into $OUT/bench"
mkdir -p "$OUT/bench"
rm -f "$OUT/bench/bench.json"  # a stale one must not stand in for a failed run
echo "rayaudit bench --quick --json $OUT/bench/bench.json"
rc=0
# On a terminal, a running count of finished rows (the table goes to table.txt).
if [ -t 1 ]; then
  "$RAYAUDIT" bench --quick --json "$OUT/bench/bench.json" | tee "$OUT/bench/table.txt" |
    awk '/ns|ms|us/ { n++; printf "\r  %d rows done", n } END { printf "\r%30s\r", "" }' || rc=$?
else
  "$RAYAUDIT" bench --quick --json "$OUT/bench/bench.json" > "$OUT/bench/table.txt" || rc=$?
fi
# The peers' hit-count agreement and where the JSON went.
grep -E '^(embree|cgal) .* differ$|^wrote ' "$OUT/bench/table.txt" | sed 's/^/  /' || true
bench_arg=()
if [ "$rc" != 0 ]; then echo "  FAILED (exit $rc)"; failed=1; fi
if [ -f "$OUT/bench/bench.json" ]; then bench_arg=(--bench "$OUT/bench/bench.json"); fi

stage "report" "the report: $OUT/report/index.html and report.json"
"$RAYAUDIT" report --audit "$OUT/audit/audit.json" "${bench_arg[@]}" --compare "$OUT/pov" \
  --crack-maps "$OUT/crack-maps" --golden "$OUT/golden/golden.json" --stages "$STAGES" -o "$OUT/report"
printf '%s\t%s\n' "$stage_name" "$((SECONDS - stage_start))" >>"$STAGES"

step "done in ${SECONDS} s ($(awk -F'\t' '{ printf "%s%s %s s", (NR > 1 ? ", " : ""), $1, $2 }' "$STAGES")): open $OUT/report/index.html"
exit $failed
