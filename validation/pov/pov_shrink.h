// Differential testing against POV-Ray 3.7: compare a scene with
// POV-Ray and explain every differing pixel (pov_explain.h); shrink a scene
// with an unexplained pixel to a minimal one that still has it, by dropping
// objects, lights and features one at a time (greedy delta debugging) while
// the pixel stays different and unexplained.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pov_explain.h"
#include <rayaudit/scene/scene.h>

namespace ra {

struct ExplainedComparison {
  int differing = 0;                     // pixels that differ at 8 bits
  std::vector<PixelExplanation> pixels;  // every differing pixel, cause empty when unknown
  int unexplained() const;
};

// Renders `scene` with our tracer and POV-Ray (8 bits), compares them and
// runs --explain's hypotheses on every differing pixel.
ExplainedComparison compare_and_explain(const Scene& scene, int threads);

// Does the scene (JSON text as read from `file`) still show an unexplained
// difference at pixel (x, y)?
using PixelPersists = std::function<bool(const nlohmann::json& scene)>;
PixelPersists unexplained_pixel_persists(const std::filesystem::path& file, int x, int y, int threads);

// The candidate simplifications of a scene, each one step smaller: without
// one object, without one light, without one feature (reflection, phong,
// texture, a mesh's own material, smooth shading, rotations, a non-default
// global), in that order.
std::vector<nlohmann::json> simplifications(const nlohmann::json& scene);

// Greedy shrinking: applies the first simplification that keeps `persists`
// true, and repeats until none does (or `max_tries` predicate calls).
// Returns the smallest scene found; `tries` gets the number of calls.
nlohmann::json shrink_scene(const nlohmann::json& scene, const PixelPersists& persists, int max_tries = 200,
                            int* tries = nullptr);

// A scene as text that reads in one screen: any value whose one-line form
// fits in a line stays on one line, larger ones are indented.
std::string readable_json(const nlohmann::json& j, int indent = 0);

}  // namespace ra
