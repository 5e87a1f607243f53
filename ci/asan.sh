#!/usr/bin/env bash
# The asan preset (ASan + UBSan, build/asan): builds it and runs ctest on it.
# ASAN_LABELS (a ctest -L regex, default "renderer|validation|cli") picks
# the sample; ASAN_LABELS=. runs everything, the slow pov/golden/corpus
# scene tests included. Not yet part of ci/test.sh: see README (Bad input,
# full disks and fuzzing) for the measured cost.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${JOBS:-$(nproc)}"
labels="${ASAN_LABELS:-renderer|validation|cli}"
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$JOBS"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS="suppressions=$PWD/ci/lsan.supp:print_suppressions=0" \
  ctest --preset asan -j "$JOBS" -L "$labels"
