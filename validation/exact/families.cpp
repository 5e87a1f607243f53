// Case families: random, edge, vertex, grazing, offset, distance, scale,
// sliver, near-miss, degenerate, closed-mesh (Embree's WatertightTest placement), secondary, refracted; spheres
// huge, tiny-far, near-origin, refracted.
#include "families.h"

#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace ra::audit {

const char* precision_name(Precision p) { return p == Precision::f32 ? "float" : "double"; }

namespace {

// ------------------------------------------------------------------- rng ---
// SplitMix64: tiny, fast, and every stream is independent given its seed.
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  int below(int n) { return int(next() % std::uint64_t(n)); }
  Vec3d in_cube(double h) { return {uniform(-h, h), uniform(-h, h), uniform(-h, h)}; }
  Vec3d unit() {
    for (;;) {
      const Vec3d v = in_cube(1);
      const double l2 = dot(v, v);
      if (l2 > 1e-4 && l2 <= 1) return v / std::sqrt(l2);
    }
  }
};

// An orthonormal frame (u, w) perpendicular to the unit vector e.
void frame(const Vec3d& e, Vec3d& u, Vec3d& w) {
  const Vec3d h = std::abs(e.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
  u = normalize(cross(e, h));
  w = cross(e, u);
}

// ------------------------------------------------------------- sweeps ---
const std::vector<double> kOffsets = {0, 1e1, 1e3, 1e5, 1e7};
const std::vector<double> kOffsetFamily = {1, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7};
// distance: the triangle alone is moved this far; the ray still starts near
// the origin, as a camera's primary ray does (offset moves both).
const std::vector<double> kTriangleDistances = {1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
const std::vector<double> kAngles = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
const std::vector<double> kScaleLo = {1e-8, 1e-4, 1, 1e4};  // each bucket spans 4 decades
const std::vector<double> kAspects = {1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
const std::vector<int> kNearMissUlps = {1, 8, 64};
const std::vector<std::string> kDegenerate = {"collinear", "repeated-vertex", "zero-direction", "near-collinear"};
// The secondary family runs over the scale family's sweep (1e-8..1e8, 4 decades per value).
const std::vector<double>& kSecondaryScales = kScaleLo;
const std::vector<std::string> kStrategies = {"eps", "pov", "normal-offset", "ulp-offset"};
const std::vector<double> kHugeRadii = {1e4, 1e5, 1e6, 1e7};
const std::vector<double> kFarDistances = {1e2, 1e4, 1e6, 1e8};
const std::vector<double> kNearDistances = {1e-1, 1e-3, 1e-5, 1e-7};
// Embree's WatertightTest puts its closed meshes here (tutorials/verify).
const Vec3d kEmbreePlacement{148376, 1234, -223423};

std::string label(double v) {
  if (v == 0) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
template <class C>
std::vector<std::string> labels(const C& c, const std::string& prefix = "") {
  std::vector<std::string> out;
  for (const auto& v : c) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string>)
      out.push_back(prefix + v);
    else
      out.push_back(prefix + label(double(v)));
  }
  return out;
}

// ------------------------------------------------------------- meshes ---
struct Mesh {
  std::vector<Vec3d> v;
  std::vector<std::array<int, 3>> f;
};

// An icosahedron subdivided once (80 triangles) projected on a sphere of
// radius 2 (Embree's test sphere radius), outward winding.
Mesh icosphere() {
  const double g = (1 + std::sqrt(5.0)) / 2;
  Mesh m;
  m.v = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  m.f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  std::vector<std::array<int, 3>> f2;
  auto mid = [&](int i, int j) {
    m.v.push_back((m.v[i] + m.v[j]) * 0.5);
    return int(m.v.size()) - 1;
  };
  // Midpoints are created once per face here and may duplicate: merge them so
  // neighbouring faces share vertex indices (and so exact coordinates).
  std::vector<std::array<int, 3>> mids;
  auto shared_mid = [&](int i, int j) {
    for (const auto& e : mids)
      if ((e[0] == i && e[1] == j) || (e[0] == j && e[1] == i)) return e[2];
    const int k = mid(i, j);
    mids.push_back({i, j, k});
    return k;
  };
  for (const auto& t : m.f) {
    const int ab = shared_mid(t[0], t[1]), bc = shared_mid(t[1], t[2]), ca = shared_mid(t[2], t[0]);
    f2.push_back({t[0], ab, ca});
    f2.push_back({t[1], bc, ab});
    f2.push_back({t[2], ca, bc});
    f2.push_back({ab, bc, ca});
  }
  m.f = f2;
  for (auto& p : m.v) p = normalize(p) * 2.0;
  return m;
}

// The cube [-1, 1]^3 as 12 triangles, outward winding.
Mesh box() {
  Mesh m;
  for (int i = 0; i < 8; ++i) m.v.push_back({i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : -1.0});
  m.f = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
         {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

const Mesh& closed_mesh(int shape) {
  static const Mesh s = icosphere(), b = box();
  return shape == 0 ? s : b;
}

// --------------------------------------------------------- rounding ---
// to_float32 (vec.h), not Vec3d(Vec3f(v)): GCC 12.2 can drop that rounding.
Vec3d to_float(const Vec3d& v) { return to_float32(v); }
double to_float(double x) { return to_float32(x); }
void round_to_float(TriangleBatch& b, std::size_t tri0, std::size_t probe0) {
  for (std::size_t i = tri0; i < b.tris.size(); ++i)
    b.tris[i] = {to_float(b.tris[i].a), to_float(b.tris[i].b), to_float(b.tris[i].c)};
  for (std::size_t i = probe0; i < b.probes.size(); ++i) {
    Rayd& r = b.probes[i].ray;
    r = {to_float(r.o), to_float(r.d), to_float(r.tmin), to_float(r.tmax)};
  }
}

// One ulp step of x toward +inf or -inf in the requested precision.
double step_ulps(double x, int dir, int ulps, Precision p) {
  for (int i = 0; i < ulps; ++i) {
    if (p == Precision::f32)
      x = std::nextafter(float(x), dir > 0 ? INFINITY : -INFINITY);
    else
      x = std::nextafter(x, dir > 0 ? INFINITY : -INFINITY);
  }
  return x;
}

// A grid on which every sum and difference the families form is exact in
// the requested precision: multiples of h = 2^(E - P) with |x| < 2^E are
// representable (P = 24 or 53), and so is the difference of two of them when
// it stays below 2^E. Rays built as o = grid point, d = target - o (exact)
// reach target exactly at t = 1: the exact crossing is the intended point.
struct Grid {
  double h;
  explicit Grid(double bound, Precision p) {
    const int e = std::ilogb(bound) + 1;  // 2^e > bound
    h = std::ldexp(1.0, e - (p == Precision::f32 ? 24 : 53));
  }
  double snap(double x) const { return std::nearbyint(x / h) * h; }
  Vec3d snap(const Vec3d& v) const { return {snap(v.x), snap(v.y), snap(v.z)}; }
};

// Size of the local configuration at an offset: 1, or 64 grid steps when the
// precision cannot resolve a unit-size configuration there (float at 1e7,
// where the spacing is 1): a unit triangle would collapse onto a few points.
double local_scale(double offset, Precision p) { return std::max(1.0, 64 * Grid(offset + 16, p).h); }

// ---------------------------------------------------- triangle makers ---
void add_single(TriangleBatch& b, const Tri& t, const Rayd& r) {
  b.tris.push_back(t);
  b.probes.push_back({r, int(b.tris.size()) - 1, 1});
}

Rayd aimed(const Vec3d& o, const Vec3d& target) { return {o, target - o}; }

// True when every triangle faces direction d the same way, clearly (not
// edge-on): then the group does not fold over itself seen along d, and a
// line through a shared edge or vertex must meet one of them (what a
// watertight method promises). Other groups are not judged for leaks.
bool faces_alike(const std::vector<Tri>& tris, const Vec3d& d) {
  int sign = 0;
  for (const Tri& t : tris) {
    const Vec3d n = cross(t.b - t.a, t.c - t.a);
    const double nd = dot(n, d);
    if (!(std::abs(nd) > 1e-6 * length(n) * length(d))) return false;
    const int s = nd > 0 ? 1 : -1;
    if (sign != 0 && s != sign) return false;
    sign = s;
  }
  return true;
}

// A triangle in [-1,1]^3 and a ray from [-4,4]^3 aimed into its bounding box
// grown by `spread` about its centre (spread 1: the box itself).
void random_case(Rng& g, double spread, double scale, const Vec3d& offset, TriangleBatch& b) {
  Tri t{g.in_cube(1), g.in_cube(1), g.in_cube(1)};
  const Vec3d lo = vmin(t.a, vmin(t.b, t.c)), hi = vmax(t.a, vmax(t.b, t.c));
  const Vec3d mid = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
  const Vec3d aim = mid + mul(half, g.in_cube(1)) * spread;
  const Vec3d o = g.in_cube(4);
  auto place = [&](const Vec3d& p) { return p * scale + offset; };
  add_single(b, {place(t.a), place(t.b), place(t.c)}, aimed(place(o), place(aim)));
}

Vec3d random_offset(Rng& g, double magnitude) { return g.unit() * magnitude; }

// A random triangle of size about 1 moved `distance` away in a random
// direction, and a ray from near the origin aimed inside its box. Long rays
// to small triangles are where conservative error bounds on t bite: pbrt-v4's
// watertight test rejects t <= deltaT (Woop et al. 2013 with pbrt's bounds),
// and deltaT grows with the triangle's distance while the edge functions
// shrink with its size (the crack maps showed float watertight missing a
// whole small triangle about 1e5 away).
void distant_case(Rng& g, double distance, TriangleBatch& b) {
  const Tri t{g.in_cube(1), g.in_cube(1), g.in_cube(1)};
  const Vec3d lo = vmin(t.a, vmin(t.b, t.c)), hi = vmax(t.a, vmax(t.b, t.c));
  const Vec3d aim = (lo + hi) * 0.5 + mul((hi - lo) * 0.5, g.in_cube(1));
  const Vec3d o = g.in_cube(4);
  const Vec3d off = random_offset(g, distance);
  add_single(b, {t.a + off, t.b + off, t.c + off}, aimed(o, aim + off));
}

// A segment from p (on the grid) of m equal grid vectors e toward a random
// point of the cube of half-size `size` about `centre`: every p + j e is a
// representable point exactly on the segment. Only e's with at least `min_steps`
// grid steps in their largest component (so directions stay varied) and, when
// `not_along` >= 0, a component off that axis.
struct GridSegment {
  Vec3d p, e;
  long long m;
  Vec3d at(long long j) const { return p + e * double(j); }
  Vec3d q() const { return at(m); }
};
GridSegment grid_segment(Rng& g, const Grid& grid, const Vec3d& centre, double size, int not_along = -1) {
  for (;;) {
    GridSegment s;
    s.p = grid.snap(centre + g.in_cube(size));
    const Vec3d q0 = centre + g.in_cube(size);
    const Vec3d span = (q0 - s.p) / grid.h;
    const double big = std::max(std::abs(span.x), std::max(std::abs(span.y), std::abs(span.z)));
    s.m = std::min<long long>(2 + g.below(255), (long long)(big / 8));
    if (s.m < 2 || big < 0.3 * size / grid.h) continue;
    const double md = double(s.m);
    s.e = Vec3d{std::nearbyint(span.x / md), std::nearbyint(span.y / md), std::nearbyint(span.z / md)} * grid.h;
    if (not_along >= 0) {
      Vec3d rest = s.e;
      rest[not_along] = 0;
      if (rest == Vec3d{0, 0, 0}) continue;
    }
    return s;
  }
}
// A random interior index of a segment of m steps, within [lo, hi] of it.
long long interior_step(Rng& g, long long m, double lo, double hi) {
  const long long a = std::max(1LL, (long long)std::ceil(lo * double(m)));
  const long long z = std::min(m - 1, (long long)std::floor(hi * double(m)));
  return a + (z > a ? (long long)(g.next() % std::uint64_t(z - a + 1)) : 0);
}
// Three aims in four are the exact point; the rest are moved up to 4 grid
// steps per coordinate (rays just beside the edge or vertex, still exact rays).
Vec3d maybe_jitter(Rng& g, const Grid& grid, const Vec3d& x) {
  if (g.below(4) != 0) return x;
  return x + Vec3d{double(g.below(9) - 4), double(g.below(9) - 4), double(g.below(9) - 4)} * grid.h;
}

// Two triangles sharing edge pq, folded by a random dihedral, and a ray
// crossing pq exactly at a representable point of it (or, one ray in four,
// a few grid steps beside it). Every coordinate is on a grid of the requested
// precision (see Grid), the aim is p + j e exactly, and d = aim - o exactly.
void edge_case(Rng& g, double offset, Precision prec, TriangleBatch& b) {
  const double L = local_scale(offset, prec);
  const Grid grid(offset + 16 * L, prec);
  const Vec3d off = random_offset(g, offset);
  const GridSegment seg = grid_segment(g, grid, off, L);
  const Vec3d p = seg.p, q = seg.q();
  const Vec3d e = normalize(q - p);
  Vec3d u, w;
  frame(e, u, w);
  const Vec3d m = (p + q) * 0.5;
  const double h1 = g.uniform(0.3, 1.5), h2 = g.uniform(0.3, 1.5);
  const Vec3d r1 = grid.snap(m + (u * h1 + w * (h1 * g.uniform(-0.5, 0.5))) * L);
  const Vec3d r2 = grid.snap(m - (u * h2 + w * (h2 * g.uniform(-0.5, 0.5))) * L);
  const Vec3d aim = maybe_jitter(g, grid, seg.at(interior_step(g, seg.m, 0.05, 0.95)));
  const Tri t1{p, q, r1}, t2{q, p, r2};
  Vec3d o;
  for (int tries = 0; tries < 64; ++tries) {
    // (one draw per statement: the order of draws must not depend on the compiler)
    const double side = g.below(2) ? 1.0 : -1.0;
    const Vec3d jit = g.in_cube(0.7);
    o = grid.snap(aim + (w * side + jit) * (g.uniform(1, 3) * L));
    if (faces_alike({t1, t2}, aim - o)) break;
  }
  b.tris.push_back(t1);
  b.tris.push_back(t2);
  b.probes.push_back({aimed(o, aim), int(b.tris.size()) - 2, 2});
}

// A closed fan of 3..8 triangles around vertex v (a shallow cone), and a ray
// aimed exactly at v (one in four: a few grid steps beside it) from within
// 60 degrees of the cone's axis; on the grid as edge_case.
void vertex_case(Rng& g, double offset, Precision prec, TriangleBatch& b) {
  const double L = local_scale(offset, prec);
  const Grid grid(offset + 16 * L, prec);
  const Vec3d local = g.in_cube(1) * L;
  const Vec3d v = grid.snap(local + random_offset(g, offset));
  const Vec3d e = g.unit();
  Vec3d u, w;
  frame(e, u, w);
  const int k = 3 + g.below(6);
  std::vector<Vec3d> ring;
  for (int i = 0; i < k; ++i) {
    const double ang = 2 * std::numbers::pi * (i + g.uniform(-0.3, 0.3)) / k;
    const double radial = g.uniform(0.5, 1.5);
    ring.push_back(grid.snap(v + ((u * std::cos(ang) + w * std::sin(ang)) * radial + e * g.uniform(-0.3, 0.3)) * L));
  }
  const int first = int(b.tris.size());
  for (int i = 0; i < k; ++i) b.tris.push_back({v, ring[i], ring[(i + 1) % k]});
  const double side = g.below(2) ? 1.0 : -1.0;
  const std::vector<Tri> fan(b.tris.begin() + first, b.tris.end());
  const Vec3d aim = maybe_jitter(g, grid, v);
  Vec3d o;
  for (int tries = 0; tries < 64; ++tries) {
    const double su = g.uniform(-1, 1);
    const Vec3d dir = normalize(e * side + (u * su + w * g.uniform(-1, 1)) * 1.7);
    o = grid.snap(v + dir * (g.uniform(1, 3) * L));
    if (faces_alike(fan, aim - o)) break;
  }
  b.probes.push_back({aimed(o, aim), first, k});
}

// A unit-size triangle and a ray meeting its plane at `angle` radians, aimed
// at barycentrics in [-0.2, 1.2] (about half hits).
void grazing_case(Rng& g, double angle, TriangleBatch& b) {
  const Vec3d n = g.unit();
  Vec3d u, w;
  frame(n, u, w);
  const Vec3d base = g.in_cube(1);
  const Tri t{base, base + u * g.uniform(0.5, 1.5), base + (u * g.uniform(-0.5, 0.5) + w) * g.uniform(0.5, 1.5)};
  const double b1 = g.uniform(-0.2, 1.2), b2 = g.uniform(-0.2, 1.2) * (1 - b1);
  const Vec3d aim = t.a + (t.b - t.a) * b1 + (t.c - t.a) * b2;
  const double az = g.uniform(0, 2 * std::numbers::pi);
  const Vec3d inplane = u * std::cos(az) + w * std::sin(az);
  const Vec3d dir = inplane * std::cos(angle) + n * (std::sin(angle) * (g.below(2) ? 1 : -1));
  add_single(b, t, aimed(aim - dir * g.uniform(1, 10), aim));
}

// A triangle of base 1 and height 1/aspect, randomly oriented.
void sliver_case(Rng& g, double aspect, TriangleBatch& b) {
  const Vec3d e = g.unit();
  Vec3d u, w;
  frame(e, u, w);
  const Vec3d a = g.in_cube(1), bb = a + e, c = a + e * g.uniform(0, 1) + u / aspect;
  const double s = g.uniform(-0.1, 1.1), h = g.uniform(-0.5, 1.5);
  const Vec3d aim = a + e * s + u * (h / aspect);
  const Vec3d o = aim + (w * (g.below(2) ? 1.0 : -1.0) + g.in_cube(0.7)) * g.uniform(1, 3);
  add_single(b, {a, bb, c}, aimed(o, aim));
}

// A triangle whose plane contains the axis direction x_k, an exact grid point
// X of one of its edges, and Y = X stepped `ulps` ulps (of the precision) along
// x_k away from the opposite vertex: Y lies in the plane, outside the edge, and
// is representable. The ray has d_k = 0 and o = Y - d (exact), so it crosses
// the plane exactly at Y: an exact miss by construction (checked by a test).
void near_miss_case(Rng& g, int ulps, Precision p, TriangleBatch& b) {
  const Grid grid(16, p);
  const int k = g.below(3);
  Vec3d ek{0, 0, 0};
  ek[k] = 1;
  const GridSegment seg = grid_segment(g, grid, {0, 0, 0}, 1, k);
  const Vec3d X = seg.at(interior_step(g, seg.m, 0.1, 0.9));
  const double sigma = g.below(2) ? 1.0 : -1.0;  // Y is on the +sigma x_k side
  // The opposite vertex: on the edge's line shifted by -sigma c x_k, so the
  // plane is spanned by e and x_k and the vertex is on the other side.
  const long long jo = (long long)(g.next() % std::uint64_t(seg.m + 1));
  const Vec3d opp = seg.at(jo) - ek * (sigma * grid.snap(g.uniform(0.3, 1.5)));
  Vec3d Y = X;
  Y[k] = step_ulps(X[k], sigma > 0 ? 1 : -1, ulps, p);
  const Vec3d n = normalize(cross(seg.e, ek)) * (g.below(2) ? 1.0 : -1.0);
  Vec3d noise = g.in_cube(0.5);
  noise[k] = 0;
  Vec3d d = grid.snap((n + noise) * g.uniform(0.5, 2));
  d[k] = 0;
  const Vec3d o = Y - d;
  add_single(b, {seg.p, seg.q(), opp}, {o, d});
}

// Zero-area triangles built exactly (coordinates on a 1/16 grid, so sums
// are exact in float too), a zero direction, and rounded near-collinear ones.
void degenerate_case(Rng& g, int kind, TriangleBatch& b) {
  auto grid = [&](double h) {
    return Vec3d{std::round(g.uniform(-h, h) * 16) / 16, std::round(g.uniform(-h, h) * 16) / 16,
                 std::round(g.uniform(-h, h) * 16) / 16};
  };
  const Vec3d a = grid(2), e = grid(1);
  Tri t;
  switch (kind) {
    case 0:
      t = {a, a + e, a + e * 2.0};
      break;
    case 1:
      t = {a, a + e, a};
      break;
    case 2:
      t = {a, a + e, a + grid(1)};
      break;
    default:
      t = {a, a + e, a + e * g.uniform(-1, 2)};
      break;
  }
  const Vec3d aim = (t.a + t.b + t.c) / 3.0;
  Rayd r = aimed(aim + g.unit() * g.uniform(1, 3), aim);
  if (kind == 2) r.d = {0, 0, 0};
  add_single(b, t, r);
}

// Rays from inside a closed mesh (shape 0: sphere, 1: box), placed at the
// origin or at Embree's placement: a third aimed exactly at a vertex, a third
// exactly at a representable point of an edge (one aim in four of those two
// moved a few grid steps), a third in a random direction. The mesh vertices
// are snapped to a grid of step H = max(4 h, 2^-10) (h: the precision's grid
// there, see Grid), so every edge holds representable points V1 + j (V2 - V1) / g,
// g >= 4; o is on the h grid and d = target - o is exact.
void closed_mesh_cases(Rng& g, int sweep, Precision p, int count, TriangleBatch& b) {
  const int shape = sweep / 2;
  const Vec3d place = (sweep % 2) ? kEmbreePlacement : Vec3d{0, 0, 0};
  const Mesh& m = closed_mesh(shape);
  const Grid grid(std::max(std::abs(place.x), std::max(std::abs(place.y), std::abs(place.z))) + 8, p);
  const double H = std::max(4 * grid.h, 0x1p-10);
  std::vector<Vec3d> v;
  for (const Vec3d& x : m.v)
    v.push_back(place + Vec3d{std::nearbyint(x.x / H), std::nearbyint(x.y / H), std::nearbyint(x.z / H)} * H);
  const int first = int(b.tris.size());
  for (const auto& f : m.f) b.tris.push_back({v[f[0]], v[f[1]], v[f[2]]});
  const double inner = shape == 0 ? 1.2 : 0.8;  // well inside either shape
  for (int i = 0; i < count; ++i) {
    Vec3d o = g.in_cube(1);
    if (shape == 0 && dot(o, o) > 1) o = o / std::sqrt(dot(o, o));
    o = grid.snap(o * inner + place);
    Rayd r;
    const int mode = g.below(3);
    if (mode == 0) {
      r = aimed(o, maybe_jitter(g, grid, v[std::size_t(g.below(int(v.size())))]));
    } else if (mode == 1) {
      const auto& f = m.f[std::size_t(g.below(int(m.f.size())))];
      const int k = g.below(3);
      const Vec3d v1 = v[std::size_t(f[std::size_t(k)])], v2 = v[std::size_t(f[std::size_t((k + 1) % 3)])];
      const Vec3d D = (v2 - v1) / grid.h;  // integers
      const long long dx = (long long)D.x, dy = (long long)D.y, dz = (long long)D.z;
      const long long gg = std::gcd(std::gcd(std::llabs(dx), std::llabs(dy)), std::llabs(dz));
      const Vec3d step = Vec3d{double(dx / gg), double(dy / gg), double(dz / gg)} * grid.h;
      r = aimed(o, maybe_jitter(g, grid, v1 + step * double(interior_step(g, gg, 0.05, 0.95))));
    } else {
      r = {o, g.unit()};
    }
    b.probes.push_back({r, first, int(m.f.size()), true});
  }
}

// Secondary: a triangle at the sweep's scale and a primary ray aimed strictly
// inside it (barycentrics >= 0.1); the engine spawns from each method's hit.
void secondary_case(Rng& g, int sweep, TriangleBatch& b) {
  const double lo = kSecondaryScales[std::size_t(sweep) % kSecondaryScales.size()];
  const double s = g.log_uniform(lo, lo * 1e4);
  const Tri t{g.in_cube(1) * s, g.in_cube(1) * s, g.in_cube(1) * s};
  const double b1 = g.uniform(0.1, 0.8), b2 = g.uniform(0.1, 0.9 - b1);
  const Vec3d aim = t.a + (t.b - t.a) * b1 + (t.c - t.a) * b2;
  add_single(b, t, aimed(g.in_cube(4) * s, aim));
}

// A primary ray entering a convex solid at `aim` on its surface, whose
// outward normal there is n: from a point on n's side of the tangent plane
// (at least 25 degrees above it), 0.5 to 4 `size` away. The solid lies
// behind that plane, so nothing of it is met before `aim`.
Rayd entering_ray(Rng& g, const Vec3d& aim, const Vec3d& n, double size) {
  Vec3d u, w;
  frame(n, u, w);
  const double su = g.uniform(-2, 2);
  const Vec3d v = normalize(n + u * su + w * g.uniform(-2, 2));
  return aimed(aim + v * (size * g.uniform(0.5, 4)), aim);
}

// Refracted: a closed convex mesh (the closed-mesh family's sphere or cube)
// of size about s at the secondary family's scales, centred within s of the
// origin, and a primary ray from outside aimed strictly inside one of its
// triangles (barycentrics >= 0.1), the entry; the engine refracts at each
// method's own hit and spawns inward.
void refracted_case(Rng& g, int sweep, TriangleBatch& b) {
  const double lo = kSecondaryScales[std::size_t(sweep) % kSecondaryScales.size()];
  const double s = g.log_uniform(lo, lo * 1e4);
  const Mesh& m = closed_mesh(g.below(2));
  const Vec3d centre = g.in_cube(0.5) * s;
  const int first = int(b.tris.size());
  for (const auto& f : m.f)
    b.tris.push_back({m.v[std::size_t(f[0])] * (0.5 * s) + centre, m.v[std::size_t(f[1])] * (0.5 * s) + centre,
                      m.v[std::size_t(f[2])] * (0.5 * s) + centre});
  const int entry = first + g.below(int(m.f.size()));
  const Tri& t = b.tris[std::size_t(entry)];
  const double b1 = g.uniform(0.1, 0.8), b2 = g.uniform(0.1, 0.9 - b1);
  const Vec3d aim = t.a + (t.b - t.a) * b1 + (t.c - t.a) * b2;
  Probe p{entering_ray(g, aim, normalize(cross(t.b - t.a, t.c - t.a)), s), first, int(m.f.size()), true};
  p.entry = entry;
  b.probes.push_back(p);
}

}  // namespace

std::vector<Tri> closed_mesh_triangles(int shape) {
  const Mesh& m = closed_mesh(shape);
  std::vector<Tri> out;
  for (const auto& f : m.f) out.push_back({m.v[std::size_t(f[0])], m.v[std::size_t(f[1])], m.v[std::size_t(f[2])]});
  return out;
}

int secondary_strategy(int sweep) { return sweep / int(kSecondaryScales.size()); }

int Family::tests_per_probe(int sweep_index) const {
  // A refracted ray is tested against the whole mesh (or its sphere): each
  // of those tests is a ray/primitive test, as the other families count.
  if (secondary && !refracted) return 2;
  return tris_per_probe(sweep_index);
}

int Family::tris_per_probe(int sweep_index) const {
  if (refracted && kind == Kind::triangle) return int((closed_mesh(0).f.size() + closed_mesh(1).f.size()) / 2);
  if (name == "closed-mesh") return int(closed_mesh(sweep_index / 2).f.size());
  if (name == "edge") return 2;
  if (name == "vertex") return 6;  // 3..8, mean 5.5
  return 1;
}

const std::vector<Family>& families() {
  static const std::vector<Family> all = [] {
    std::vector<Family> f;
    auto add = [&](std::string name, Kind k, std::string param, std::vector<std::string> sweep, bool grouped = false,
                   bool secondary = false, bool refracted = false) {
      f.push_back({std::move(name), k, std::move(param), std::move(sweep), grouped, secondary, refracted});
    };
    add("random", Kind::triangle, "aim spread", {"0.5", "1", "2"});
    add("edge", Kind::triangle, "offset", labels(kOffsets), true);
    add("vertex", Kind::triangle, "offset", labels(kOffsets), true);
    add("grazing", Kind::triangle, "angle (rad)", labels(kAngles));
    add("offset", Kind::triangle, "offset", labels(kOffsetFamily));
    add("distance", Kind::triangle, "distance", labels(kTriangleDistances));
    add("scale", Kind::triangle, "scale from", labels(kScaleLo));
    add("sliver", Kind::triangle, "aspect", labels(kAspects));
    add("near-miss", Kind::triangle, "ulps outside", labels(kNearMissUlps));
    add("degenerate", Kind::triangle, "kind", kDegenerate);
    add("closed-mesh", Kind::triangle, "mesh@placement", {"sphere@origin", "sphere@embree", "box@origin", "box@embree"},
        true);
    std::vector<std::string> sec;
    for (const auto& s : kStrategies)
      for (double sc : kSecondaryScales) sec.push_back(s + "@" + label(sc));
    add("secondary", Kind::triangle, "strategy@scale", sec, false, true);
    add("refracted", Kind::triangle, "strategy@scale", sec, true, true, true);
    add("huge", Kind::sphere, "radius", labels(kHugeRadii));
    add("tiny-far", Kind::sphere, "distance/radius", labels(kFarDistances));
    add("near-origin", Kind::sphere, "origin to surface", labels(kNearDistances));
    add("refracted", Kind::sphere, "strategy@scale", sec, false, true, true);
    return f;
  }();
  return all;
}

const Family* find_family(const std::string& name) {
  for (const auto& f : families())
    if (f.name == name) return &f;
  return nullptr;
}

const Family* find_family(const std::string& name, Kind kind) {
  for (const auto& f : families())
    if (f.name == name && f.kind == kind) return &f;
  return nullptr;
}

std::vector<const Family*> families_named(const std::string& name) {
  std::vector<const Family*> out;
  for (const auto& f : families())
    if (f.name == name) out.push_back(&f);
  return out;
}

std::string family_names() {
  std::string s;
  for (const auto& f : families())
    if (find_family(f.name) == &f) s += (s.empty() ? "" : ", ") + f.name;
  return s;
}

std::uint64_t stream_seed(std::uint64_t seed, const std::string& family, int sweep, std::uint64_t chunk) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the family name
  for (unsigned char ch : family) h = (h ^ ch) * 1099511628211ull;
  Rng g{seed ^ h};
  g.s ^= (std::uint64_t(sweep) << 40) ^ chunk * 0xD1B54A32D192ED03ull;
  return g.next();
}

bool group_is_proper(const Tri* tris, int count, const Vec3d& d) {
  return faces_alike(std::vector<Tri>(tris, tris + count), d);
}

void generate(const Family& f, int sweep, Precision p, std::uint64_t stream, int count, TriangleBatch& out) {
  Rng g{stream};
  const std::size_t tri0 = out.tris.size(), probe0 = out.probes.size();
  const auto s = std::size_t(sweep);
  if (f.name == "closed-mesh") {
    closed_mesh_cases(g, sweep, p, count, out);
  } else {
    for (int i = 0; i < count; ++i) {
      if (f.name == "random")
        random_case(g, std::stod(f.sweep[s]), 1, {}, out);
      else if (f.name == "edge")
        edge_case(g, kOffsets[s], p, out);
      else if (f.name == "vertex")
        vertex_case(g, kOffsets[s], p, out);
      else if (f.name == "grazing")
        grazing_case(g, kAngles[s], out);
      else if (f.name == "offset")
        random_case(g, 1, 1, random_offset(g, kOffsetFamily[s]), out);
      else if (f.name == "distance")
        distant_case(g, kTriangleDistances[s], out);
      else if (f.name == "scale")
        random_case(g, 1, g.log_uniform(kScaleLo[s], kScaleLo[s] * 1e4), {}, out);
      else if (f.name == "sliver")
        sliver_case(g, kAspects[s], out);
      else if (f.name == "near-miss")
        near_miss_case(g, kNearMissUlps[s], p, out);
      else if (f.name == "degenerate")
        degenerate_case(g, sweep, out);
      else if (f.name == "secondary")
        secondary_case(g, sweep, out);
      else if (f.name == "refracted")
        refracted_case(g, sweep, out);
      else
        throw std::logic_error("no triangle generator for family " + f.name);
    }
  }
  if (p == Precision::f32) round_to_float(out, tri0, probe0);
}

void generate(const Family& f, int sweep, Precision p, std::uint64_t stream, int count, std::vector<SphereCase>& out) {
  Rng g{stream};
  const std::size_t first = out.size();
  const auto s = std::size_t(sweep);
  for (int i = 0; i < count; ++i) {
    SphereCase c;
    if (f.name == "huge") {
      // A floor: the sphere's top touches y = 0; rays from a few units up
      // aimed at floor points up to 1000 away (beyond the horizon some miss).
      c.radius = kHugeRadii[s];
      c.center = {g.uniform(-1, 1), -c.radius, g.uniform(-1, 1)};
      const Vec3d o{g.uniform(-10, 10), g.uniform(0.5, 5), g.uniform(-10, 10)};
      const double dist = g.log_uniform(1, 1000), az = g.uniform(0, 2 * std::numbers::pi);
      const Vec3d target{o.x + dist * std::cos(az), -g.uniform(0, 1) * dist * dist / (2 * c.radius) * 2,
                         o.z + dist * std::sin(az)};
      c.ray = aimed(o, target);
    } else if (f.name == "tiny-far") {
      // A unit sphere at distance D, rays aimed within 1.5 radii of its centre.
      c.radius = 1;
      c.center = g.unit() * kFarDistances[s];
      const Vec3d o = g.in_cube(1);
      c.ray = aimed(o, c.center + g.in_cube(1.5));
    } else if (f.name == "refracted") {
      // A sphere of radius about s at the secondary family's scales, centred
      // within s of the origin, and a primary ray from outside entering it
      // at a random point (see entering_ray).
      const double lo = kSecondaryScales[s % kSecondaryScales.size()];
      c.radius = g.log_uniform(lo, lo * 1e4);
      c.center = g.in_cube(0.5) * c.radius;
      const Vec3d n = g.unit();
      c.ray = entering_ray(g, c.center + n * c.radius, n, c.radius);
    } else if (f.name == "near-origin") {
      // Origins at distance delta from the surface (inside or outside).
      c.radius = g.log_uniform(0.1, 10);
      c.center = g.in_cube(10);
      const Vec3d n = g.unit();
      const double delta = kNearDistances[s] * c.radius * (g.below(2) ? 1 : -1);
      const Vec3d o = c.center + n * (c.radius + delta);
      c.ray = {o, normalize(g.unit() - n * 0.5)};
    } else {
      throw std::logic_error("no sphere generator for family " + f.name);
    }
    out.push_back(c);
  }
  if (p == Precision::f32)
    for (std::size_t i = first; i < out.size(); ++i) {
      SphereCase& c = out[i];
      c.ray = {to_float(c.ray.o), to_float(c.ray.d), to_float(c.ray.tmin), to_float(c.ray.tmax)};
      c.center = to_float(c.center);
      c.radius = to_float(c.radius);
    }
}

}  // namespace ra::audit
