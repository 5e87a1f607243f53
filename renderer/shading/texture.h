// Image textures looked up by (u, v) exactly as POV-Ray 3.7 does for a
// uv_mapped image_map (imageutil.cpp, map_pos / no_interpolation / Interp):
//   x = wrap(u W + EPSILON, W),  y = wrap(-(fmod(v H, H) + EPSILON), H)
// so v = 0 is the BOTTOM row (as in OBJ), both axes repeat, and
//  - nearest: the texel (int x, int y);
//  - bilinear (POV's `interpolate 2`): texel centres at +0.5, the four
//    texels around (x + 0.5, y + 0.5), wrapping at the borders.
// Values are raw: a PNG's 8-bit v is v / 255, no gamma decoding.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "../image.h"
#include "../scene/scene.h"
#include "../vec.h"

namespace ra {

// POV-Ray 3.7's EPSILON, added to image coordinates in map_pos.
inline constexpr double kPovImageEpsilon = 1e-10;

// Texels are kept as the file has them (image.h's StoredPixels: grey or
// RGB, 8 or 16 bits or float), row-major, row 0 at the top; an 8-bit v
// reads as float(v) * (1.0f / 255), exactly OpenImageIO's conversion, so
// lookups are bit for bit those of a float copy, in a quarter (RGB) to a
// twelfth (grey) of its memory. Textures made in code (set()) are float RGB.
struct Texture {
  int width = 0, height = 0;
  int channels = 3;              // 1: grey, 3: RGB
  std::vector<float> rgb;        // float texels (made in code, or a float file)
  std::vector<std::uint8_t> u8;  // an 8-bit file's
  std::vector<std::uint16_t> u16;

  Texture() = default;
  Texture(int w, int h) : width(w), height(h), rgb(std::size_t(w) * h * 3, 0.f) {}
  explicit Texture(StoredPixels&& p);

  // The texel at integer (x, y), both wrapped into the image.
  Vec3d texel(int x, int y) const;
  void set(int x, int y, const Vec3d& c);
  // Continuous image coordinates of (u, v), in [0, W) x [0, H).
  void image_coords(double u, double v, double& x, double& y) const;
  Vec3d nearest(double u, double v) const;
  Vec3d bilinear(double u, double v) const;
  Vec3d sample(double u, double v, TextureFilter f) const {
    return f == TextureFilter::nearest ? nearest(u, v) : bilinear(u, v);
  }
  // Lookups at image coordinates (x, y) already inside the image.
  Vec3d nearest_xy(double x, double y) const;
  Vec3d bilinear_xy(double x, double y) const;
};

// Reads any image OpenImageIO reads: 1 or 2 channels are grey (+ alpha),
// 3 or more are RGB (alpha ignored). Throws InputError.
Texture load_texture(const std::filesystem::path& file);

// Every texture a scene's materials name, loaded once before rendering;
// read-only afterwards, so any thread may look up.
class TextureCache {
 public:
  // Loads `file` unless already loaded.
  const Texture& load(const std::filesystem::path& file);
  // nullptr when not loaded.
  const Texture* find(const std::filesystem::path& file) const;

 private:
  std::map<std::string, std::unique_ptr<Texture>> by_file_;
};

}  // namespace ra
