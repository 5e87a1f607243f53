// Triangle meshes read from Wavefront OBJ (+ MTL), the shape of document 002
// (shared arrays of positions, normals and uvs; triangles index into them).
//
// What load_obj accepts (the decisions the OBJ spec leaves open; each has a
// unit test in obj_loader_test.cpp):
// - Text: UTF-8 or ASCII, an optional UTF-8 BOM, LF or CRLF line ends (a lone
//   CR is whitespace, not a line end), no trailing newline, tabs and runs of
//   spaces, `\` immediately before the line end joins the next line, `#`
//   after whitespace (or right after a number) starts a comment. A comment
//   ends at its line end: a physical line holding a `#` is never continued
//   (`v 0 0 0 # note \` does not swallow the next line). UTF-16 (BOM FF FE /
//   FE FF) and files with NUL bytes are rejected, not decoded; so are files
//   with CR-only line ends (classic Mac OS; found on the first line), with
//   a message naming them: converting is the user's one-line fix, reading
//   them would need every line scanner to know CR as a line end.
// - Numbers: what std::from_chars accepts plus a leading `+`: `1e2`, `-.5`,
//   `+3.E-1`, `.8e-001`. Non-finite values (`nan`, `inf`, `infinity`, MSVC's
//   `1.#IND`, `1.#INF`, `1.#QNAN`) are errors: a grader's geometry must be
//   finite. So are values out of double's range (`1e400`), hex floats and
//   numbers longer than kMaxNumberChars characters.
// - `v x y z [w]` (w, a rational weight for curves, is ignored: no division)
//   and `v x y z r g b` (vertex colours, ignored); `vn x y z` (not
//   normalised); `vt u [v [w]]` (missing v is 0, w ignored).
// - `f` with `v`, `v/vt`, `v//vn`, `v/vt/vn`, positive or negative
//   (relative) indices. A face mixing forms is accepted; a component (vt or
//   vn) present on only some corners is dropped for the whole face, with one
//   warning per file. Polygons of any size are split by ear clipping
//   (triangulate.h) into n-2 triangles. No forward references: an index must
//   name an element defined before the face (error at the face's line, which
//   says either the later line defining it or how many the whole file has).
// - `vp`, `l`, `p` are counted in `skipped` and otherwise ignored; `s`, `mg`
//   and the free-form geometry statements (`curv`, `surf`, ...) are ignored,
//   unknown statements get one warning per keyword.
// - `o NAME`, `usemtl NAME`: the name is the rest of the line, trimmed (spaces
//   inside kept). `g A B`: several names make one group named "A B".
//   Triangles before any `g`/`o`/`usemtl` have group/object/material -1.
// - `mtllib A.mtl B.mtl`: several files split at whitespace, unless the whole
//   rest of the line names an existing file (names with spaces). Libraries
//   are read after the OBJ, so `mtllib` may come after `usemtl`. A missing
//   library, a missing texture, or a `usemtl` naming no defined material is a
//   warning ("FILE:LINE: ..."); such a name gets a default material appended
//   after the libraries' materials. Duplicate `newmtl` names: the first wins.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "../vec.h"

namespace ra {

// 0-based indices, -1 where absent. gnormal = normalize((B-A) x (C-A)), the
// zero vector for a degenerate triangle. material indexes Mesh::materials,
// -1 = default. 64 bytes; group, object and smoothing are in Mesh::runs.
struct MeshTriangle {
  int v[3];
  int n[3];
  int t[3];
  int material;
  Vec3d gnormal;
};

// Group, object and smoothing group (`s N` in force, 0 = off) of a run of
// consecutive triangles, indices into Mesh::groups/objects, -1 = none. They
// change rarely, so they are stored per run rather than per triangle.
struct TriangleRun {
  std::size_t first;  // index of the run's first triangle
  int group = -1, object = -1, smoothing = 0;
  bool operator==(const TriangleRun&) const = default;
};

// Phong-style material of an MTL file. Map paths are resolved relative to
// the .mtl's directory with backslashes turned into '/'; empty = no map.
struct MtlMaterial {
  std::string name;
  Vec3d Ka{0, 0, 0}, Kd{0.8, 0.8, 0.8}, Ks{0, 0, 0};
  double Ns = 0, Ni = 1, d = 1;  // d: opacity; `Tr t` sets d = 1 - t unless `d` is given
  int illum = 2;
  Vec3d Tf{1, 1, 1};  // transmission filter
  bool has_Tf = false;
  std::string Ni_at;  // "m.mtl:5: Ni": where Ni was given, for errors about it
  std::string map_Ka, map_Kd, map_Ks, map_d, map_bump;
  // Where map_Kd and map_bump were named ("m.mtl:7: map_Kd 'tex.png'"), for errors
  // met when the image is read later.
  std::string map_Kd_at, map_bump_at;
  std::string Ka_at;           // "m.mtl:3: Ka": where Ka was given, for warnings about it
  double bump_multiplier = 1;  // `-bm` of the bump map
};

struct Bounds3d {
  Vec3d min{1e300 * 1e300, 1e300 * 1e300, 1e300 * 1e300};  // +inf: empty
  Vec3d max{-1e300 * 1e300, -1e300 * 1e300, -1e300 * 1e300};
  bool empty() const { return !(min.x <= max.x); }
};

struct BoundingSphere {
  Vec3d center;
  double radius = 0;
};

struct Mesh {
  std::string path;
  std::vector<Vec3d> positions, normals;
  std::vector<std::array<double, 2>> uvs;
  std::vector<MeshTriangle> triangles;
  // Maximal runs in triangle order: the first starts at 0, each next one at
  // the first triangle whose group, object or smoothing differs; empty
  // exactly when there are no triangles.
  std::vector<TriangleRun> runs;
  std::vector<MtlMaterial> materials;
  std::vector<std::string> groups, objects;
  struct {
    long vp = 0, l = 0, p = 0;
  } skipped;
  std::vector<std::string> warnings;  // each "FILE:LINE: message"

  // The run holding triangle i (i < triangles.size()): a binary search.
  const TriangleRun& run_of(std::size_t i) const;
  // Box of all positions (referenced or not); empty() when there are none.
  Bounds3d bbox() const;
  // Sum of the triangles' areas, 0.5 |(B-A) x (C-A)| each.
  double area() const;
  // Sphere around all positions: centre of bbox(), radius the farthest
  // position from it: not the minimal sphere but within sqrt(3) of its radius
  // (radius <= half the box diagonal <= sqrt(3) x half the longest side).
  BoundingSphere bounding_sphere() const;
};

struct ObjOptions {
  // Read `mtllib` files (relative to the OBJ's directory) and check texture
  // files exist. Off: materials come only from `usemtl` names (defaults).
  bool load_materials = true;
  // 1: serial. 0: all hardware threads. N > 1: N threads (the result is
  // identical to the serial one; see obj_loader.cpp for the scheme).
  int threads = 1;
  // Files smaller than this are parsed serially whatever `threads` says:
  // the parallel scheme's extra passes (count, then fix-ups) cost more than
  // a second core saves on small files (`rayaudit bench` obj/ rows, 2 cores: the
  // 2.4 MB bunny took 4.1 ms on 2 threads against 3.7 ms on one).
  std::size_t parallel_min_bytes = std::size_t(8) << 20;
};

// Largest file load_obj reads (bytes): beyond it, an InputError.
inline constexpr std::uint64_t kMaxObjFileBytes = std::uint64_t(8) << 30;
// Longest number token accepted (characters).
inline constexpr int kMaxNumberChars = 200;

// Reads FILE; throws ra::InputError("FILE:LINE: ...") on malformed input.
Mesh load_obj(const std::filesystem::path& file);
Mesh load_obj(const std::filesystem::path& file, const ObjOptions& options);
// Parses OBJ text held in memory; `name` is used in messages and, with
// options.load_materials, as the base for `mtllib` paths.
Mesh parse_obj(std::string_view text, const std::string& name, const ObjOptions& options = {});

// MTL: parses text in memory. `base_dir` resolves map paths; when
// check_files, a missing map file adds a warning. Warnings are appended.
std::vector<MtlMaterial> parse_mtl(std::string_view text, const std::string& name,
                                   const std::filesystem::path& base_dir, bool check_files,
                                   std::vector<std::string>& warnings);
// Reads an .mtl file (throws InputError when it cannot be read).
std::vector<MtlMaterial> load_mtl(const std::filesystem::path& file, std::vector<std::string>& warnings);

// Reads a whole file into a string (InputError if unreadable or larger than
// max_bytes); rejects UTF-16 and NUL bytes only in the text parsers.
std::string read_file_bytes(const std::filesystem::path& file, std::uint64_t max_bytes);

}  // namespace ra
