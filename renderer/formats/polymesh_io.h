// PLY and OFF readers and an OBJ writer, for `rayaudit convert` (meshes of
// the corpus that come as PLY or OFF are turned into OBJ by our own code).
// Only positions and polygons are kept (colours, normals, other elements and
// properties are skipped).
// - PLY: `ascii`, `binary_little_endian` and `binary_big_endian` 1.0; any
//   element order; vertex properties x, y, z of any scalar type; faces as a
//   list property `vertex_indices` or `vertex_index`.
// - OFF: header `OFF` (also COFF, NOFF, CNOFF, STOFF...: extra per-vertex
//   values are ignored), counts on the header line or the next, `#` comments;
//   each vertex and each face on its own line.
// Errors: ra::InputError "FILE:LINE: ..." (binary PLY: "FILE: byte N: ...").
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "../vec.h"

namespace ra {

struct PolyMesh {
  std::vector<Vec3d> positions;
  std::vector<int> face_start;  // face i is indices[face_start[i] .. face_start[i+1])
  std::vector<int> indices;     // 0-based
  std::size_t faces() const { return face_start.empty() ? 0 : face_start.size() - 1; }
};

PolyMesh read_ply(const std::filesystem::path& file);
PolyMesh read_off(const std::filesystem::path& file);
// Text in memory (name used in messages).
PolyMesh parse_ply(std::string_view bytes, const std::string& name);
PolyMesh parse_off(std::string_view text, const std::string& name);

// OBJ text: `v x y z` with the shortest round-trip form of each double,
// `f a b c ...` 1-based.
std::string to_obj_text(const PolyMesh& m, const std::string& comment);
// Writes it atomically.
void write_obj(const PolyMesh& m, const std::filesystem::path& out, const std::string& comment);

}  // namespace ra
