#!/usr/bin/env bash
# Checks that every tracked C++ file is as clang-format (Debian's, with the
# repository's .clang-format) writes it; exit 1 and the offending lines
# otherwise. To fix: ci/format-check.sh --fix
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.cpp' '*.h' '*.inc' '*.cc')
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${files[@]}"
  exit 0
fi
clang-format --dry-run -Werror "${files[@]}"
echo "ci/format-check.sh: ${#files[@]} files formatted as .clang-format says"
