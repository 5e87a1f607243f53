#!/usr/bin/env bash
# Command 2 of the README (and what .ci/run runs): install what is missing,
# build, and run the whole test suite through ctest. Idempotent.
source "$(dirname "$0")/common.sh"

step "running the test suite (ctest --preset release)"
ctest --preset release -j "$JOBS"
