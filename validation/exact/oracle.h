// The exact oracle: what a ray/triangle or ray/sphere query answers in exact
// arithmetic over the given (double) inputs. Filtered (CGAL::Interval_nt), exact fallback (GMP/MPFR).
#pragma once
#include <string_view>

#include <rayaudit/ray.h>

namespace ra::oracle {

// Ray semantics, shared by every oracle query and stated once:
//  - the ray is the set { o + t d : t in W }, W = [max(tmin, 0), tmax]
//    (closed at both ends; t = 0, a hit exactly at the origin, counts);
//    an empty W (tmin > tmax) means a miss;
//  - inputs are taken as the exact rational values of their doubles (a float
//    converts to double exactly, so float cases are judged on the float values);
//  - the triangle is closed: its edges and vertices belong to it.
// Verdicts (triangle):
//  - degenerate: any input is NaN/Inf, d == 0, or (B-A) x (C-A) == 0 exactly;
//  - coplanar: d is parallel to the plane and o lies in it (whether or not the
//    line meets the triangle: every answer is defensible there);
//  - miss: the line misses the closed triangle, or its plane crossing is
//    outside W (including a parallel ray off the plane);
//  - boundary: the crossing is in W and exactly on an edge or a vertex;
//  - hit: the crossing is in W and strictly inside the triangle.
// Verdicts (sphere, centre and radius): degenerate (radius <= 0, d == 0,
// NaN/Inf), miss, boundary (tangent ray: one double root, in W), hit.
enum class Verdict { hit, miss, boundary, coplanar, degenerate };

std::string_view verdict_name(Verdict v);
// Parses a verdict name; returns false for anything else.
bool parse_verdict(std::string_view s, Verdict& out);

struct Answer {
  Verdict verdict = Verdict::miss;
  // Exact t of the (nearest in-window) crossing, rounded to nearest double;
  // NaN unless the verdict is hit or boundary.
  double t;
  // Spheres only: the other root when it is in W too (NaN otherwise).
  double t_far;
  // Triangles only: how many of the three edge functions are exactly zero
  // (1 = on an edge, 2 = at a vertex) for boundary answers.
  int zero_edges = 0;
};

Answer triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c);
Answer sphere(const Rayd& r, const Vec3d& center, double radius);

// How many queries took the exact (GMP) path on this thread, for benchmarks.
unsigned long long exact_fallbacks();

}  // namespace ra::oracle
