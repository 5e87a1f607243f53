# Shared by ci/main.sh and ci/test.sh: install what is missing, then
# configure and build the release preset. Sourced, not run.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
JOBS="${JOBS:-$(nproc)}"
step() { printf '\n== %s\n' "$*"; }

step "installing missing Debian packages (ci/install-deps.sh)"
ci/install-deps.sh

step "configuring (cmake --preset release) and building with $JOBS jobs into build/release"
cmake --preset release >/dev/null
cmake --build --preset release -j "$JOBS"
RAYAUDIT="$ROOT/build/release/rayaudit"
export RAYAUDIT_EXE="$RAYAUDIT"
