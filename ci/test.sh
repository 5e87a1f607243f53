#!/usr/bin/env bash
# Command 2 of the README (and what .ci/run runs): install what is missing,
# build, check the formatting, fetch the mesh corpus into the cache, run the whole test suite
# through ctest, the unit suites again on the asan preset (ASan + UBSan;
# ci/asan.sh), then a 20-second libFuzzer run per parser. Idempotent. Each stage prints its wall
# and CPU time (the budget: 30 minutes on 2 cores).
build_start=$SECONDS
source "$(dirname "$0")/common.sh"
echo "== stage install+build: $((SECONDS - build_start)) s wall"
# Runs "$@" as one timed stage: wall, user and sys seconds (children included).
timed() {
  local name="$1"
  shift
  local TIMEFORMAT="== stage $name: %0R s wall, %0U s user, %0S s sys"
  time "$@"
}

# In CI (CI set) the corpus is fetched into a new, empty cache on every run,
# as a newcomer's machine has it: a missing or broken fetch step fails here
# instead of hiding behind a cache filled by an earlier run.
if [ -n "${CI:-}" ]; then
  RAYAUDIT_CACHE="$(mktemp -d "${TMPDIR:-/tmp}/rayaudit-ci-cache.XXXXXX")"
  export RAYAUDIT_CACHE
  trap 'rm -rf "$RAYAUDIT_CACHE"' EXIT
  step "CI is set: a new, empty corpus cache in $RAYAUDIT_CACHE"
fi

step "checking the C++ formatting (ci/format-check.sh: clang-format --dry-run -Werror over every tracked file)"
timed format ci/format-check.sh

step "fetching the mesh corpus into ${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}/corpus (ci/fetch-corpus.sh)"
timed corpus ci/fetch-corpus.sh "$RAYAUDIT"

step "running the test suite (ctest --preset release)"
timed ctest ctest --preset release -j "$JOBS"

step "the unit suites under ASan + UBSan (ci/asan.sh: asan preset; the nightly runs every test under it)"
timed asan ci/asan.sh

step "fuzzing every parser (OBJ, MTL, PLY, OFF, scene JSON, cases CSV, tolerance JSON) for ${FUZZ_SECONDS:-20} s each, after its regression inputs and bad-input corpus (ci/fuzz.sh)"
timed fuzz ci/fuzz.sh
echo "== total: $SECONDS s wall"
