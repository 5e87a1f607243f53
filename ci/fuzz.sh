#!/usr/bin/env bash
# Builds the libFuzzer targets (renderer/fuzz/, validation/fuzz/) with clang
# in build/fuzz and runs each for ${FUZZ_SECONDS:-30} seconds from its seed
# corpus (new inputs go to build/fuzz/corpus-*, not to git), then replays the
# committed regression inputs (*/fuzz/regressions/TARGET_*, every past
# finding, each also a named test beside its parser).
# Fails on any crash; the crashing input is left as build/fuzz/crash-*.
# FUZZ_TARGETS="ply off" limits the run to some targets.
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${FUZZ_SECONDS:-30}"
# target:seed corpus (the regression inputs are replayed by every target of the dir)
all="obj:renderer/fuzz/corpus/obj mtl:renderer/fuzz/corpus/mtl ply:renderer/fuzz/corpus/ply
     off:renderer/fuzz/corpus/off scene:renderer/fuzz/corpus/scene
     cases:validation/fuzz/corpus/cases tolerance:validation/fuzz/corpus/tolerance"
targets=()
for entry in $all; do
  t="${entry%%:*}"
  if [ -z "${FUZZ_TARGETS:-}" ] || [[ " $FUZZ_TARGETS " == *" $t "* ]]; then targets+=("$entry"); fi
done
CC=clang CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DRAYAUDIT_BUILD_FUZZ=ON -DRAYAUDIT_BUILD_BENCH=OFF >/dev/null
cmake --build build/fuzz -j2 --target $(for e in "${targets[@]}"; do printf '%s_fuzz ' "${e%%:*}"; done)
status=0
for entry in "${targets[@]}"; do
  t="${entry%%:*}" seeds="${entry#*:}"
  regress=( $(ls "$(dirname "$seeds")/../regressions/${t}_"* 2>/dev/null || true) )
  if [ "${#regress[@]}" -gt 0 ]; then
    echo "fuzz.sh: ${t}_fuzz replays ${#regress[@]} regression input(s)"
    if ! build/fuzz/${t}_fuzz -runs=0 "${regress[@]}" > "build/fuzz/${t}_regress.log" 2>&1; then
      echo "fuzz.sh: ${t}_fuzz FAILS A REGRESSION INPUT (see build/fuzz/${t}_regress.log)" >&2
      tail -40 "build/fuzz/${t}_regress.log" >&2
      status=1
    fi
  fi
  work="build/fuzz/corpus-$t"
  mkdir -p "$work"
  echo "fuzz.sh: ${t}_fuzz for ${secs}s"
  if ! build/fuzz/${t}_fuzz -max_total_time="$secs" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix=build/fuzz/${t}- -print_final_stats=1 "$work" "$seeds" \
       2> "build/fuzz/${t}_fuzz.log"; then
    echo "fuzz.sh: ${t}_fuzz FOUND A CRASH (see build/fuzz/${t}_fuzz.log)" >&2
    tail -40 "build/fuzz/${t}_fuzz.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "build/fuzz/${t}_fuzz.log" | tail -2
  fi
done
exit $status
