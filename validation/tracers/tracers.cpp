// Whole tracers graded on closed meshes (tracers.h says what and why).
// Sources: Embree's tutorials/verify WatertightTest (rays from inside closed
// meshes far from the origin, a 2e-5 miss-rate bar); the exact oracle
// (exact/oracle.h) for the nearest crossing; ours through ra::Tracer.
#include "tracers.h"

#include <embree3/rtcore.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>

#include "exact/oracle.h"
#include <rayaudit/registry.h>
#include <rayaudit/render.h>

namespace ra::tracers {
namespace {

// ------------------------------------------------------------ ours ---
IntersectFn ours(const Mesh& m, Accel accel, const std::string& method, bool dbl) {
  auto set = std::make_shared<TriangleSet>();
  set->name = "closed mesh";
  set->materials.resize(1);
  set->positions = m.positions;
  for (const auto& t : m.triangles) {
    MeshTriangle3 tri;
    for (int k = 0; k < 3; ++k) tri.v[k] = t[std::size_t(k)];
    set->triangles.push_back(tri);
  }
  auto scene = std::make_shared<Scene>();
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = set;
  scene->objects.push_back(o);
  RenderOptions opt;
  opt.triangle_method = method;
  opt.use_double = dbl;
  opt.accel = accel;
  opt.threads = 1;
  auto tracer = std::make_shared<Tracer>(*scene, opt);
  return [scene, tracer](const Rayd& r) -> std::optional<Hit> {
    if (auto h = tracer->intersect(r)) return Hit{h->t, h->prim};
    return std::nullopt;
  };
}

// ---------------------------------------------------------- embree ---
RTCDevice embree_device() {
  static RTCDevice dev = [] {
    RTCDevice d = rtcNewDevice("threads=1");
    if (!d) throw std::runtime_error("Embree: rtcNewDevice failed (libembree3)");
    return d;
  }();
  return dev;
}
IntersectFn embree(const Mesh& m, bool robust) {
  static std::mutex mu;  // one device: scenes built one at a time
  std::lock_guard<std::mutex> lock(mu);
  RTCDevice dev = embree_device();
  RTCScene scene = rtcNewScene(dev);
  if (robust) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.positions.size()));
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + std::size_t(k)] = float(m.positions[i][k]);
  auto* idx = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.triangles.size()));
  for (std::size_t i = 0; i < m.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) idx[3 * i + std::size_t(k)] = unsigned(m.triangles[i][std::size_t(k)]);
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  std::shared_ptr<RTCSceneTy> keep(scene, [](RTCScene s) { rtcReleaseScene(s); });
  return [keep](const Rayd& r) -> std::optional<Hit> {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = float(r.o.x), rh.ray.org_y = float(r.o.y), rh.ray.org_z = float(r.o.z);
    rh.ray.dir_x = float(r.d.x), rh.ray.dir_y = float(r.d.y), rh.ray.dir_z = float(r.d.z);
    rh.ray.tnear = float(r.tmin);
    rh.ray.tfar = std::isinf(r.tmax) ? std::numeric_limits<float>::infinity() : float(r.tmax);
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(keep.get(), &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    return Hit{double(rh.ray.tfar), int(rh.hit.primID)};
  };
}

// ------------------------------------------------------------ cgal ---
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
IntersectFn cgal(const Mesh& m) {
  struct S {
    Triangles tris;
    std::unique_ptr<Tree> tree;
  };
  auto s = std::make_shared<S>();
  auto pt = [](const Vec3d& v) { return K::Point_3(v.x, v.y, v.z); };
  for (const auto& t : m.triangles)
    s->tris.emplace_back(pt(m.positions[std::size_t(t[0])]), pt(m.positions[std::size_t(t[1])]),
                         pt(m.positions[std::size_t(t[2])]));
  s->tree = std::make_unique<Tree>(s->tris.begin(), s->tris.end());
  s->tree->build();
  return [s](const Rayd& r) -> std::optional<Hit> {
    const auto h =
        s->tree->first_intersection(K::Ray_3(K::Point_3(r.o.x, r.o.y, r.o.z), K::Vector_3(r.d.x, r.d.y, r.d.z)));
    if (!h) return std::nullopt;
    K::Point_3 p;
    if (const K::Point_3* q = boost::get<K::Point_3>(&h->first))
      p = *q;
    else if (const K::Segment_3* g = boost::get<K::Segment_3>(&h->first))
      p = g->source();
    else
      return std::nullopt;
    const Vec3d P{CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
    return Hit{dot(P - r.o, r.d) / dot(r.d, r.d), int(h->second - s->tris.begin())};
  };
}

// ------------------------------------------------------------ rays ---
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
  int below(int n) { return int(next() % std::uint64_t(n)); }
  Vec3d ball() {
    for (;;) {
      const Vec3d v{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
      if (dot(v, v) <= 1) return v;
    }
  }
  Vec3d unit() {
    for (;;) {
      const Vec3d v = ball();
      if (dot(v, v) > 1e-4) return v / std::sqrt(dot(v, v));
    }
  }
};

const std::vector<double> kOffsets = {0, 1e2, 1e4, 1e5, 1e7};
const std::vector<double> kScales = {1e-4, 1, 1e4};
const Vec3d kDirection{0.8, 0.5, -0.33};  // offsets along it (no axis-aligned luck)
const char* kShapes[] = {"sphere", "cube"};

struct Case {
  Rayd ray;
  bool inside = false;
  bool crosses = false;  // the exact ray meets the mesh
  bool touch = false;    // from outside, it only touches it (one t): not judged
  double t = 0;          // the exact nearest crossing
};

double ulp_float(double x) { return std::ldexp(1.0, std::ilogb(std::max(x, 1e-30)) - 23); }

}  // namespace

void Stats::merge(const Stats& o) {
  rays += o.rays, inside_rays += o.inside_rays, leaks += o.leaks, inside_leaks += o.inside_leaks;
  false_hits += o.false_hits, wrong_nearest += o.wrong_nearest;
}
nlohmann::json Stats::to_json() const {
  return {{"rays", rays},
          {"inside_rays", inside_rays},
          {"leaks", leaks},
          {"inside_leaks", inside_leaks},
          {"false_hits", false_hits},
          {"wrong_nearest", wrong_nearest},
          {"leaks_per_million", per_million(leaks)},
          {"false_hits_per_million", per_million(false_hits)},
          {"wrong_nearest_per_million", per_million(wrong_nearest)},
          {"inside_miss_rate", inside_rays ? double(inside_leaks) / double(inside_rays) : 0.0}};
}

std::string known_names() {
  return "bvh, sphere, none (ours: every triangle method and precision, or NAME:METHOD[/float|/double]), embree, "
         "embree-robust, cgal-aabb";
}

std::vector<Subject> named(const std::string& spec) {
  const std::string base = spec.substr(0, spec.find(':'));
  if (base == "embree" || base == "embree-robust") {
    if (spec != base) throw std::invalid_argument("unknown tracer '" + spec + "'; known: " + known_names());
    const bool robust = base == "embree-robust";
    return {{base, Precision::f32, [robust](const Mesh& m) { return embree(m, robust); }}};
  }
  if (spec == "cgal-aabb") return {{"cgal-aabb", Precision::f64, [](const Mesh& m) { return cgal(m); }}};
  const std::optional<Accel> accel = parse_accel(base);
  if (!accel) throw std::invalid_argument("unknown tracer '" + spec + "'; known: " + known_names());
  std::string method, prec;
  if (spec.size() > base.size()) {
    method = spec.substr(base.size() + 1);
    if (const auto slash = method.find('/'); slash != std::string::npos) {
      prec = method.substr(slash + 1);
      method = method.substr(0, slash);
    }
    const Method* m = find_method(method);
    if (!m || m->kind != Kind::triangle || (!prec.empty() && prec != "float" && prec != "double"))
      throw std::invalid_argument("unknown tracer '" + spec + "'; known: " + known_names() +
                                  "; triangle methods: " + method_names(Kind::triangle));
  }
  std::vector<Subject> out;
  for (const Method& m : methods()) {
    if (m.kind != Kind::triangle || (!method.empty() && m.name != method)) continue;
    for (const bool dbl : {false, true}) {
      if (!prec.empty() && (prec == "double") != dbl) continue;
      const std::string name = base + "/" + m.name + (dbl ? "/double" : "/float");
      const Accel a = *accel;
      const std::string mn = m.name;
      out.push_back({name, dbl ? Precision::f64 : Precision::f32,
                     [a, mn, dbl](const Mesh& mesh) { return ours(mesh, a, mn, dbl); }});
    }
  }
  return out;
}

Stats Report::total(std::size_t subject) const {
  Stats s;
  for (const Cell& c : cells)
    if (c.subject == subject) s.merge(c.stats);
  return s;
}

nlohmann::json Report::to_json() const {
  nlohmann::json j;
  j["offsets"] = offsets;
  j["scales"] = scales;
  j["embree_miss_rate_bar"] = kEmbreeMissRate;
  j["subjects"] = subjects;
  j["cells"] = nlohmann::json::array();
  for (const Cell& c : cells) {
    nlohmann::json x = c.stats.to_json();
    x["tracer"] = subjects[c.subject];
    x["shape"] = c.shape;
    x["offset"] = c.offset;
    x["scale"] = c.scale;
    j["cells"].push_back(x);
  }
  j["totals"] = nlohmann::json::object();
  for (std::size_t s = 0; s < subjects.size(); ++s) j["totals"][subjects[s]] = total(s).to_json();
  j["skipped"] = nlohmann::json::array();
  for (const auto& [o, s] : skipped) j["skipped"].push_back({{"offset", o}, {"scale", s}});
  return j;
}

std::string Report::summary_table() const {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-28s %9s %11s %11s %11s %12s %s\n", "tracer", "rays", "leaks/M", "false/M",
                "wrong-t/M", "inside miss", "Embree's bar (2e-5)");
  out << line;
  for (std::size_t s = 0; s < subjects.size(); ++s) {
    const Stats t = total(s);
    double worst = 0;
    for (const Cell& c : cells)
      if (c.subject == s && c.stats.inside_rays)
        worst = std::max(worst, double(c.stats.inside_leaks) / double(c.stats.inside_rays));
    std::snprintf(line, sizeof line, "%-28s %9llu %11.1f %11.1f %11.1f %12.2e %s\n", subjects[s].c_str(),
                  (unsigned long long)t.rays, t.per_million(t.leaks), t.per_million(t.false_hits),
                  t.per_million(t.wrong_nearest), worst, worst > kEmbreeMissRate ? "FAILS (worst cell)" : "passes");
    out << line;
  }
  if (!skipped.empty()) {
    out << "not judged (float cannot hold the mesh there):";
    for (const auto& [o, s] : skipped) out << " offset " << o << " scale " << s << ";";
    out << "\n";
  }
  return out.str();
}

Report run(const std::vector<Subject>& subjects, const Options& opt) {
  if (opt.rays < 2 || opt.rays > 100000000) throw std::invalid_argument("tracer rays must be 2..1e8 per cell");
  Report rep;
  rep.offsets = kOffsets;
  rep.scales = kScales;
  for (const Subject& s : subjects) rep.subjects.push_back(s.name);
  std::uint64_t stream = opt.seed * 0x9E3779B97F4A7C15ull;
  for (double offset : kOffsets)
    for (double scale : kScales) {
      const Vec3d place = kDirection * offset;
      if (ulp_float(max_component(abs(place)) + 2 * scale) > scale / 64) {
        rep.skipped.push_back({offset, scale});
        continue;
      }
      for (int shape = 0; shape < 2; ++shape) {
        // The mesh: the audit's closed mesh, placed, scaled, in float.
        const std::vector<audit::Tri> tris = audit::closed_mesh_triangles(shape);
        Mesh mesh;
        std::set<std::array<double, 3>> seen;
        std::vector<Vec3d> verts;
        for (const audit::Tri& t : tris) {
          std::array<int, 3> f{};
          int k = 0;
          for (const Vec3d* v : {&t.a, &t.b, &t.c}) {
            const Vec3d p = to_float32(place + *v * scale);
            mesh.positions.push_back(p);
            if (seen.insert({p.x, p.y, p.z}).second) verts.push_back(p);
            f[std::size_t(k++)] = int(mesh.positions.size()) - 1;
          }
          mesh.triangles.push_back(f);
        }
        // The rays and their exact answers.
        Rng g{stream++};
        std::vector<Case> cases;
        const double inner = shape == 0 ? 1.2 : 0.8;
        for (long long i = 0; i < opt.rays; ++i) {
          Case c;
          c.inside = i % 2 == 0;
          const Vec3d o = to_float32(c.inside ? place + g.ball() * (inner * scale) : place + g.unit() * (4 * scale));
          const int mode = g.below(c.inside ? 3 : 2);
          Vec3d target;
          if (mode == 0) {
            target = verts[std::size_t(g.below(int(verts.size())))];
          } else if (mode == 1) {
            const auto& f = mesh.triangles[std::size_t(g.below(int(mesh.triangles.size())))];
            const int k = g.below(3);
            const Vec3d a = mesh.positions[std::size_t(f[std::size_t(k)])],
                        b = mesh.positions[std::size_t(f[std::size_t((k + 1) % 3)])];
            target = to_float32(a + (b - a) * g.uniform(0.05, 0.95));
          } else {
            target = o + g.unit() * scale;
          }
          c.ray = {o, to_float32(target - o)};
          if (c.ray.d == Vec3d{0, 0, 0}) c.ray.d = to_float32(g.unit());
          double best = std::numeric_limits<double>::infinity(), last = -best;
          for (const auto& f : mesh.triangles) {
            const oracle::Answer a =
                oracle::triangle(c.ray, mesh.positions[std::size_t(f[0])], mesh.positions[std::size_t(f[1])],
                                 mesh.positions[std::size_t(f[2])]);
            if (a.verdict == oracle::Verdict::hit || a.verdict == oracle::Verdict::boundary) {
              best = std::min(best, a.t);
              last = std::max(last, a.t);
            }
          }
          // From outside a convex mesh the ray enters the solid when it
          // crosses twice at distinct t. Where the two crossings are nearer
          // than 2^-10 of the mesh's size it only grazes the silhouette (a
          // vertex or an edge touched): a float tracer's rounding of the
          // vertices against o moves the silhouette by more than that, and a
          // hit and a miss are both right there; not judged.
          const double span = (last - best) * max_component(abs(c.ray.d));
          c.crosses = std::isfinite(best) && (c.inside || span > 0x1p-10 * scale);
          c.touch = !c.inside && std::isfinite(best) && !c.crosses;
          if (!c.inside && !std::isfinite(best)) {
            // A miss by less than 2^-10 of the mesh's size (the mesh grown
            // by that about its centre is met): a near miss of the
            // silhouette, where a hit is as right as a miss; not judged.
            const double grow = 1 + 0x1p-10;
            for (const auto& f : mesh.triangles) {
              auto big = [&](int k) { return place + (mesh.positions[std::size_t(f[std::size_t(k)])] - place) * grow; };
              const oracle::Answer a = oracle::triangle(c.ray, big(0), big(1), big(2));
              if (a.verdict == oracle::Verdict::hit || a.verdict == oracle::Verdict::boundary) {
                c.touch = true;
                break;
              }
            }
          }
          c.t = best;
          cases.push_back(c);
        }
        for (std::size_t s = 0; s < subjects.size(); ++s) {
          const IntersectFn f = subjects[s].build(mesh);
          const double u = subjects[s].precision == Precision::f32 ? 0x1p-24 : 0x1p-53;
          Cell cell{s, kShapes[shape], offset, scale, {}};
          Stats& st = cell.stats;
          for (const Case& c : cases) {
            if (c.touch) continue;
            ++st.rays;
            st.inside_rays += c.inside;
            const std::optional<Hit> h = f(c.ray);
            if (!h || !std::isfinite(h->t)) {
              if (c.crosses) ++st.leaks, st.inside_leaks += c.inside;
              continue;
            }
            if (!c.crosses) {
              ++st.false_hits;
              continue;
            }
            const double dm = max_component(abs(c.ray.d));
            const double bound = 64 * u * (max_component(abs(c.ray.o)) + c.t * dm) / dm;
            if (std::abs(h->t - c.t) > bound) ++st.wrong_nearest;
          }
          rep.cells.push_back(std::move(cell));
        }
      }
    }
  return rep;
}

}  // namespace ra::tracers
