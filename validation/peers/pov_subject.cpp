// POV-Ray 3.7's mesh2 triangle test as POV computes it, as an audit subject:
// float32 vertices (POV stores a mesh2's vertices as SNGL_VECT), a double ray.
//
// Source: POV-Ray 3.7.0.10 source/backend/shape/mesh.cpp
// (Compute_Mesh_Triangle, intersect_mesh_triangle), modelled operation for
// operation in renderer/pov_mesh.h for `compare --explain`, whose tests pin
// it to the real POV-Ray's images. Guarantee: none. The plane is stored in
// float32 and the hit point tested by 2D edge functions after projection
// along the plane normal's dominant axis; depths outside [1e-6, 1e7]
// (DEPTH_TOLERANCE, MAX_DISTANCE) are misses, as in POV-Ray.
//
// Graded in float: the triangle POV-Ray tests is the float32 one, so the
// oracle judges those vertices (grading double inputs would count every
// vertex's rounding to float against it). The ray is the float case's,
// widened to double as POV-Ray's rays are.
#include "peers.h"
#include "pov_mesh.h"

namespace ra::peers {
namespace {

std::optional<TriangleHit<float>> pov_hit(const Rayf& rf, const Vec3f& af, const Vec3f& bf, const Vec3f& cf) {
  const Rayd r(rf);
  const Vec3d a(af), b(bf), c(cf);
  const std::optional<double> t = pov_mesh_intersect(r, a, b, c);
  // POV-Ray's own window is applied inside; the audit's ray window here.
  if (!t || *t < r.tmin || *t > r.tmax) return std::nullopt;
  // The weights POV-Ray interpolates normals with (compute_smooth_triangle's
  // Perp): the barycentrics of its hit point.
  const PovMeshHit h = pov_mesh_hit(r, a, b, c);
  return TriangleHit<float>{float(*t), float(h.b1), float(h.b2)};
}

}  // namespace

audit::TriangleSubject pov_mesh2_subject() { return audit::triangle_subject<float>("pov-mesh2", &pov_hit); }

}  // namespace ra::peers
