#include "scene_mesh.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "../errors.h"

namespace ra {

Vec3d rotate_about(char axis, double a, const Vec3d& p) {
  const double c = std::cos(a), s = std::sin(a);
  switch (axis) {
    case 'x':
      return {p.x, c * p.y - s * p.z, s * p.y + c * p.z};
    case 'y':
      return {c * p.x + s * p.z, p.y, -s * p.x + c * p.z};
    default:
      return {c * p.x - s * p.y, s * p.x + c * p.y, p.z};
  }
}

Material material_from_mtl(const MtlMaterial& m, std::vector<std::string>* warnings) {
  Material out;
  out.color = m.Kd;
  out.diffuse = 1;
  std::string dropped;  // the channels whose Ka has no Kd to scale (one warning for all)
  for (int c = 0; c < 3; ++c) {
    if (m.Kd[c] > 0) {
      out.ambient[c] = m.Ka[c] / m.Kd[c];
    } else {
      out.ambient[c] = 0;
      if (m.Ka[c] > 0) dropped += std::string(dropped.empty() ? "" : ", ") + "rgb"[c];
    }
  }
  if (!dropped.empty() && warnings)
    warnings->push_back((m.Ka_at.empty() ? std::string("Ka") : m.Ka_at) + " of material \"" + m.name +
                        "\": no Kd in channel " + dropped +
                        ", so POV's ambient (a multiple of the pigment) cannot express it; dropped");
  out.phong = (m.Ks.x + m.Ks.y + m.Ks.z) / 3;
  out.phong_size = m.Ns;
  // Transparency (the MTL specification's dissolve d; Tr = 1 - d) is POV's
  // transmit, untinted; with a transmission filter Tf that is not white it
  // is POV's filter, which tints by the pigment (Kd): POV has no separate
  // filter colour, so a Tf unlike Kd is said in a warning.
  const double clear = 1 - m.d;
  if (clear > 0) {
    const bool tinted = m.has_Tf && !(m.Tf.x == 1 && m.Tf.y == 1 && m.Tf.z == 1);
    if (tinted) {
      out.filter = clear;
      if (warnings && !(m.Tf.x == m.Kd.x && m.Tf.y == m.Kd.y && m.Tf.z == m.Kd.z))
        warnings->push_back("material \"" + m.name +
                            "\": Tf differs from Kd; POV's filter tints by the pigment, so Kd tints what passes");
    } else {
      out.transmit = clear;
    }
  }
  // illum 4 to 7 (ray-traced reflection, with transparency; 5 and 7 by
  // Fresnel; 6 and 7 refract): reflection = Ks, fresnel for 5 and 7, the
  // interior's ior = Ni for 6 and 7.
  if (m.illum >= 4 && m.illum <= 7) {
    out.reflection = m.Ks;
    out.fresnel = m.illum == 5 || m.illum == 7;
    if (m.illum == 6 || m.illum == 7) {
      if (!(m.Ni > 0 && m.Ni <= 1e30))
        throw InputError((m.Ni_at.empty() ? "material \"" + m.name + "\"" : m.Ni_at) +
                         ": an index of refraction must be greater than 0 (illum " + std::to_string(m.illum) +
                         " refracts by Ni)");
      out.ior = m.Ni;
    }
  }
  if (!m.map_Kd.empty() && std::filesystem::exists(m.map_Kd))
    out.texture = ImageTexture{m.map_Kd, TextureFilter::bilinear, m.map_Kd_at};
  if (!m.map_bump.empty() && std::filesystem::exists(m.map_bump))
    out.bump = BumpMap{m.map_bump, BumpVariant::height, m.bump_multiplier, TextureFilter::bilinear, m.map_bump_at};
  return out;
}

namespace {

Vec3d place_point(const MeshPlacement& pl, Vec3d p) {
  for (const auto& [axis, a] : pl.rotations) p = rotate_about(axis, a, p);
  return p * pl.scale + pl.translate;
}

// Normals under rotation + uniform scale: rotate, renormalise (the scale
// does not change directions; a zero normal stays zero).
Vec3d place_normal(const MeshPlacement& pl, Vec3d n) {
  for (const auto& [axis, a] : pl.rotations) n = rotate_about(axis, a, n);
  const double len = length(n);
  return len > 0 ? n / len : n;
}

}  // namespace

void check_mesh_format(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  // Read as OBJ, a PLY or OFF file was "NUL byte in a text file" or "invalid JSON".
  if (ext == ".ply" || ext == ".off")
    throw InputError(located(file.string(), 0,
                             "a " + ext.substr(1) +
                                 " mesh: scenes take OBJ; convert it first "
                                 "(rayaudit convert " +
                                 file.filename().string() + " -o NAME.obj)"));
}

std::shared_ptr<TriangleSet> load_placed_mesh(const MeshPlacement& place) {
  check_mesh_format(place.file);
  // A scene (even the scene itself) named as a mesh read as an OBJ of
  // unknown statements: warnings, and an empty mesh rendered.
  if (place.file.extension() == ".json" || place.file.extension() == ".JSON")
    throw InputError(located(place.file.string(), 0, "a JSON file, not a mesh: a scene's \"mesh\" names an OBJ file"));
  ObjOptions opt;
  opt.threads = 0;  // identical to serial (obj_loader.cpp); faster on the dragon
  Mesh mesh = load_obj(place.file, opt);
  std::vector<std::string> warnings = std::move(mesh.warnings);

  auto set = std::make_shared<TriangleSet>();
  set->name = place.file.string();
  set->shading = place.shading;
  set->positions.reserve(mesh.positions.size());
  for (const auto& p : mesh.positions) set->positions.push_back(place_point(place, p));
  set->normals.reserve(mesh.normals.size());
  for (const auto& n : mesh.normals) set->normals.push_back(place_normal(place, n));
  set->uvs = std::move(mesh.uvs);

  // Materials: the MTL ones in order, then POV's default for triangles with
  // none (material -1); an override replaces them all.
  int fallback = 0;
  if (place.material_override) {
    set->materials = {*place.material_override};
  } else {
    for (const auto& m : mesh.materials) set->materials.push_back(material_from_mtl(m, &warnings));
    fallback = int(set->materials.size());
    set->materials.push_back(Material{});
  }
  set->triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    MeshTriangle3 out;
    for (int k = 0; k < 3; ++k) {
      out.v[k] = t.v[k];
      out.n[k] = t.n[k];
      out.t[k] = t.t[k];
    }
    out.material = place.material_override ? 0 : (t.material >= 0 ? t.material : fallback);
    set->triangles.push_back(out);
  }
  // A `vn 0 0 0` has no direction: a face using one takes the normals
  // computed from the mesh, as a face without vn does. Here, so that the
  // tracer and the POV-Ray export (which both read these triangles) agree;
  // it was accepted silently and rendered 2,557 pixels unlike POV-Ray.
  long zero_faces = 0, first_zero = -1;
  for (auto& t : set->triangles) {
    bool zero = false;
    for (int k = 0; k < 3; ++k)
      if (t.n[k] >= 0 && set->normals[std::size_t(t.n[k])] == Vec3d{0, 0, 0}) {
        zero = true;
        if (first_zero < 0) first_zero = t.n[k];
      }
    if (zero) {
      ++zero_faces;
      t.n[0] = t.n[1] = t.n[2] = -1;
    }
  }
  if (zero_faces)
    warnings.push_back(set->name + ": " + std::to_string(zero_faces) +
                       " triangle(s) use a zero-length vn (first: vn #" + std::to_string(first_zero + 1) +
                       " of the file); they take normals computed from the mesh, "
                       "as triangles without vn do");
  for (const auto& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  return set;
}

std::filesystem::path cache_dir() {
  if (const char* c = std::getenv("RAYAUDIT_CACHE"); c && *c) return c;
  const char* home = std::getenv("HOME");
  return std::filesystem::path(home && *home ? home : "/tmp") / ".cache" / "rayaudit";
}

std::optional<std::filesystem::path> expand_cache_prefix(const std::string& path) {
  static const std::string kPrefix = "${cache}";
  if (path.compare(0, kPrefix.size(), kPrefix) != 0) return std::nullopt;
  std::string rest = path.substr(kPrefix.size());
  while (!rest.empty() && rest.front() == '/') rest.erase(rest.begin());
  return cache_dir() / rest;
}

}  // namespace ra
