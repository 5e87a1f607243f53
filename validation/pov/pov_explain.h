// Names the likely cause of each pixel where our render and POV-Ray's
// differ, by testing the known causes (../shared/POVRAY.md):
//  - float32: POV stores mesh2 vertices and normals as float32 (its UVs
//    are double). We render again with them rounded to float32; if the
//    pixel then equals POV's, that rounding is the cause.
//  - equal normals: POV makes a smooth triangle whose three float32 normals
//    are equal within |N1 - N2|^2 <= 1e-10 and |N1 - N3|^2 <= 1e-10 flat,
//    with its geometric normal (and float32 data).
//  - mesh2 hit point: POV's hit point is O + t D with t from the triangle's
//    float32 plane, and the smooth normal is interpolated there through its
//    Perp vector, computed in float32 step by step (renderer/pov_mesh.h:
//    pov_perp); rendered so, with the two
//    models above.
//  - mesh2 intersection: which triangle a ray meets decided by POV's own
//    test (dominant-axis projection on float32 data, renderer/pov_mesh.h)
//    and its bounding-box tree search, which stops at the nearest hit even
//    when the caller then refuses it (render.cpp, pov_mesh_hits), for every
//    ray, with the models above.
//  - mesh2 UV: texture coordinates by POV's Mesh::UVCoord at its hit point.
//  - float32 shading: every colour of the shading rounded to float32, as
//    POV's RGBColour is float (with all the mesh2 rules, and alone).
//  - POV lighting: every surface shaded by POV's ComputeLightedTexture as the
//    glass path does (RenderOptions::pov_lighting: the light's direction
//    times 1/|L - P|, each light's terms summed first, the phong cut-off),
//    in double and in float32.
//  - rounding self-hit: a reflected ray meeting the primitive it leaves
//    within the rounding of its origin (grazing, far out), skipped.
//  - shadow cache: POV first re-tests the object that last blocked a light
//    (one cache for camera-ray hits, one for deeper ones), accepting
//    t >= 1e-4 there instead of t > 1e-3. The whole image is re-rendered
//    with that cache in POV's pixel order (RenderOptions::pov_shadow_cache),
//    plainly and with every rule above.
//  - float32 colour: our value within 4 float32 ulps of a rounding boundary.
//  - shadow cache, cheap test: a blocker of the camera hit's shadow ray in
//    [1e-4, 1e-3] with POV's pixel darker than ours.
// Every model re-renders the whole pixel (reflections included); only the
// last, cheap shadow-cache test looks at the camera ray's hit alone.
#pragma once
#include <string>
#include <vector>

#include <rayaudit/image.h>
#include "../images/image_compare.h"
#include <rayaudit/render.h>
#include <rayaudit/scene/scene.h>

namespace ra {

struct PixelExplanation {
  int x = 0, y = 0;
  int levels = 0;
  std::string cause;  // empty: none of the known causes
};

// The "float32 colour" cause of one pixel (3 channels in 0..1; max levels), or
// empty: every channel that differs is one level off, and ours lies within
// 4 float32 ulps of the boundary between the two levels.
std::string float32_colour_cause(const float* ours, const float* pov, unsigned max);

std::vector<PixelExplanation> explain_differences(const Scene& scene, const Image& ours, const Image& pov,
                                                  const ImageComparison& c, const RenderOptions& options);

}  // namespace ra
