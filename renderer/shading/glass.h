// Transparency, refraction and Fresnel reflection as POV-Ray 3.7.0.10
// computes them (source/backend/render/trace.cpp: ComputeLightedTexture,
// ComputeRefraction, TraceRefractionRay, ComputeReflectivity,
// ComputeRelativeIOR, ComputeShadowColour; source/base/types.h for the
// colour operations). Guarantee: the same formulas in the same order, so
// that with colours rounded to float32 (POV's RGBColour) the arithmetic is
// POV's; scenes/README.md states them for users.
#pragma once
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "../vec.h"

namespace ra::glass {

// POV's EPSILON (configbackend.h): iors this close to 1 transmit unbent.
inline constexpr double kEpsilon = 1e-10;

// Colour::opacity(): what the surface's own light (ambient, diffuse) is
// scaled by.
inline double opacity(double filter, double transmit) { return 1.0 - filter - transmit; }

// Colour::rgbTransm(): the share of light passing, per channel.
inline Vec3d rgb_transm(const Vec3d& c, double filter, double transmit) {
  return {c.x * filter + transmit, c.y * filter + transmit, c.z * filter + transmit};
}

// RGBColour::greyscale() with POV's weights (types.h: RED_INTENSITY etc.).
inline double greyscale(const Vec3d& c) { return 0.297 * c.x + 0.589 * c.y + 0.114 * c.z; }

// ComputeReflectivity's Fresnel case (unpolarised light), with ior the
// relative index n2/n1 as ComputeRelativeIOR gives it and cos_i = -D.N:
//   g = sqrt(ior^2 + cos^2 - 1),
//   F = 1/2 (g - c)^2/(g + c)^2 (1 + (c (g + c) - 1)^2 / (c (g - c) + 1)^2),
// clamped to [0, 1]; nullopt where g^2 <= 0 (POV then takes the maximum).
inline std::optional<double> fresnel(double ior, double cos_i) {
  const double sqx = ior * ior + cos_i * cos_i - 1.0;
  if (!(sqx > 0.0)) return std::nullopt;
  const double g = std::sqrt(sqx);
  const double gm = g - cos_i, gp = g + cos_i;
  double f = 0.5 * ((gm * gm) / (gp * gp));
  const double a = cos_i * gp - 1.0, b = cos_i * gm + 1.0;
  f = f * (1.0 + (a * a) / (b * b));
  return std::min(1.0, std::max(0.0, f));
}

// The objects (by index) a ray is inside, innermost last: POV's ray
// interior list. ComputeRefraction's rules for the ratio of indices, where
// ior_of(object) is that object's interior ior.
struct RefractionStep {
  double ior;                  // n1 / n2 for Heckbert's formula
  std::vector<int> interiors;  // the refracted ray's list
};
template <class IorOf>
RefractionStep refraction_step(const std::vector<int>& interiors, int object, IorOf&& ior_of) {
  RefractionStep r{1.0, interiors};
  auto& list = r.interiors;
  const double own = ior_of(object);
  if (list.empty()) {  // entering from the atmosphere (ior 1)
    list.push_back(object);
    r.ior = 1.0 / own;
  } else if (list.back() == object) {  // leaving the innermost object
    list.pop_back();
    r.ior = list.empty() ? own / 1.0 : own / ior_of(list.back());
  } else if (auto it = std::find(list.begin(), list.end(), object); it != list.end()) {
    list.erase(it);  // leaving an overlap: pretend the other one was left on entering
    r.ior = 1.0;
  } else {  // entering a new object inside another
    r.ior = ior_of(list.back()) / own;
    list.push_back(object);
  }
  return r;
}

// ComputeRelativeIOR (what the Fresnel reflectivity uses: n2/n1, and with
// POV's own rule when leaving into another object: the innermost's ior over
// this one's, which is 1 when this one is the innermost).
template <class IorOf>
double relative_ior(const std::vector<int>& interiors, int object, IorOf&& ior_of) {
  const double own = ior_of(object);
  if (interiors.empty()) return own / 1.0;
  if (std::find(interiors.begin(), interiors.end(), object) != interiors.end())
    return interiors.size() == 1 ? 1.0 / own : ior_of(interiors.back()) / own;
  return own / ior_of(interiors.back());
}

// TraceRefractionRay (Heckbert's method): D the incoming direction, N the
// normal facing it, ior = n1/n2. nullopt on total internal reflection. The
// result is not normalised (POV does not).
inline std::optional<Vec3d> refract(const Vec3d& D, const Vec3d& N, double ior) {
  double n = dot(D, N);
  Vec3d local = N;
  if (n <= 0.0)
    n = -n;
  else
    local = -N;
  double t = 1.0 + ior * ior * (n * n - 1.0);
  if (t < 0.0) return std::nullopt;
  t = ior * n - std::sqrt(t);
  return D * ior + local * t;
}

}  // namespace ra::glass
