#include "pov_export.h"

#include <charconv>
#include <cmath>
#include <map>
#include <sstream>

#include "io/atomic_file.h"
#include "errors.h"
#include "image.h"
#include "image_module.h"

namespace ra {
namespace {

bool safe_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         std::string_view(" _.,+=@%/-").find(c) != std::string_view::npos;
}

// Text for a comment: safe characters only (a newline would end the comment
// and let the rest be parsed as SDL).
std::string comment_text(std::string_view text) {
  std::string out;
  for (char c : text) out += (safe_char(c) && c != '/') ? c : '_';
  return out;
}

// The shortest decimal that reads back as the same double, so POV parses
// exactly the numbers our tracer uses.
std::string num(double x) {
  if (!std::isfinite(x)) throw InputError("POV-Ray export: a number is not finite");
  if (x == 0) return "0";
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

std::string vec(const Vec3d& v) { return "<" + num(v.x) + "," + num(v.y) + "," + num(v.z) + ">"; }
std::string rgb(const Color& c) { return "rgb " + vec(c); }

// Every finish term is written, so POV's defaults never apply silently.
// Fresnel: POV's reflection { min, max fresnel on } with min 0 and
// conserve_energy (transmission less what is reflected).
std::string finish(const Material& m) {
  const std::string reflection = m.fresnel
                                     ? "reflection { rgb 0, " + rgb(m.reflection) + " fresnel on } conserve_energy"
                                     : "reflection { " + rgb(m.reflection) + " }";
  return "finish { ambient " + rgb(m.ambient) + " diffuse " + num(m.diffuse) + " brilliance 1 phong " + num(m.phong) +
         " phong_size " + num(m.phong_size) + " specular 0 " + reflection + " }";
}

// The pigment's filter and transmit (rgbft), only where light passes, so an
// opaque material's SDL stays as it was.
bool clear(const Material& m) { return m.filter != 0 || m.transmit != 0; }
std::string colour(const Material& m) {
  if (!clear(m)) return rgb(m.color);
  return "rgbft <" + num(m.color.x) + "," + num(m.color.y) + "," + num(m.color.z) + "," + num(m.filter) + "," +
         num(m.transmit) + ">";
}

// POV's interior is one per object: a mesh's is its first material's ior
// that is not 1 (as the renderer's).
double object_ior(const Object& o) {
  if (o.kind != Object::Kind::mesh) return o.material.ior;
  for (const Material& m : o.mesh->materials)
    if (m.ior != 1) return m.ior;
  return 1;
}
std::string interior(const Object& o) {
  const double ior = object_ior(o);
  return ior == 1 ? "" : "  interior { ior " + num(ior) + " }\n";
}

// Names of the images the SDL refers to, one per distinct source file.
class ImageNames {
 public:
  explicit ImageNames(std::string prefix) : prefix_(std::move(prefix)) {}
  std::string name_of(const std::filesystem::path& source) {
    auto it = names_.find(source);
    if (it != names_.end()) return it->second;
    const std::string name = prefix_ + "tex" + std::to_string(files_.size()) + ".png";
    names_.emplace(source, name);
    files_.push_back({source, name});
    return name;
  }
  std::vector<PovImageFile> take() { return std::move(files_); }

 private:
  std::string prefix_;
  std::map<std::filesystem::path, std::string> names_;
  std::vector<PovImageFile> files_;
};

// POV's texture for a material. `with_uv`: the surface has UVs, so the image
// texture and the bump map apply (our tracer uses them only there).
std::string texture(const Material& m, bool with_uv, ImageNames& names) {
  std::string pigment = "pigment { " + colour(m) + " }";
  std::string normal;
  if (with_uv && m.texture) {
    // gamma 1.0: the PNG's values are linear (else POV decodes them as sRGB).
    pigment = "pigment { image_map { png " + pov_string_literal(names.name_of(m.texture->file)) + " gamma 1.0" +
              (m.texture->filter == TextureFilter::bilinear ? " interpolate 2" : "") +
              (clear(m) ? " filter all " + num(m.filter) + " transmit all " + num(m.transmit) : "") + " } }";
  }
  if (with_uv && m.bump) {
    // Only the pov variant gets here (pov_inexpressible); POV does not
    // gamma-decode bump maps.
    normal = " normal { bump_map { png " + pov_string_literal(names.name_of(m.bump->file)) + " bump_size " +
             num(m.bump->strength) + (m.bump->filter == TextureFilter::bilinear ? " interpolate 2" : "") + " } }";
  }
  return "texture { " + pigment + normal + " " + finish(m) + " }";
}

bool has(const std::array<int, 3>& idx) { return idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0; }

std::string idx3(int a, int b, int c) {
  return "<" + std::to_string(a) + "," + std::to_string(b) + "," + std::to_string(c) + ">";
}

// A triangle set as mesh2 (0-based indices). Flat sets get no normals, so
// POV computes each face normal from its vertices as we do; smooth sets get
// the set's normals and, for triangles without normal indices, the
// area-weighted vertex normals.
void write_mesh2(std::ostringstream& out, const TriangleSet& set, ImageNames& names, const std::string& modifiers) {
  if (set.triangles.empty()) {
    // POV-Ray refuses a mesh2 without faces ("Cannot parse input"); our
    // tracer sees nothing there either (an OBJ of points or lines).
    out << "// mesh " << comment_text(std::filesystem::path(set.name).filename().string()) << ": no triangles\n";
    return;
  }
  out << "// mesh " << comment_text(std::filesystem::path(set.name).filename().string()) << ", " << set.triangles.size()
      << " triangles\nmesh2 {\n  vertex_vectors { " << set.positions.size();
  for (const auto& p : set.positions) out << ",\n    " << vec(p);
  out << " }\n";

  const bool smooth = set.shading == Shading::smooth;
  bool need_computed = false;
  for (const auto& tri : set.triangles) need_computed |= !has(tri.n);
  const int computed_base = int(set.normals.size());
  if (smooth) {
    std::vector<Vec3d> normals = set.normals;
    if (need_computed) {
      const auto vn = area_weighted_vertex_normals(set);
      normals.insert(normals.end(), vn.begin(), vn.end());
    }
    out << "  normal_vectors { " << normals.size();
    for (const auto& n : normals) out << ",\n    " << vec(n);
    out << " }\n";
  }

  bool any_uv = false;
  for (const auto& tri : set.triangles) any_uv |= has(tri.t);
  if (any_uv) {
    out << "  uv_vectors { " << set.uvs.size();
    for (const auto& uv : set.uvs) out << ",\n    <" << num(uv[0]) << "," << num(uv[1]) << ">";
    out << " }\n";
  }

  // One texture per (material, has UVs) pair that occurs.
  std::vector<std::string> textures;
  std::map<std::string, int> texture_index;
  std::vector<int> face_texture;
  for (const auto& tri : set.triangles) {
    const int mi = std::clamp(tri.material, 0, int(set.materials.size()) - 1);
    const std::string t = texture(set.materials[mi], has(tri.t), names);
    auto [it, added] = texture_index.emplace(t, int(textures.size()));
    if (added) textures.push_back(t);
    face_texture.push_back(it->second);
  }
  out << "  texture_list { " << textures.size();
  for (const auto& t : textures) out << ",\n    " << t;
  out << " }\n";

  out << "  face_indices { " << set.triangles.size();
  for (std::size_t i = 0; i < set.triangles.size(); ++i) {
    const auto& v = set.triangles[i].v;
    out << ",\n    " << idx3(v[0], v[1], v[2]) << ", " << face_texture[i];
  }
  out << " }\n";
  if (smooth) {
    out << "  normal_indices { " << set.triangles.size();
    for (const auto& tri : set.triangles) {
      const auto& v = tri.v;
      const auto& n = tri.n;
      out << ",\n    "
          << (has(n) ? idx3(n[0], n[1], n[2]) : idx3(computed_base + v[0], computed_base + v[1], computed_base + v[2]));
    }
    out << " }\n";
  }
  if (any_uv) {
    // Triangles without UVs use a plain pigment, so their indices do not matter.
    out << "  uv_indices { " << set.triangles.size();
    for (const auto& tri : set.triangles)
      out << ",\n    " << (has(tri.t) ? idx3(tri.t[0], tri.t[1], tri.t[2]) : idx3(0, 0, 0));
    out << " }\n  uv_mapping\n";
  }
  out << modifiers << "}\n";
}

std::optional<std::string> material_inexpressible(const Material& m) {
  if (m.bump && m.bump->variant != BumpVariant::pov)
    return std::string("bump variant \"") + (m.bump->variant == BumpVariant::height ? "height" : "normal-map") +
           "\" is the documents' own bump mapping, which POV-Ray does not have (only variant \"pov\" is)";
  return std::nullopt;
}

// POV-Ray's image_map and bump_map take integer images: the export copies a
// texture as a 16-bit PNG, which rounds a float image's values and clamps
// them to [0, 1] (an EXR of values up to 3 rendered 8,114 pixels unlike
// POV-Ray, reported as unexplained). Read once per file.
std::optional<std::string> float_images(const Material& m, std::map<std::filesystem::path, bool>& seen) {
  for (const std::filesystem::path* f : {m.texture ? &m.texture->file : nullptr,
                                         m.bump && m.bump->variant == BumpVariant::pov ? &m.bump->file : nullptr}) {
    if (!f) continue;
    auto [it, fresh] = seen.emplace(*f, false);
    if (fresh) {
      try {
        it->second = !read_stored_pixels(*f, "texture").f.empty();
      } catch (const InputError&) {
        // Unreadable: not this rule's to say (the image copy names the file).
      }
    }
    if (it->second)
      return "texture " + f->string() +
             " stores floating-point values, which POV-Ray's image maps (8 or 16-bit "
             "integers) cannot hold: save it as an 8 or 16-bit PNG";
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> pov_inexpressible(const Scene& scene) {
  std::map<std::filesystem::path, bool> seen;
  for (const auto& o : scene.objects) {
    if (o.kind != Object::Kind::mesh) {
      if (auto r = material_inexpressible(o.material)) return r;
      if (auto r = float_images(o.material, seen)) return r;
      continue;
    }
    for (const auto& m : o.mesh->materials) {
      if (m.ior != 1 && m.ior != object_ior(o))
        return "mesh " + std::filesystem::path(o.mesh->name).filename().string() +
               " has materials of different ior, and POV-Ray's mesh2 has one interior";
      if (auto r = material_inexpressible(m)) return r;
      if (auto r = float_images(m, seen)) return r;
    }
  }
  return std::nullopt;
}

std::string pov_string_literal(std::string_view text) {
  for (char c : text)
    if (!safe_char(c))
      throw InputError("refusing to write \"" + comment_text(text) +
                       "\" into POV-Ray SDL: only letters, digits and \" _.,+=@%/-\" are allowed");
  return "\"" + std::string(text) + "\"";
}

double horizontal_fov_degrees(double vfov_degrees, double aspect) {
  return 2 * std::atan(aspect * std::tan(vfov_degrees * M_PI / 360.0)) * 180.0 / M_PI;
}

PovExport export_pov(const Scene& scene, const std::string& image_prefix) {
  if (auto reason = pov_inexpressible(scene)) throw InputError("POV-Ray cannot express this scene: " + *reason);
  for (char c : image_prefix)
    if (!safe_char(c) || c == ' ' || c == '/' || c == ',')
      throw InputError("image name prefix \"" + comment_text(image_prefix) + "\" must match [A-Za-z0-9_.-]*");
  ImageNames names(image_prefix);
  std::ostringstream out;
  const double aspect = double(scene.width) / double(scene.height);
  const CameraSpec& cam = scene.camera;
  out << "// Written by rayaudit export-pov from " << comment_text(scene.file.filename().string()) << " ("
      << scene.width << "x" << scene.height << ").\n"
      << "// Render with Antialias=Off File_Gamma=1.0 at +W" << scene.width << " +H" << scene.height
      << " to match rayaudit render (../shared/POVRAY.md).\n"
      << "#version 3.7;\n"
      << "global_settings { assumed_gamma 1.0 ambient_light " << rgb(scene.ambient_light) << " max_trace_level "
      << scene.max_depth << " adc_bailout " << num(scene.adc_bailout) << " }\n"
      << "background { " << rgb(scene.background)
      << " }\n"
      // A negative right makes POV's left-handed camera right-handed like
      // ours; sky is our up, and `up y` only gives |up| = 1 and the handedness.
      << "camera { perspective location " << vec(cam.position) << " sky " << vec(cam.up) << " up y right <"
      << num(-aspect) << ",0,0> angle " << num(horizontal_fov_degrees(cam.vfov, aspect)) << " look_at "
      << vec(cam.look_at) << " }\n";
  for (const auto& l : scene.lights) out << "light_source { " << vec(l.position) << " color " << rgb(l.color) << " }\n";
  for (const auto& o : scene.objects) {
    switch (o.kind) {
      case Object::Kind::sphere:
        out << "sphere { " << vec(o.sphere.center) << ", " << num(o.sphere.radius) << "\n  "
            << texture(o.material, false, names) << (interior(o).empty() ? "" : "\n" + interior(o)) << " }\n";
        break;
      case Object::Kind::plane:
        out << "plane { " << vec(o.plane.normal) << ", " << num(o.plane.offset) << "\n  "
            << texture(o.material, false, names) << (interior(o).empty() ? "" : "\n" + interior(o)) << " }\n";
        break;
      case Object::Kind::mesh:
        write_mesh2(out, *o.mesh, names, interior(o));
        break;
    }
  }
  return {out.str(), names.take()};
}

void copy_pov_image(const std::filesystem::path& source, const std::filesystem::path& dest) {
  // Encoded in memory, then written with every write and close checked:
  // OIIO's PNG writer does not report a full disk.
  // Read first as a texture is: its header size bounded by the file, a
  // truncated file an error of one line (libpng's own lines kept off
  // stderr), before the module's copy trusts it.
  read_stored_pixels(source, "texture");  // its own 8 or 16 bits: not 4 bytes a channel
  std::vector<unsigned char> png;
  std::string err;
  switch (image_module::api().rgb_png(source.c_str(), &png, &err)) {
    case 0:
      break;
    case 1:
      throw InputError(located(source.string(), 0, "cannot read image: " + err));
    default:
      throw InputError(located(dest.string(), 0, "cannot encode PNG: " + err));
  }
  write_atomically(
      dest, [&](const std::filesystem::path& tmp) { write_bytes_checked(tmp, png.data(), png.size(), dest.string()); });
}

}  // namespace ra
