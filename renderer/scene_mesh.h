// Placing an OBJ mesh in a scene: load, transform (rotations in the order
// given, then uniform scale, then translation), and carry its materials.
#pragma once
#include <filesystem>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

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

// Loads and places a mesh; throws InputError with FILE:LINE on bad input.
std::shared_ptr<TriangleSet> load_placed_mesh(const MeshPlacement& place);

}  // namespace ra
