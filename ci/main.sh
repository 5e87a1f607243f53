#!/usr/bin/env bash
# Command 1 of the README: install what is missing, build, and run the main
# job on the scenes shipped in scenes/: each is rendered into OUT (default
# out/). Idempotent.
#
# Scenes may name files in the cache (${cache}/... in a mesh path, see
# scenes/README.md): the teapot is tessellated there first (from Debian's
# povray-examples, taken with apt-get download when not installed), and
# scenes/corpus/*.json (the mesh ladder) are rendered only when
# ci/fetch-corpus.sh has filled the cache (RAYAUDIT_FETCH=1 runs it here).
source "$(dirname "$0")/common.sh"
OUT="${1:-$ROOT/out}"
mkdir -p "$OUT/renders"
CACHE="${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}"

step "teapot: tessellating POV-Ray's teapot.inc into $CACHE/corpus/generated"
teapot="$CACHE/corpus/generated/teapot.obj"
if [ ! -s "$teapot" ]; then
  inc=/usr/share/doc/povray/examples/advanced/teapot/teapot.inc
  pkg="$CACHE/corpus/pkg/povray-examples"
  if [ ! -e "$inc" ]; then
    if [ ! -e "$pkg/.done" ]; then
      sandbox=""; [ "$(id -u)" = 0 ] && sandbox="-o APT::Sandbox::User=root"
      mkdir -p "$CACHE/corpus/deb" "$pkg"
      (cd "$CACHE/corpus/deb" && rm -f povray-examples_*.deb && apt-get download -q $sandbox povray-examples >/dev/null)
      dpkg -x "$CACHE"/corpus/deb/povray-examples_*.deb "$pkg" && rm -f "$CACHE"/corpus/deb/povray-examples_*.deb
      touch "$pkg/.done"
    fi
    inc="$pkg/usr/share/doc/povray/examples/advanced/teapot/teapot.inc"
  fi
  mkdir -p "$(dirname "$teapot")"
  "$RAYAUDIT" generate teapot "$inc" -o "$teapot" --steps 8
else
  echo "have $teapot"
fi

render() {
  local scene="$1" name
  name="$(basename "$scene" .json)"
  echo "rayaudit render $scene -o $OUT/renders/$name.png"
  "$RAYAUDIT" render "$scene" -o "$OUT/renders/$name.png"
}

step "rendering scenes/*.json into $OUT/renders"
for scene in scenes/*.json; do render "$scene"; done

step "rendering the mesh ladder, scenes/corpus/*.json"
if [ "${RAYAUDIT_FETCH:-0}" = 1 ]; then ci/fetch-corpus.sh "$RAYAUDIT"; fi
if [ -s "$CACHE/corpus/ladder/dragon.obj" ]; then
  for scene in scenes/corpus/*.json; do render "$scene"; done
else
  echo "skipped: the corpus cache $CACHE/corpus/ladder is not filled (run ci/fetch-corpus.sh, or RAYAUDIT_FETCH=1 ci/main.sh)"
fi

step "done: outputs are in $OUT"
