// CGAL's Epick kernel (Exact_predicates_inexact_constructions_kernel) as an
// audit subject, double: do_intersect(Ray_3, Triangle_3) decides hit or
// miss, intersection(Ray_3, Triangle_3) gives the point whose t is reported.
//
// Source: CGAL 5.5 Intersections_3 (Ray_3_Triangle_3_do_intersect.h and
// _intersection.h; Debian libcgal-dev), as its users call it. Guarantee:
// Epick's predicates are exact (filtered, exact fallback), so the verdict is
// the exact one for the given doubles, boundaries included (a closed
// triangle); its constructions are not: the point, and so t, is rounded.
//
// Three things a caller must do, done here as a careful user would:
//  - CGAL's precondition is a non-degenerate triangle and ray (checked only
//    in debug builds; undefined otherwise): both are tested first, and a
//    degenerate one is answered as a miss.
//  - Ray_3 is a half-line from the origin: the audit's window [tmin, tmax]
//    is applied to the t computed from the point (a hit outside it is a miss).
//  - The intersection is a point, or a segment when the ray lies in the
//    triangle's plane: the segment's nearer end is the hit.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <algorithm>

#include "peers.h"

namespace ra::peers {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

K::Point_3 pt(const Vec3d& v) { return {v.x, v.y, v.z}; }

// The ray parameter of a point on it (its projection: exact for exact points).
double t_of(const Rayd& r, const K::Point_3& p) {
  const Vec3d q{p.x() - r.o.x, p.y() - r.o.y, p.z() - r.o.z};
  return dot(q, r.d) / dot(r.d, r.d);
}

std::optional<TriangleHit<double>> cgal_hit(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const K::Triangle_3 tri(pt(a), pt(b), pt(c));
  const K::Ray_3 ray(pt(r.o), K::Vector_3(r.d.x, r.d.y, r.d.z));
  if (tri.is_degenerate() || ray.is_degenerate()) return std::nullopt;
  if (!CGAL::do_intersect(ray, tri)) return std::nullopt;
  const auto x = CGAL::intersection(ray, tri);
  // do_intersect is exact, intersection() constructs: should it find
  // nothing where do_intersect found a point, the caller has no point to
  // shade, and the answer is a miss.
  if (!x) return std::nullopt;
  double t;
  if (const K::Point_3* p = boost::get<K::Point_3>(&*x))
    t = t_of(r, *p);
  else {
    const K::Segment_3& s = *boost::get<K::Segment_3>(&*x);
    t = std::min(t_of(r, s.source()), t_of(r, s.target()));
  }
  if (t < r.tmin || t > r.tmax) return std::nullopt;
  // Barycentrics are not part of CGAL's answer; they are only checked for NaN.
  return TriangleHit<double>{t, 0, 0};
}

}  // namespace

audit::TriangleSubject cgal_epick_subject() { return audit::triangle_subject<double>("cgal-epick", &cgal_hit); }

}  // namespace ra::peers
