#!/usr/bin/env bash
# The asan preset (ASan + UBSan, -O1 -g1, build/asan): builds it and runs the
# whole ctest suite on it, as ci/test.sh does after the release tests.
# Left out, with the reason printed: the large pov/ corpus rungs (POV-Ray
# itself is not instrumented; our side of `compare` runs the same code on
# the small rungs and the shipped scenes, which all run): a deterministic
# sample, the slow pov label being the one we may sample; and the browser
# and slow labels (below: each of their steps runs under ASan elsewhere).
# ASAN_ALL=1 runs every pov test too. ASAN_LABELS (a ctest -L regex) narrows
# the run for development, e.g. ASAN_LABELS=renderer.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${JOBS:-$(nproc)}"
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$JOBS"

# pov/ tests of corpus rungs beyond 10k triangles and of the 1k/10k rungs and
# cornell-box, whose compare path equals ladder-10-box's and the shipped
# scenes' (they differ only in size); spider-textured stays (POV's mesh2 UVs).
sampled_out='^pov/corpus/(ladder-1k-teapot-npm|ladder-10k-cheese-ball|ladder-100k-bunny|ladder-1M-dragon|cornell-box)$'
# Two long single tests whose own work is not ours to instrument, each of
# whose steps another test runs under ASan: the browser label (headless
# Chromium on a report of a small real run: 36 s in release; audit,
# crack-maps, compare, golden and report run under ASan in their cli
# tests) and the slow label (pov/random-unexplained: about a minute of
# POV-Ray re-renders while shrinking; compare --random runs in
# CompareRandomCli.*, the shrink in the validation tests' Shrink.*).
sampled_labels='browser|slow'
exclude=()
if [ -z "${ASAN_ALL:-}" ]; then
  echo "asan.sh: pov label sampled: left out (same code as the small rungs, run in the release stage):"
  ctest --preset asan -N -R "$sampled_out" | sed -n 's/^ *Test *#[0-9]*: /  /p'
  echo "asan.sh: labels $sampled_labels left out (each step runs under ASan in another test; run in the release stage):"
  ctest --preset asan -N -L "$sampled_labels" | sed -n 's/^ *Test *#[0-9]*: /  /p'
  exclude=(-E "$sampled_out" -LE "$sampled_labels")
fi
labels=()
if [ -n "${ASAN_LABELS:-}" ]; then labels=(-L "$ASAN_LABELS"); fi
# use_tls=0: gcc 12's LeakSanitizer crashes scanning the dynamic TLS of a
# dlopen()ed library (the image module); see ci/lsan.supp.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS="use_tls=0:suppressions=$PWD/ci/lsan.supp:print_suppressions=0" \
  ctest --preset asan -j "$JOBS" "${labels[@]}" "${exclude[@]}"
