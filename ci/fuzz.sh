#!/usr/bin/env bash
# Builds the libFuzzer targets (renderer/fuzz/) with clang in build/fuzz and
# runs each for ${FUZZ_SECONDS:-60} seconds from the seed corpus in
# renderer/fuzz/corpus/ (new inputs go to build/fuzz/corpus-*, not to git).
# Fails on any crash; the crashing input is left as build/fuzz/crash-*.
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${FUZZ_SECONDS:-60}"
CC=clang CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DRAYAUDIT_BUILD_FUZZ=ON -DRAYAUDIT_BUILD_BENCH=OFF >/dev/null
cmake --build build/fuzz -j2 --target obj_fuzz mtl_fuzz
status=0
for t in obj mtl; do
  work="build/fuzz/corpus-$t"
  mkdir -p "$work"
  echo "fuzz.sh: ${t}_fuzz for ${secs}s"
  if ! build/fuzz/${t}_fuzz -max_total_time="$secs" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix=build/fuzz/ -print_final_stats=1 "$work" "renderer/fuzz/corpus/$t" \
       2> "build/fuzz/${t}_fuzz.log"; then
    echo "fuzz.sh: ${t}_fuzz FOUND A CRASH (see build/fuzz/${t}_fuzz.log)" >&2
    tail -40 "build/fuzz/${t}_fuzz.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "build/fuzz/${t}_fuzz.log" | tail -2
  fi
done
exit $status
