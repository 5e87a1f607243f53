#!/usr/bin/env bash
# The audit gate, step by step, as the CI files in examples/ci/ run it (one
# matrix job per shard, then one job that merges, gates and reports), or all
# of it here with `ci/audit-gate.sh all`.
#
#   ci/audit-gate.sh shard K N   audit shard K of N         -> $AUDIT_OUT/shard-K.json
#   ci/audit-gate.sh merge       merge every shard          -> $AUDIT_OUT/audit.json
#   ci/audit-gate.sh gate        compare with the baseline  -> $AUDIT_OUT/junit.xml, exit 1 if a figure rose
#   ci/audit-gate.sh report      the HTML report            -> $AUDIT_OUT/report/index.html
#   ci/audit-gate.sh all         every step above, the shards one after another
#
# Settings (environment): RAYAUDIT (the program; default build/release/
# rayaudit beside this script, else rayaudit on PATH), AUDIT_OUT (audit-out),
# AUDIT_RAYS (200000), AUDIT_SEED (1), AUDIT_SHARDS (4, for `all`),
# AUDIT_METHODS and AUDIT_FAMILIES (comma lists; default all), AUDIT_REPORT
# (0: `all` draws no report), AUDIT_BENCH (a bench --json for the report), AUDIT_BASELINE
# (ci/audit-baseline.json). Without a baseline file, `gate` makes this run
# the baseline and says so; AUDIT_UPDATE_BASELINE=1 replaces it on purpose
# (a new rayaudit version, an intended change). The baseline must come from
# the same version, seed, rays and families: anything else is refused in one
# line (exit 2).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ -z "${RAYAUDIT:-}" ]; then
  if [ -x "$here/build/release/rayaudit" ]; then RAYAUDIT="$here/build/release/rayaudit"
  else RAYAUDIT="$(command -v rayaudit || true)"; fi
fi
[ -n "$RAYAUDIT" ] && [ -x "$RAYAUDIT" ] || {
  echo "ci/audit-gate.sh: no rayaudit program (build it, or set RAYAUDIT=/path/to/rayaudit)" >&2; exit 2; }
OUT="${AUDIT_OUT:-audit-out}"
RAYS="${AUDIT_RAYS:-200000}"
SEED="${AUDIT_SEED:-1}"
SHARDS="${AUDIT_SHARDS:-4}"
BASELINE="${AUDIT_BASELINE:-ci/audit-baseline.json}"
mkdir -p "$OUT"

choose=()
[ -n "${AUDIT_METHODS:-}" ] && choose+=(--methods "$AUDIT_METHODS")
[ -n "${AUDIT_FAMILIES:-}" ] && choose+=(--families "$AUDIT_FAMILIES")

step_shard() {
  local k="$1" n="$2"
  "$RAYAUDIT" audit "${choose[@]}" --rays "$RAYS" --seed "$SEED" --shard "$k/$n" --json "$OUT/shard-$k.json"
}

step_merge() {
  local shards=("$OUT"/shard-*.json)
  [ -e "${shards[0]}" ] || { echo "ci/audit-gate.sh: no $OUT/shard-*.json to merge (run the shard step)" >&2; exit 2; }
  "$RAYAUDIT" audit merge "${shards[@]}" --json "$OUT/audit.json" --csv "$OUT/audit.csv"
}

step_gate() {
  [ -f "$OUT/audit.json" ] || { echo "ci/audit-gate.sh: no $OUT/audit.json (run the merge step)" >&2; exit 2; }
  if [ ! -f "$BASELINE" ] || [ "${AUDIT_UPDATE_BASELINE:-0}" = 1 ]; then
    mkdir -p "$(dirname "$BASELINE")"
    cp "$OUT/audit.json" "$BASELINE"
    echo "ci/audit-gate.sh: $BASELINE is now this run (commit it: later runs are gated on it)"
    # The JUnit file all the same: every family judged against itself.
    "$RAYAUDIT" audit diff "$BASELINE" "$OUT/audit.json" --junit "$OUT/junit.xml"
    return
  fi
  "$RAYAUDIT" audit diff "$BASELINE" "$OUT/audit.json" --junit "$OUT/junit.xml"
}

step_report() {
  [ -f "$OUT/audit.json" ] || { echo "ci/audit-gate.sh: no $OUT/audit.json (run the merge step)" >&2; exit 2; }
  local extra=()
  [ -n "${AUDIT_BENCH:-}" ] && extra+=(--bench "$AUDIT_BENCH")
  "$RAYAUDIT" report --audit "$OUT/audit.json" "${extra[@]}" -o "$OUT/report"
}

case "${1:-}" in
  shard) [ $# -eq 3 ] || { echo "usage: ci/audit-gate.sh shard K N" >&2; exit 2; }; step_shard "$2" "$3" ;;
  merge) step_merge ;;
  gate) step_gate ;;
  report) step_report ;;
  all)
    rm -f "$OUT"/shard-*.json
    for k in $(seq 1 "$SHARDS"); do step_shard "$k" "$SHARDS"; done
    step_merge
    status=0
    step_gate || status=$?
    # AUDIT_REPORT=0 leaves the report out (the ctest draws it once).
    [ "${AUDIT_REPORT:-1}" = 0 ] || step_report
    exit "$status"
    ;;
  *) echo "usage: ci/audit-gate.sh shard K N | merge | gate | report | all" >&2; exit 2 ;;
esac
