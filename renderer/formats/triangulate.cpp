#include "triangulate.h"

#include <algorithm>
#include <cmath>
#include <vector>

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

bool triangulate_polygon(const Vec3d* pts, int n, std::vector<std::array<int, 3>>& out, EarClipScratch& s) {
  if (n < 3) return false;
  if (n == 3) {
    out.push_back({0, 1, 2});
    return false;
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
  // The polygon as a doubly linked ring, so cutting a corner is O(1).
  s.next.resize(size_t(n));
  s.prev.resize(size_t(n));
  s.alive.assign(size_t(n), 1);
  for (int i = 0; i < n; ++i) {
    s.next[size_t(i)] = (i + 1) % n;
    s.prev[size_t(i)] = (i + n - 1) % n;
  }
  const auto& q = s.q;
  auto& next = s.next;
  auto& prev = s.prev;
  auto convex = [&](int k) {
    return orient2(q[size_t(prev[size_t(k)])], q[size_t(k)], q[size_t(next[size_t(k)])]) > 0;
  };
  // Only a corner that is not convex can lie inside an ear (Meisters), so
  // only those are tested, found through a uniform grid of about one cell
  // each: a convex polygon costs O(n), a small ear O(1) tests.
  // The grid spans the reflex corners alone: an ear's box is clamped to it
  // (the clamped cells still hold every reflex corner the box holds). Over
  // the whole polygon, a star's inner corners, 1% of its radius from the
  // centre, shared one or two cells, so every spike's ear scanned all of
  // them: 2,000 corners spent the work limit and came out as a fan 118
  // times the star's area.
  s.reflex.clear();
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  for (int i = 0; i < n; ++i) {
    if (convex(i)) continue;
    const P2& p = q[size_t(i)];
    if (s.reflex.empty()) x0 = x1 = p[0], y0 = y1 = p[1];
    x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]);
    y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
    s.reflex.push_back(i);
  }
  const int g = std::max(1, int(std::sqrt(double(s.reflex.size()))));
  const double sx = x1 > x0 ? g / (x1 - x0) : 0, sy = y1 > y0 ? g / (y1 - y0) : 0;
  auto cell = [&](double v, double lo, double scale) {
    const double c = (v - lo) * scale;
    return !(c > 0) ? 0 : (c >= g - 1 ? g - 1 : int(c));  // NaN (inf - inf) too: cell 0
  };
  s.cell_start.assign(size_t(g) * size_t(g) + 1, 0);
  for (int w : s.reflex)
    ++s.cell_start[size_t(cell(q[size_t(w)][1], y0, sy)) * size_t(g) + size_t(cell(q[size_t(w)][0], x0, sx)) + 1];
  for (size_t k = 1; k < s.cell_start.size(); ++k) s.cell_start[k] += s.cell_start[k - 1];
  s.cell_items.resize(s.reflex.size());
  {
    std::vector<int> fill(s.cell_start.begin(), s.cell_start.end() - 1);
    for (int w : s.reflex)
      s.cell_items[size_t(
          fill[size_t(cell(q[size_t(w)][1], y0, sy)) * size_t(g) + size_t(cell(q[size_t(w)][0], x0, sx))]++)] = w;
  }
  // Work limit (see triangulate.h): beyond it the rest is cut as a fan.
  long budget = kEarClipWorkPerCorner * long(n);
  int m = n, cur = 1, since_cut = 0;
  bool limited = false;
  while (m > 3) {
    const int a_i = prev[size_t(cur)], c_i = next[size_t(cur)];
    bool ear = false;
    if (budget > 0 && convex(cur)) {
      ear = true;
      const P2 &a = q[size_t(a_i)], &b = q[size_t(cur)], &c = q[size_t(c_i)];
      const int cx0 = cell(std::min({a[0], b[0], c[0]}), x0, sx), cx1 = cell(std::max({a[0], b[0], c[0]}), x0, sx);
      const int cy0 = cell(std::min({a[1], b[1], c[1]}), y0, sy), cy1 = cell(std::max({a[1], b[1], c[1]}), y0, sy);
      for (int cy = cy0; cy <= cy1 && ear; ++cy)
        for (int cx = cx0; cx <= cx1 && ear; ++cx) {
          const size_t k = size_t(cy) * size_t(g) + size_t(cx);
          --budget;
          for (int it = s.cell_start[k]; it < s.cell_start[k + 1]; ++it) {
            const int w = s.cell_items[size_t(it)];
            --budget;
            if (!s.alive[size_t(w)] || w == a_i || w == cur || w == c_i) continue;
            const P2& p = q[size_t(w)];
            if (p == a || p == b || p == c) continue;  // duplicated vertex
            if (in_triangle(p, a, b, c)) {
              ear = false;
              break;
            }
          }
        }
    }
    --budget;
    if (!ear && budget > 0 && since_cut < m) {  // try the next corner
      cur = c_i;
      ++since_cut;
      continue;
    }
    // An ear, or none in a whole turn (degenerate or not simple), or the
    // work limit spent: cut this corner anyway, so the count still holds.
    limited = limited || (!ear && budget <= 0);
    out.push_back({a_i, cur, c_i});
    s.alive[size_t(cur)] = 0;
    next[size_t(a_i)] = c_i;
    prev[size_t(c_i)] = a_i;
    --m;
    cur = c_i;
    since_cut = 0;
  }
  out.push_back({prev[size_t(cur)], cur, next[size_t(cur)]});
  return limited;
}

}  // namespace ra
