// Names the likely cause of each pixel where our render and POV-Ray's
// differ, by testing the known causes (../shared/POVRAY.md):
//  - float32: POV stores mesh2 vertices, normals and UVs as float32. We
//    render again with the mesh data rounded to float32; if the pixel then
//    equals POV's, that rounding is the cause.
//  - equal normals: POV makes a smooth triangle whose three normals are
//    equal flat, with its geometric normal (and float32 data).
//  - mesh2 hit point: POV's hit point is O + t D with t from the triangle's
//    float32 plane, and the smooth normal is interpolated there through its
//    float32 Perp vector (renderer/pov_mesh.h); rendered so, with the two
//    models above.
//  - float32 colour: our value within 4 float32 ulps of a rounding boundary.
//  - shadow cache: POV first re-tests the object that blocked the previous
//    shadow ray, accepting t >= 1e-4 there instead of t > 1e-3. We cast the
//    pixel's shadow rays with the window [1e-4, 1e-3]; a blocker there, with
//    POV's pixel darker than ours, is that quirk.
// Camera rays only: a difference reached through a reflection is reported
// as unexplained.
#pragma once
#include <string>
#include <vector>

#include "image.h"
#include "image_compare.h"
#include "render.h"
#include "scene.h"

namespace ra {

struct PixelExplanation {
  int x = 0, y = 0;
  int levels = 0;
  std::string cause;  // empty: none of the known causes
};

std::vector<PixelExplanation> explain_differences(const Scene& scene, const Image& ours, const Image& pov,
                                                  const ImageComparison& c, const RenderOptions& options);

}  // namespace ra
