#include "texture.h"

#include <cmath>
#include <new>
#include <optional>

#include "../errors.h"
#include "../image.h"

namespace ra {
namespace {

// POV-Ray's wrap(): into [0, m).
double wrap(double v, double m) {
  v = std::fmod(v, m);
  if (v < 0) v += m;
  return v >= m ? 0.0 : v;  // -tiny + m may round up to m
}

int wrap_int(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

}  // namespace

Texture::Texture(StoredPixels&& p)
    : width(p.width),
      height(p.height),
      channels(p.channels),
      rgb(std::move(p.f)),
      u8(std::move(p.u8)),
      u16(std::move(p.u16)) {}

Vec3d Texture::texel(int x, int y) const {
  const std::size_t i = (std::size_t(wrap_int(y, height)) * width + wrap_int(x, width)) * std::size_t(channels);
  // OpenImageIO's uint8/uint16 -> float conversion (fmath.h convert_type).
  auto at = [&](std::size_t k) -> float {
    if (!u8.empty()) return float(u8[k]) * (1.0f / 255.0f);
    if (!u16.empty()) return float(u16[k]) * (1.0f / 65535.0f);
    return rgb[k];
  };
  if (channels == 1) {
    const float g = at(i);
    return {g, g, g};
  }
  return {at(i), at(i + 1), at(i + 2)};
}

void Texture::set(int x, int y, const Vec3d& c) {
  float* p = &rgb[(std::size_t(y) * width + x) * 3];  // made in code: float RGB
  p[0] = float(c.x);
  p[1] = float(c.y);
  p[2] = float(c.z);
}

void Texture::image_coords(double u, double v, double& x, double& y) const {
  const double w = width, h = height;
  x = wrap(std::fmod(u * w, w) + kPovImageEpsilon, w);
  y = wrap(-(std::fmod(v * h, h) + kPovImageEpsilon), h);
}

Vec3d Texture::nearest_xy(double x, double y) const { return texel(int(x), int(y)); }

Vec3d Texture::bilinear_xy(double x, double y) const {
  x += 0.5;
  y += 0.5;
  const int ix = int(x), iy = int(y);
  const double p = x - ix, q = y - iy;
  return texel(ix, iy) * (p * q) + texel(ix - 1, iy) * ((1 - p) * q) + texel(ix, iy - 1) * (p * (1 - q)) +
         texel(ix - 1, iy - 1) * ((1 - p) * (1 - q));
}

Vec3d Texture::nearest(double u, double v) const {
  double x, y;
  image_coords(u, v, x, y);
  return nearest_xy(x, y);
}

Vec3d Texture::bilinear(double u, double v) const {
  double x, y;
  image_coords(u, v, x, y);
  return bilinear_xy(x, y);
}

Texture load_texture(const std::filesystem::path& file) {
  // Read straight into the texture's own storage: no float copy on the way.
  return Texture(read_stored_pixels(file, "texture"));
}

const Texture& TextureCache::load(const std::filesystem::path& file) {
  const std::string key = file.lexically_normal().string();
  auto& slot = by_file_[key];
  if (!slot) slot = std::make_unique<Texture>(load_texture(file));
  return *slot;
}

const Texture* TextureCache::find(const std::filesystem::path& file) const {
  auto it = by_file_.find(file.lexically_normal().string());
  return it == by_file_.end() ? nullptr : it->second.get();
}

}  // namespace ra
