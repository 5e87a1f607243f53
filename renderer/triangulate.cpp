#include "triangulate.h"

#include <cmath>

namespace ra {
namespace {

using P2 = std::array<double, 2>;

// Twice the signed area of (a, b, c): > 0 when counter-clockwise.
double orient2(const P2& a, const P2& b, const P2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

// p inside or on the boundary of the counter-clockwise triangle (a, b, c).
bool in_triangle(const P2& p, const P2& a, const P2& b, const P2& c) {
  return orient2(a, b, p) >= 0 && orient2(b, c, p) >= 0 && orient2(c, a, p) >= 0;
}

}  // namespace

void triangulate_polygon(const Vec3d* pts, int n, std::vector<std::array<int, 3>>& out,
                         EarClipScratch& s) {
  if (n < 3) return;
  if (n == 3) {
    out.push_back({0, 1, 2});
    return;
  }
  // Newell normal, relative to pts[0].
  const Vec3d o = pts[0];
  Vec3d nn{0, 0, 0};
  for (int i = 0; i < n; ++i) {
    Vec3d a = pts[i] - o, b = pts[(i + 1) % n] - o;
    nn.x += (a.y - b.y) * (a.z + b.z);
    nn.y += (a.z - b.z) * (a.x + b.x);
    nn.z += (a.x - b.x) * (a.y + b.y);
  }
  // Drop the dominant axis; keep a right-handed (u, v) so the polygon is
  // counter-clockwise when its normal points along +axis, then flip if not.
  const Vec3d an = abs(nn);
  const int axis = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double sign = nn[axis] < 0 ? -1.0 : 1.0;
  s.q.resize(size_t(n));
  for (int i = 0; i < n; ++i) {
    Vec3d d = pts[i] - o;
    s.q[size_t(i)] = {d[u], sign * d[v]};
  }
  s.remaining.resize(size_t(n));
  for (int i = 0; i < n; ++i) s.remaining[size_t(i)] = i;
  auto& r = s.remaining;
  const auto& q = s.q;
  while (r.size() > 3) {
    const size_t m = r.size();
    size_t ear = m;  // none found yet
    // Try corners 1, 2, ..., m-1, 0 so that a convex polygon gives a fan at 0.
    for (size_t k = 0; k < m && ear == m; ++k) {
      const size_t i = (k + 1) % m;
      const int ip = r[(i + m - 1) % m], ic = r[i], in = r[(i + 1) % m];
      const P2 &a = q[size_t(ip)], &b = q[size_t(ic)], &c = q[size_t(in)];
      if (!(orient2(a, b, c) > 0)) continue;  // reflex or flat corner
      bool empty = true;
      for (size_t j = 0; j < m && empty; ++j) {
        const int iv = r[j];
        if (iv == ip || iv == ic || iv == in) continue;
        const P2& p = q[size_t(iv)];
        if (p == a || p == b || p == c) continue;  // duplicated vertex
        empty = !in_triangle(p, a, b, c);
      }
      if (empty) ear = i;
    }
    if (ear == m) ear = 1;  // degenerate or not simple: cut corner 1 anyway
    out.push_back({r[(ear + m - 1) % m], r[ear], r[(ear + 1) % m]});
    r.erase(r.begin() + long(ear));
  }
  out.push_back({r[0], r[1], r[2]});
}

}  // namespace ra
