#include "bump.h"

#include <cmath>

namespace ra {

std::optional<UvBasis> uv_basis(const Vec3d& a, const Vec3d& b, const Vec3d& c, const std::array<double, 2>& ta,
                                const std::array<double, 2>& tb, const std::array<double, 2>& tc) {
  // UV edges AB, AC; solve (1,0) = px AB + qx AC and (0,1) = py AB + qy AC.
  const double e1u = tb[0] - ta[0], e1v = tb[1] - ta[1];
  const double e2u = tc[0] - ta[0], e2v = tc[1] - ta[1];
  const double det = e1u * e2v - e2u * e1v;
  if (det == 0 || !std::isfinite(det)) return std::nullopt;
  const double px = e2v / det, qx = -e1v / det;
  const double py = -e2u / det, qy = e1u / det;
  const Vec3d ab = b - a, ac = c - a;
  const Vec3d tu = ab * px + ac * qx, tv = ab * py + ac * qy;
  const double lu = length(tu), lv = length(tv);
  if (!(lu > 0) || !(lv > 0)) return std::nullopt;
  return UvBasis{tu / lu, tv / lv};
}

Texture height_derivatives(const Texture& h) {
  Texture d(h.width, h.height);
  auto intensity = [&](int x, int y) {
    const Vec3d c = h.texel(x, y);
    return (c.x + c.y + c.z) / 3;
  };
  for (int y = 0; y < h.height; ++y)
    for (int x = 0; x < h.width; ++x) {
      const double i = intensity(x, y);
      d.set(x, y, {i - intensity(x + 1, y), i - intensity(x, y + 1), 0});
    }
  return d;
}

namespace {
Vec3d normalized_or(const Vec3d& v, const Vec3d& fallback) {
  const double len = length(v);
  return len > 0 && std::isfinite(len) ? v / len : fallback;
}
}  // namespace

Vec3d bump_height(const Vec3d& n, const Texture& deriv, TextureFilter filter, double strength, double u, double v,
                  const UvBasis& basis) {
  const Vec3d s = deriv.sample(u, v, filter);
  if (s.x == 0 && s.y == 0) return n;  // n += 0: no renormalisation either
  // Image +y runs towards -v.
  return normalized_or(n + (basis.tu * s.x - basis.tv * s.y) * strength, n);
}

Vec3d bump_normal_map(const Vec3d& n, const Texture& map, TextureFilter filter, double strength, double u, double v,
                      const UvBasis& basis) {
  const Vec3d c = map.sample(u, v, filter);
  const Vec3d d = c * 2.0 - Vec3d{1, 1, 1};
  if (d.x == 0 && d.y == 0 && d.z > 0) return n;  // no deflection
  return normalized_or((basis.tu * d.x + basis.tv * d.y) * strength + n * d.z, n);
}

Vec3d bump_pov(const Vec3d& n, const Texture& image, TextureFilter filter, double bump_size, double u, double v) {
  double x, y;
  image.image_coords(u, v, x, y);
  const double w = image.width, h = image.height;
  auto tap = [&](double tx, double ty) {
    const Vec3d c = filter == TextureFilter::nearest ? image.nearest_xy(tx, ty) : image.bilinear_xy(tx, ty);
    // POV keeps colours in float (COLC).
    return double(float(0.297 * float(c.x) + 0.589 * float(c.y) + 0.114 * float(c.z)));
  };
  const double g1 = tap(x, y);
  x -= 1;
  y += 1;
  if (x < 0)
    x += w;
  else if (x >= w)
    x -= w;
  if (y < 0)
    y += h;
  else if (y >= h)
    y -= h;
  const double g2 = tap(x, y);
  x += 2;
  if (x < 0)
    x += w;
  else if (x >= w)
    x -= w;
  const double g3 = tap(x, y);
  const Vec3d p1{0, bump_size * g1, 0}, p2{-1, bump_size * g2, 1}, p3{1, bump_size * g3, 1};
  const Vec3d bn = normalize(cross(p3 - p2, p1 - p2));
  Vec3d yp = n;
  Vec3d xp = cross(yp, Vec3d{0, 1, 0});
  double len = length(xp);
  constexpr double kPovEpsilon = 1e-10;
  if (len < kPovEpsilon) {
    yp = std::fabs(n.y - 1.0) < kPovEpsilon ? Vec3d{0, 1, 0} : Vec3d{0, -1, 0};
    xp = {1, 0, 0};
    len = 1;
  }
  xp = xp / len;
  const Vec3d zp = normalize(cross(xp, yp));
  return xp * bn.x + yp * bn.y - zp * bn.z;
}

}  // namespace ra
