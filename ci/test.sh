#!/usr/bin/env bash
# Command 2 of the README (and what .ci/run runs): install what is missing,
# build, fetch the mesh corpus into the cache, run the whole test suite
# through ctest, then a 30-second libFuzzer run per parser. Idempotent.
source "$(dirname "$0")/common.sh"

step "fetching the mesh corpus into ${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}/corpus (ci/fetch-corpus.sh)"
ci/fetch-corpus.sh "$RAYAUDIT"

step "running the test suite (ctest --preset release)"
ctest --preset release -j "$JOBS"

step "fuzzing every parser (OBJ, MTL, PLY, OFF, scene JSON, cases CSV, tolerance JSON) for ${FUZZ_SECONDS:-30} s each (ci/fuzz.sh)"
ci/fuzz.sh
