// The table of peers (peers.h): names, precisions, what each is, where its
// speed figure comes from, and how to get one a build lacks.
#include "peers.h"

#include <stdexcept>

namespace ra::peers {

const std::vector<Peer>& peers() {
  static const std::vector<Peer> all = [] {
    const std::string no_embree =
        have_embree() ? ""
                      : "this build has no Embree 3: install the Debian package libembree-dev (ci/install-deps.sh) "
                        "and reconfigure with -DRAYAUDIT_PEER_EMBREE=ON";
    // Embree's answer through a one-triangle scene costs a scene commit
    // (~10 us), not its test: no per-test time exists.
    const std::string embree_speed =
        "no per-test time (each test commits a one-triangle scene); the peer bench's "
        "peer/embree/MESH/primary/";
    std::vector<Peer> v;
    v.push_back({"embree",
                 audit::Precision::f32,
                 {"Embree 3 rtcIntersect1 (default scene flags), a one-triangle scene per test, float",
                  embree_speed + "default rows (Embree's whole tracer on the ladder's meshes)"},
                 no_embree,
                 have_embree() ? +[] { return embree_subject(false); } : nullptr});
    v.push_back({"embree-robust",
                 audit::Precision::f32,
                 {"Embree 3 rtcIntersect1 (RTC_SCENE_FLAG_ROBUST), a one-triangle scene per test, float",
                  embree_speed + "robust rows (Embree's whole tracer on the ladder's meshes)"},
                 no_embree,
                 have_embree() ? +[] { return embree_subject(true); } : nullptr});
    v.push_back({"cgal-epick",
                 audit::Precision::f64,
                 {"CGAL Epick do_intersect(Ray_3, Triangle_3) for the verdict, intersection() for t, double",
                  "no per-test time; the peer bench's peer/cgal/MESH/primary rows (CGAL's AABB_tree over Epick "
                  "triangles, whole tracer)"},
                 "",
                 &cgal_epick_subject});
    v.push_back({"pov-mesh2",
                 audit::Precision::f32,
                 {"POV-Ray 3.7's mesh2 triangle test as POV computes it (renderer/pov_mesh.h: float32 plane, "
                  "2D edge tests), float vertices",
                  "no per-test time of POV-Ray itself; the peer bench's peer/pov/MESH rows (POV-Ray 3.7 rendering "
                  "the scene, trace seconds from its statistics)"},
                 "",
                 &pov_mesh2_subject});
    return v;
  }();
  return all;
}

const Peer* find_peer(std::string_view name) {
  for (const Peer& p : peers())
    if (p.name == name) return &p;
  return nullptr;
}

std::string peer_names() {
  std::string out;
  // Appended piece by piece (GCC 12 warns falsely on `", " + std::string`).
  for (const Peer& p : peers()) out.append(out.empty() ? "" : ", ").append(p.name);
  return out;
}

audit::TriangleSubject subject(const Peer& p) {
  if (!p.make) throw std::invalid_argument("peer '" + p.name + "' is not in this build: " + p.missing);
  audit::TriangleSubject s = p.make();
  s.method = p.name;
  s.precision = p.precision;
  s.peer = p.info;
  return s;
}

}  // namespace ra::peers
