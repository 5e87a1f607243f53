// Placing an OBJ mesh in a scene: load (renderer/formats/mesh.h), transform
// (rotations in the order given, then uniform scale, then translation), and
// map its MTL materials onto the tracer's POV-Ray finish (scenes/README.md).
#pragma once
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "../formats/mesh.h"
#include "scene.h"

namespace ra {

struct MeshPlacement {
  std::filesystem::path file;
  Vec3d translate{0, 0, 0};
  std::vector<std::pair<char, double>> rotations;  // axis, radians, in order
  double scale = 1;
  Shading shading = Shading::flat;
  std::optional<Material> material_override;
};

// Rotation of p about one axis by `radians` (right-handed).
Vec3d rotate_about(char axis, double radians, const Vec3d& p);

// An MTL material as a POV-Ray finish (classic Phong
// I = Ka + Kd (N.L) + Ks (R.V)^Ns, per channel):
//   color = Kd, diffuse = 1, ambient = Ka / Kd per channel (0 where Kd is 0;
//   then Ka is lost and a warning is appended), phong = mean(Ks),
//   phong_size = Ns, map_Kd -> texture (bilinear; replaces Kd as the
//   pigment), map_bump -> height bump (document 002 variant 2) with
//   strength = -bm. Ni, d, illum, map_Ka, map_Ks, map_d are not used.
Material material_from_mtl(const MtlMaterial& m, std::vector<std::string>* warnings = nullptr);

// Loads and places a mesh; throws InputError with FILE:LINE on bad input.
// The loader's warnings go to stderr, each prefixed "warning: ".
std::shared_ptr<TriangleSet> load_placed_mesh(const MeshPlacement& place);

// Throws InputError for a .ply or .off path (scenes and render take OBJ;
// `rayaudit convert` makes one), so it is not misread as OBJ or JSON.
void check_mesh_format(const std::filesystem::path& file);

// The cache of downloaded and generated data: $RAYAUDIT_CACHE, else
// $HOME/.cache/rayaudit (ci/fetch-corpus.sh fills <cache>/corpus).
std::filesystem::path cache_dir();
// "${cache}/rest" -> cache_dir() / rest; anything else -> nullopt.
std::optional<std::filesystem::path> expand_cache_prefix(const std::string& path);

}  // namespace ra
