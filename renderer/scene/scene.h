// The scene model: one set of objects that the renderer traces and the
// POV-Ray exporter writes. Every field has a default (scenes/README.md), so a
// scene file states only what differs from them.
#pragma once
#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../formats/mesh.h"  // BoundingSphere (one definition for the loader and the scene)
#include "../vec.h"

namespace ra {

using Color = Vec3d;

// A pinhole camera. vfov is the VERTICAL field of view in degrees.
struct CameraSpec {
  Vec3d position{0, 0, 5};
  Vec3d look_at{0, 0, 0};
  Vec3d up{0, 1, 0};
  double vfov = 45;
};

struct PointLight {
  Vec3d position;
  Color color{1, 1, 1};
};

enum class TextureFilter { nearest, bilinear };
enum class BumpVariant { height, normal_map, pov };

struct ImageTexture {
  std::filesystem::path file;
  TextureFilter filter = TextureFilter::bilinear;
  std::string named_at{};  // "m.mtl:7: map_Kd 'tex.png'" when an MTL names it: prefixes errors reading it
};

struct BumpMap {
  std::filesystem::path file;
  BumpVariant variant = BumpVariant::height;
  double strength = 1.0;  // document 002's scale on dx, dy; POV's bump_size
  TextureFilter filter = TextureFilter::bilinear;
  std::string named_at{};  // as ImageTexture's
};

// POV-Ray's finish terms (../shared/POVRAY.md), POV's defaults:
//   I = C ambient ambient_light + sum_lights (diffuse (N.L) C + phong (R.L)^phong_size) Lc
//       + reflection I_reflected
// with the phong term not tinted by the pigment C, and reflection additive.
struct Material {
  Color color{1, 1, 1};          // the pigment
  Color ambient{0.1, 0.1, 0.1};  // multiplies the pigment (POV allows rgb)
  double diffuse = 0.6;
  double phong = 0.0;
  double phong_size = 40.0;
  Color reflection{0, 0, 0};
  // Light through the surface (POV-Ray's pigment filter and transmit, 0..1):
  // transmit passes it untinted, filter tinted by the pigment. The surface's
  // own light (ambient, diffuse) is scaled by 1 - filter - transmit; what
  // passes is C filter + transmit per channel (renderer/shading/glass.h).
  double filter = 0;
  double transmit = 0;
  // The interior's index of refraction (POV's interior { ior }): 1 bends
  // nothing. A mesh has one interior: its first material's ior that is not 1.
  double ior = 1;
  // POV's reflection { 0, reflection fresnel on } with conserve_energy:
  // reflection weighted by the Fresnel equations for the interior's ior,
  // transmission by 1 - that reflectivity.
  bool fresnel = false;
  std::optional<ImageTexture> texture;  // replaces `color` where the object has UVs
  std::optional<BumpMap> bump;
};

struct SphereObject {
  Vec3d center{0, 0, 0};
  double radius = 1;
};

// dot(normal, P) = offset, with normal of unit length.
struct PlaneObject {
  Vec3d normal{0, 1, 0};
  double offset = 0;
};

enum class Shading { flat, smooth };

// Triangles in world space: shared arrays as in document 002. Single
// triangles of a scene are one-triangle meshes.
struct MeshTriangle3 {
  std::array<int, 3> v{-1, -1, -1}, n{-1, -1, -1}, t{-1, -1, -1};
  int material = 0;  // index into TriangleSet::materials
};

struct TriangleSet {
  std::string name;  // the .obj path or "triangle"
  std::vector<Vec3d> positions;
  std::vector<Vec3d> normals;
  std::vector<std::array<double, 2>> uvs;
  std::vector<MeshTriangle3> triangles;
  std::vector<Material> materials;  // at least one
  Shading shading = Shading::flat;
};

// Unit vertex normals for smooth shading of a set without `vn`: each vertex
// gets the sum of its triangles' (B-A)x(C-A), i.e. normals weighted by area,
// normalised. The renderer and the POV-Ray exporter both use this.
std::vector<Vec3d> area_weighted_vertex_normals(const TriangleSet& set);

// Document 002 culls back faces of CLOSED meshes only: on any other set a
// back face can be the visible one. Returns why culling would change what is
// seen, or "" for a closed surface (vertices welded by exact position; every
// edge shared by exactly two triangles, traversed once in each direction)
// whose (B-A)x(C-A) normals point outward (positive signed volume).
std::string cull_unsafe_reason(const TriangleSet& set);

struct Object {
  enum class Kind { sphere, plane, mesh } kind = Kind::sphere;
  SphereObject sphere;
  PlaneObject plane;
  std::shared_ptr<TriangleSet> mesh;
  Material material;  // spheres and planes; meshes carry their own
};

struct Scene {
  std::filesystem::path file;  // where it was read from
  int width = 320;
  int height = 240;
  CameraSpec camera;
  bool camera_given = false;  // false: frame the scene's bounding sphere
  Color background{0, 0, 0};
  Color ambient_light{1, 1, 1};
  int max_depth = 5;  // POV's max_trace_level
  double adc_bailout = 1.0 / 255.0;
  std::vector<PointLight> lights;
  bool lights_given = false;  // false: one white light at the camera
  std::vector<Object> objects;
};

// Reads a scene: a JSON file (scenes/README.md) or a bare .obj. Throws
// InputError naming the file, the JSON path and the line where known.
Scene load_scene(const std::filesystem::path& file);
Scene parse_scene_json(const std::string& text, const std::filesystem::path& file);

// Bounding sphere of everything bounded (planes excluded).
BoundingSphere scene_bounds(const Scene& scene);

// Fills in the defaults that depend on the content: a camera framing the
// bounding sphere when none was given, a light at the camera when none was.
void apply_content_defaults(Scene& scene);

}  // namespace ra
