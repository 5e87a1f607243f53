// Case families (issue 6): random, edge, vertex, grazing, offset, scale,
// sliver, near-miss, degenerate, closed-mesh (Embree's WatertightTest placement), secondary; spheres huge, tiny-far, near-origin.
#include "families.h"

#include <array>
#include <cmath>
#include <numbers>
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
  double log_uniform(double lo, double hi) {
    return std::exp(uniform(std::log(lo), std::log(hi)));
  }
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
const std::vector<double> kAngles = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
const std::vector<double> kScaleLo = {1e-8, 1e-4, 1, 1e4};  // each bucket spans 4 decades
const std::vector<double> kAspects = {1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
const std::vector<int> kNearMissUlps = {1, 8, 64};
const std::vector<std::string> kDegenerate = {"collinear", "repeated-vertex", "zero-direction",
                                              "near-collinear"};
const std::vector<double> kSecondaryScales = {1e-4, 1, 1e4, 1e8};
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
template <class C> std::vector<std::string> labels(const C& c, const std::string& prefix = "") {
  std::vector<std::string> out;
  for (const auto& v : c) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string>) out.push_back(prefix + v);
    else out.push_back(prefix + label(double(v)));
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
  m.v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
         {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  m.f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
         {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
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
Vec3d to_float(const Vec3d& v) { return Vec3d(Vec3<float>(v)); }
double to_float(double x) { return double(float(x)); }
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

// Two triangles sharing edge pq, folded by a random dihedral, and a ray aimed
// at a float point of pq (rounded to float for both precisions).
void edge_case(Rng& g, double offset, TriangleBatch& b) {
  const Vec3d off = random_offset(g, offset);
  const Vec3d p = g.in_cube(1) + off, q = g.in_cube(1) + off;
  const Vec3d e = normalize(q - p);
  Vec3d u, w;
  frame(e, u, w);
  const Vec3d m = (p + q) * 0.5;
  const double h1 = g.uniform(0.3, 1.5), h2 = g.uniform(0.3, 1.5);
  const Vec3d r1 = m + u * h1 + w * (h1 * g.uniform(-0.5, 0.5));
  const Vec3d r2 = m - u * h2 + w * (h2 * g.uniform(-0.5, 0.5));
  const Vec3d aim = to_float(p + (q - p) * g.uniform(0.05, 0.95));
  const Tri t1{p, q, r1}, t2{q, p, r2};
  Vec3d o;
  for (int tries = 0; tries < 64; ++tries) {
    o = aim + (w * (g.below(2) ? 1.0 : -1.0) + g.in_cube(0.7)) * g.uniform(1, 3);
    if (faces_alike({t1, t2}, aim - o)) break;
  }
  b.tris.push_back(t1);
  b.tris.push_back(t2);
  b.probes.push_back({aimed(o, aim), int(b.tris.size()) - 2, 2});
}

// A closed fan of 3..8 triangles around vertex v (a shallow cone), and a ray
// aimed at v from within 60 degrees of the cone's axis.
void vertex_case(Rng& g, double offset, TriangleBatch& b) {
  const Vec3d v = to_float(g.in_cube(1) + random_offset(g, offset));
  const Vec3d e = g.unit();
  Vec3d u, w;
  frame(e, u, w);
  const int k = 3 + g.below(6);
  std::vector<Vec3d> ring;
  for (int i = 0; i < k; ++i) {
    const double ang = 2 * std::numbers::pi * (i + g.uniform(-0.3, 0.3)) / k;
    ring.push_back(v + (u * std::cos(ang) + w * std::sin(ang)) * g.uniform(0.5, 1.5) +
                   e * g.uniform(-0.3, 0.3));
  }
  const int first = int(b.tris.size());
  for (int i = 0; i < k; ++i) b.tris.push_back({v, ring[i], ring[(i + 1) % k]});
  const double side = g.below(2) ? 1.0 : -1.0;
  const std::vector<Tri> fan(b.tris.begin() + first, b.tris.end());
  Vec3d o;
  for (int tries = 0; tries < 64; ++tries) {
    const Vec3d dir = normalize(e * side + (u * g.uniform(-1, 1) + w * g.uniform(-1, 1)) * 1.7);
    o = v + dir * g.uniform(1, 3);
    if (faces_alike(fan, v - o)) break;
  }
  b.probes.push_back({aimed(o, v), first, k});
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

// A point of an edge stepped `ulps` ulps (of the precision) outward from the
// triangle in every coordinate, and a ray aimed at it.
void near_miss_case(Rng& g, int ulps, Precision p, TriangleBatch& b) {
  Tri t{g.in_cube(1), g.in_cube(1), g.in_cube(1)};
  if (p == Precision::f32) t = {to_float(t.a), to_float(t.b), to_float(t.c)};
  const int k = g.below(3);
  const Vec3d& P0 = k == 0 ? t.a : k == 1 ? t.b : t.c;
  const Vec3d& P1 = k == 0 ? t.b : k == 1 ? t.c : t.a;
  const Vec3d& opp = k == 0 ? t.c : k == 1 ? t.a : t.b;
  const Vec3d n = cross(t.b - t.a, t.c - t.a);
  Vec3d out = cross(P1 - P0, n);  // in-plane, perpendicular to the edge
  if (dot(out, opp - P0) > 0) out = -out;
  Vec3d aim = P0 + (P1 - P0) * g.uniform(0.1, 0.9);
  if (p == Precision::f32) aim = to_float(aim);
  for (int i = 0; i < 3; ++i)
    if (out[i] != 0) aim[i] = step_ulps(aim[i], out[i] > 0 ? 1 : -1, ulps, p);
  const Vec3d nn = normalize(n) * (g.below(2) ? 1.0 : -1.0);
  const Vec3d o = aim + (nn + g.in_cube(0.7)) * g.uniform(0.5, 2);
  add_single(b, t, aimed(o, aim));
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
    case 0: t = {a, a + e, a + e * 2.0}; break;
    case 1: t = {a, a + e, a}; break;
    case 2: t = {a, a + e, a + grid(1)}; break;
    default: t = {a, a + e, a + e * g.uniform(-1, 2)}; break;
  }
  const Vec3d aim = (t.a + t.b + t.c) / 3.0;
  Rayd r = aimed(aim + g.unit() * g.uniform(1, 3), aim);
  if (kind == 2) r.d = {0, 0, 0};
  add_single(b, t, r);
}

// Rays from inside a closed mesh (shape 0: sphere, 1: box), placed at the
// origin or at Embree's placement: a third aimed at a vertex, a third at a
// float point of an edge, a third in a random direction.
void closed_mesh_cases(Rng& g, int sweep, Precision p, int count, TriangleBatch& b) {
  const int shape = sweep / 2;
  const Vec3d place = (sweep % 2) ? kEmbreePlacement : Vec3d{0, 0, 0};
  const Mesh& m = closed_mesh(shape);
  const int first = int(b.tris.size());
  for (const auto& f : m.f) b.tris.push_back({m.v[f[0]] + place, m.v[f[1]] + place, m.v[f[2]] + place});
  const double inner = shape == 0 ? 1.2 : 0.8;  // well inside either shape
  for (int i = 0; i < count; ++i) {
    Vec3d o = g.in_cube(1);
    if (shape == 0 && dot(o, o) > 1) o = o / std::sqrt(dot(o, o));
    o = o * inner + place;
    Vec3d target;
    const int mode = g.below(3);
    if (mode == 0) {
      target = m.v[g.below(int(m.v.size()))] + place;
    } else if (mode == 1) {
      const auto& f = m.f[g.below(int(m.f.size()))];
      const int k = g.below(3);
      target = to_float(m.v[f[k]] + place + (m.v[f[(k + 1) % 3]] - m.v[f[k]]) * g.uniform(0.05, 0.95));
    } else {
      target = o + g.unit();
    }
    b.probes.push_back({aimed(o, target), first, int(m.f.size()), true});
  }
  (void)p;
}

// Secondary: a triangle at the sweep's scale and a primary ray aimed strictly
// inside it (barycentrics >= 0.1); the engine spawns from each method's hit.
void secondary_case(Rng& g, int sweep, TriangleBatch& b) {
  const double lo = kSecondaryScales[std::size_t(sweep) % kSecondaryScales.size()];
  const double s = g.log_uniform(lo, lo * 10);
  const Tri t{g.in_cube(1) * s, g.in_cube(1) * s, g.in_cube(1) * s};
  const double b1 = g.uniform(0.1, 0.8), b2 = g.uniform(0.1, 0.9 - b1);
  const Vec3d aim = t.a + (t.b - t.a) * b1 + (t.c - t.a) * b2;
  add_single(b, t, aimed(g.in_cube(4) * s, aim));
}

}  // namespace

int secondary_strategy(int sweep) { return sweep / int(kSecondaryScales.size()); }

int Family::tris_per_probe(int sweep_index) const {
  if (name == "closed-mesh") return int(closed_mesh(sweep_index / 2).f.size());
  if (name == "edge") return 2;
  if (name == "vertex") return 6;  // 3..8, mean 5.5
  return 1;
}

const std::vector<Family>& families() {
  static const std::vector<Family> all = [] {
    std::vector<Family> f;
    auto add = [&](std::string name, Kind k, std::string param, std::vector<std::string> sweep,
                   bool grouped = false, bool secondary = false) {
      f.push_back({std::move(name), k, std::move(param), std::move(sweep), grouped, secondary});
    };
    add("random", Kind::triangle, "aim spread", {"0.5", "1", "2"});
    add("edge", Kind::triangle, "offset", labels(kOffsets), true);
    add("vertex", Kind::triangle, "offset", labels(kOffsets), true);
    add("grazing", Kind::triangle, "angle (rad)", labels(kAngles));
    add("offset", Kind::triangle, "offset", labels(kOffsetFamily));
    add("scale", Kind::triangle, "scale from", labels(kScaleLo));
    add("sliver", Kind::triangle, "aspect", labels(kAspects));
    add("near-miss", Kind::triangle, "ulps outside", labels(kNearMissUlps));
    add("degenerate", Kind::triangle, "kind", kDegenerate);
    add("closed-mesh", Kind::triangle, "mesh@placement",
        {"sphere@origin", "sphere@embree", "box@origin", "box@embree"}, true);
    std::vector<std::string> sec;
    for (const auto& s : kStrategies)
      for (double sc : kSecondaryScales) sec.push_back(s + "@" + label(sc));
    add("secondary", Kind::triangle, "strategy@scale", sec, false, true);
    add("huge", Kind::sphere, "radius", labels(kHugeRadii));
    add("tiny-far", Kind::sphere, "distance/radius", labels(kFarDistances));
    add("near-origin", Kind::sphere, "origin to surface", labels(kNearDistances));
    return f;
  }();
  return all;
}

const Family* find_family(const std::string& name) {
  for (const auto& f : families())
    if (f.name == name) return &f;
  return nullptr;
}

std::string family_names() {
  std::string s;
  for (const auto& f : families()) s += (s.empty() ? "" : ", ") + f.name;
  return s;
}

std::uint64_t stream_seed(std::uint64_t seed, const std::string& family, int sweep, int chunk) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the family name
  for (unsigned char ch : family) h = (h ^ ch) * 1099511628211ull;
  Rng g{seed ^ h};
  g.s ^= (std::uint64_t(sweep) << 40) ^ std::uint64_t(chunk) * 0xD1B54A32D192ED03ull;
  return g.next();
}

bool group_is_proper(const Tri* tris, int count, const Vec3d& d) {
  return faces_alike(std::vector<Tri>(tris, tris + count), d);
}

void generate(const Family& f, int sweep, Precision p, std::uint64_t stream, int count,
              TriangleBatch& out) {
  Rng g{stream};
  const std::size_t tri0 = out.tris.size(), probe0 = out.probes.size();
  const auto s = std::size_t(sweep);
  if (f.name == "closed-mesh") {
    closed_mesh_cases(g, sweep, p, count, out);
  } else {
    for (int i = 0; i < count; ++i) {
      if (f.name == "random") random_case(g, std::stod(f.sweep[s]), 1, {}, out);
      else if (f.name == "edge") edge_case(g, kOffsets[s], out);
      else if (f.name == "vertex") vertex_case(g, kOffsets[s], out);
      else if (f.name == "grazing") grazing_case(g, kAngles[s], out);
      else if (f.name == "offset") random_case(g, 1, 1, random_offset(g, kOffsetFamily[s]), out);
      else if (f.name == "scale") random_case(g, 1, g.log_uniform(kScaleLo[s], kScaleLo[s] * 1e4), {}, out);
      else if (f.name == "sliver") sliver_case(g, kAspects[s], out);
      else if (f.name == "near-miss") near_miss_case(g, kNearMissUlps[s], p, out);
      else if (f.name == "degenerate") degenerate_case(g, sweep, out);
      else if (f.name == "secondary") secondary_case(g, sweep, out);
      else throw std::logic_error("no triangle generator for family " + f.name);
    }
  }
  if (p == Precision::f32) round_to_float(out, tri0, probe0);
}

void generate(const Family& f, int sweep, Precision p, std::uint64_t stream, int count,
              std::vector<SphereCase>& out) {
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
