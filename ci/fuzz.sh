#!/usr/bin/env bash
# Builds the libFuzzer targets (renderer/fuzz/, validation/fuzz/) with clang
# in build/fuzz; each replays the committed regression inputs
# (*/fuzz/regressions/TARGET_*, every past finding, each also a named test
# beside its parser) and the bad-input corpus's files of its parser's kind
# (cli/badinput/), then fuzzes for ${FUZZ_SECONDS:-20} seconds from its seed
# corpus (new inputs go to build/fuzz/corpus-*, not to git).
# Fails on any crash; the crashing input is left as build/fuzz/crash-*.
# FUZZ_TARGETS="ply off" limits the run to some targets.
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${FUZZ_SECONDS:-20}"
# target:seed corpus (the regression inputs are replayed by every target of the dir)
all="obj:renderer/fuzz/corpus/obj mtl:renderer/fuzz/corpus/mtl ply:renderer/fuzz/corpus/ply
     off:renderer/fuzz/corpus/off scene:renderer/fuzz/corpus/scene
     cases:validation/fuzz/corpus/cases tolerance:validation/fuzz/corpus/tolerance"
# The bad-input corpus's directory of each target's kind: its files are
# replayed whole under ASan + UBSan (the program's bad-input test runs them
# in the release build only).
declare -A badinput=([obj]=obj [mtl]=mtl [ply]=ply [off]=off [scene]=scene [cases]=csv [tolerance]=tolerance)
targets=()
for entry in $all; do
  t="${entry%%:*}"
  if [ -z "${FUZZ_TARGETS:-}" ] || [[ " $FUZZ_TARGETS " == *" $t "* ]]; then targets+=("$entry"); fi
done
CC=clang CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DRAYAUDIT_BUILD_FUZZ=ON -DRAYAUDIT_BUILD_BENCH=OFF >/dev/null
cmake --build build/fuzz -j2 --target $(for e in "${targets[@]}"; do printf '%s_fuzz ' "${e%%:*}"; done)
# One target's regression replay and fuzzing run; its lines go to
# build/fuzz/TARGET.out, printed when it ends. Exit 1 on any failure.
fuzz_one() {
  local entry="$1" t seeds work status=0
  t="${entry%%:*}" seeds="${entry#*:}"
  local regress=( $(ls "$(dirname "$seeds")/../regressions/${t}_"* 2>/dev/null || true) )
  if [ "${#regress[@]}" -gt 0 ]; then
    echo "fuzz.sh: ${t}_fuzz replays ${#regress[@]} regression input(s)"
    if ! build/fuzz/${t}_fuzz -runs=0 "${regress[@]}" > "build/fuzz/${t}_regress.log" 2>&1; then
      echo "fuzz.sh: ${t}_fuzz FAILS A REGRESSION INPUT (see build/fuzz/${t}_regress.log)"
      tail -40 "build/fuzz/${t}_regress.log"
      status=1
    fi
  fi
  local bad=( $(find "cli/badinput/${badinput[$t]}" -maxdepth 1 -type f | sort) )
  echo "fuzz.sh: ${t}_fuzz replays ${#bad[@]} file(s) of cli/badinput/${badinput[$t]}"
  if ! build/fuzz/${t}_fuzz -runs=0 -timeout=10 -rss_limit_mb=2048 "${bad[@]}" > "build/fuzz/${t}_badinput.log" 2>&1; then
    echo "fuzz.sh: ${t}_fuzz FAILS ON THE BAD-INPUT CORPUS (see build/fuzz/${t}_badinput.log)"
    tail -40 "build/fuzz/${t}_badinput.log"
    status=1
  fi
  work="build/fuzz/corpus-$t"
  mkdir -p "$work"
  echo "fuzz.sh: ${t}_fuzz for ${secs}s"
  if ! build/fuzz/${t}_fuzz -max_total_time="$secs" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix=build/fuzz/${t}- -print_final_stats=1 "$work" "$seeds" \
       2> "build/fuzz/${t}_fuzz.log"; then
    echo "fuzz.sh: ${t}_fuzz FOUND A CRASH (see build/fuzz/${t}_fuzz.log)"
    tail -40 "build/fuzz/${t}_fuzz.log"
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "build/fuzz/${t}_fuzz.log" | tail -2
  fi
  return $status
}

# Each libFuzzer run is one thread: JOBS of them at a time (default: the
# number of cores), so 7 targets of 20 s take 80 s on 2 cores, not 140.
jobs_max="${JOBS:-$(nproc)}"
status=0
pids=() names=()
finish() {  # waits for the oldest running target, prints its lines
  local pid="${pids[0]}" t="${names[0]}"
  pids=("${pids[@]:1}") names=("${names[@]:1}")
  if ! wait "$pid"; then status=1; cat "build/fuzz/$t.out" >&2; else cat "build/fuzz/$t.out"; fi
}
for entry in "${targets[@]}"; do
  t="${entry%%:*}"
  [ "${#pids[@]}" -ge "$jobs_max" ] && finish
  fuzz_one "$entry" > "build/fuzz/$t.out" 2>&1 &
  pids+=("$!") names+=("$t")
done
while [ "${#pids[@]}" -gt 0 ]; do finish; done
exit $status
