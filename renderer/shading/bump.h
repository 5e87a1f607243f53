// Bump mapping on triangles with UVs: document 002's two variants and
// POV-Ray 3.7's bump_map.
//
// Variant 2, "height" (the default; document 002, "Изчисляване на bump map
// текстурата"): a derivative texture is computed once per image,
//   dx(x, y) = I(x, y) - I(x+1, y),   dy(x, y) = I(x, y) - I(x, y+1),
// with I = (R + G + B) / 3 and WRAPPING at the right and bottom borders (the
// textures repeat, so the neighbour of the last column is the first). It is
// looked up at (u, v) like any texture (nearest or bilinear) and
//   n' = normalize(n + strength (dx dNdx + dy dNdy))
// where dNdx is the 3D direction of the image's +x (= +u) and dNdy that of
// the image's +y, i.e. of -v since v = 0 is the bottom row: so that a
// brighter texel is higher in both directions. dNdx, dNdy come from the
// triangle: the UV axes expressed in the UV edge basis
// (x = px AB + qx AC, y = py AB + qy AC) and mapped with the 3D edges,
// normalised.
//
// Variant 1, "normal-map" (document 002: "RGB of the texel is the XYZ
// deflection"): each texel holds d = 2 RGB - 1 in the triangle's tangent
// frame (X along +u, Y along +v, Z along the normal):
//   n' = normalize(strength (d.x Tu + d.y Tv) + d.z n),
// so strength 1 reproduces the encoded normal and (0.5, 0.5, 1) changes
// nothing (up to 8-bit quantisation: 128/255 is not exactly 0.5).
//
// "pov": POV-Ray 3.7's bump_map (imageutil.cpp): three taps at image
// coordinates (x, y), (x-1, y+1), (x+1, y+1) (wrapped), heights
// h = bump_size * (0.297 R + 0.589 G + 0.114 B), the normal of the triangle
// (0, h1, 0), (-1, h2, 1), (1, h3, 1), placed in the frame
// X = normalize(N x +Y), Y = N, Z = normalize(X x Y) as X bx + Y by - Z bz,
// where N is the normal ALREADY FLIPPED to face the ray (POV flips before
// perturbing). The UV layout's orientation on the surface plays no part.
#pragma once
#include <optional>

#include "../scene/scene.h"
#include "texture.h"

namespace ra {

// The 3D directions of +u and +v on a triangle (unit length), or nullopt
// when its UVs are degenerate.
struct UvBasis {
  Vec3d tu, tv;
};
std::optional<UvBasis> uv_basis(const Vec3d& a, const Vec3d& b, const Vec3d& c, const std::array<double, 2>& ta,
                                const std::array<double, 2>& tb, const std::array<double, 2>& tc);

// Document 002's derivative texture: (dx, dy, 0) per texel.
Texture height_derivatives(const Texture& height);

// Variant 2: `deriv` from height_derivatives.
Vec3d bump_height(const Vec3d& n, const Texture& deriv, TextureFilter filter, double strength, double u, double v,
                  const UvBasis& basis);
// Variant 1.
Vec3d bump_normal_map(const Vec3d& n, const Texture& map, TextureFilter filter, double strength, double u, double v,
                      const UvBasis& basis);
// POV-Ray's bump_map; `n` faces the ray; bump_size = strength.
Vec3d bump_pov(const Vec3d& n, const Texture& image, TextureFilter filter, double bump_size, double u, double v);

}  // namespace ra
