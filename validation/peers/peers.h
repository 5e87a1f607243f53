// Peers as audit subjects: other projects' own ray/triangle tests, graded by
// the exact oracle exactly as the registry's methods are (`rayaudit audit
// --methods embree,embree-robust,cgal-epick,pov-mesh2`). Each answers at its
// own precision (Embree and POV-Ray's mesh2 store float32 vertices, CGAL's
// Epick takes doubles); a build without a peer's library lists it as
// missing, with how to get it. See README.md beside this file.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "exact/audit.h"

namespace ra::peers {

struct Peer {
  std::string name;  // as --methods takes it
  audit::Precision precision;
  audit::PeerInfo info;                        // what it is, where its speed figure comes from
  std::string missing;                         // empty when in this build; else how to get it
  audit::TriangleSubject (*make)() = nullptr;  // set when in this build
};

// Every peer rayaudit knows, in this build or not, in a fixed order.
const std::vector<Peer>& peers();
// nullptr when no peer has that name.
const Peer* find_peer(std::string_view name);
// "embree, embree-robust, ..." (for error messages).
std::string peer_names();
// The peer as an audit subject (its name, precision and PeerInfo set).
// Throws std::invalid_argument naming how to get it when not in this build.
audit::TriangleSubject subject(const Peer& p);

// The subjects behind each peer (one file each; null when not built).
audit::TriangleSubject embree_subject(bool robust);
audit::TriangleSubject cgal_epick_subject();
audit::TriangleSubject pov_mesh2_subject();
bool have_embree();

}  // namespace ra::peers
