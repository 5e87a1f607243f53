#!/usr/bin/env bash
# The asan preset (ASan + UBSan, -O1 -g1, build/asan, without the benchmark
# programs: timings mean nothing under a sanitizer). Two scopes:
#
# ASAN_SCOPE=units (the default; ci/test.sh, every commit): the unit suites
# of the libraries, renderer_tests, renderer_image_tests, the tinyobjloader
# differential test, validation_tests and tracers_tests (every method,
# loader and acceleration structure, the oracle, families, audit, grading,
# POV-Ray export and explanation, images, golden). The program's own
# commands and the bad-input corpus run in the release stage; their
# parsers run under ASan + UBSan in ci/fuzz.sh, which also replays every
# file of the bad-input corpus (cli/badinput/). Building the whole program
# and its CLI tests a second time, sanitized, took 20 of CI's minutes.
#
# ASAN_SCOPE=all (ci/nightly.sh): every test but these, left out with the
# reason printed: the large pov/ corpus rungs (POV-Ray itself is not
# instrumented; our side of `compare` runs the same code on the small rungs
# and the shipped scenes, which all run): a deterministic sample, the slow
# pov label being the one we may sample; and the browser and slow labels
# (each of their steps runs under ASan in another test). ASAN_ALL=1 runs
# every test. ASAN_LABELS (a ctest -L regex) narrows either scope for
# development, e.g. ASAN_LABELS=renderer.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${JOBS:-$(nproc)}"
scope="${ASAN_SCOPE:-units}"
[ -n "${ASAN_ALL:-}" ] && scope=all
if [ "$scope" != units ] && [ "$scope" != all ]; then
  echo "asan.sh: ASAN_SCOPE is 'units' or 'all', not '$scope'" >&2
  exit 2
fi
cmake --preset asan >/dev/null

ctest_args=()
case "$scope" in
  units)
    units=(renderer_tests renderer_image_tests obj_tinyobj_diff_test validation_tests tracers_tests)
    echo "asan.sh: the unit suites (${units[*]}); ASAN_SCOPE=all (nightly) runs every test"
    cmake --build --preset asan -j "$JOBS" --target "${units[@]}"
    # Their tests carry the renderer and validation labels; those of programs
    # not built here (peers_tests, labelled peers too; the scene tests) are
    # left out.
    # PackageConsumer installs the whole build (the program too): release only.
    ctest_args=(-L '^(renderer|validation)$' -LE '^peers$' -E '(_NOT_BUILT|^pov/|^PackageConsumer\.)')
    ;;
  all)
    cmake --build --preset asan -j "$JOBS"
    # pov/ tests of corpus rungs beyond 10k triangles and of the 1k/10k rungs
    # and cornell-box, whose compare path equals ladder-10-box's and the
    # shipped scenes' (they differ only in size); spider-textured stays
    # (POV's mesh2 UVs).
    sampled_out='^pov/corpus/(ladder-1k-teapot-npm|ladder-10k-cheese-ball|ladder-100k-bunny|ladder-1M-dragon|cornell-box)$'
    # Two long single tests whose own work is not ours to instrument, each
    # of whose steps another test runs under ASan: the browser label
    # (headless Chromium on a report of a small real run; audit,
    # crack-maps, compare, golden and report run under ASan in their cli
    # tests) and the slow label (pov/random-unexplained: about a minute of
    # POV-Ray re-renders while shrinking; compare --random runs in
    # CompareRandomCli.*, the shrink in the validation tests' Shrink.*).
    sampled_labels='browser|slow'
    if [ -z "${ASAN_ALL:-}" ]; then
      echo "asan.sh: pov label sampled: left out (same code as the small rungs, run in the release stage):"
      ctest --preset asan -N -R "$sampled_out" | sed -n 's/^ *Test *#[0-9]*: /  /p'
      echo "asan.sh: labels $sampled_labels left out (each step runs under ASan in another test; run in the release stage):"
      ctest --preset asan -N -L "$sampled_labels" | sed -n 's/^ *Test *#[0-9]*: /  /p'
      ctest_args=(-E "$sampled_out" -LE "$sampled_labels")
    fi
    ;;
esac
if [ -n "${ASAN_LABELS:-}" ]; then ctest_args+=(-L "$ASAN_LABELS"); fi
# use_tls=0: gcc 12's LeakSanitizer crashes scanning the dynamic TLS of a
# dlopen()ed library (the image module); see ci/lsan.supp.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS="use_tls=0:suppressions=$PWD/ci/lsan.supp:print_suppressions=0" \
  ctest --preset asan -j "$JOBS" "${ctest_args[@]}"
