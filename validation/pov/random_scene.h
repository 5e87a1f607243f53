// Random scenes for differential testing against POV-Ray 3.7:
// spheres, planes, lone triangles and corpus meshes at random placements,
// random finishes and corpus textures, 1 to 3 coloured lights, random
// cameras, max_depth and adc_bailout, written in our JSON scene format.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ra {

// The corpus meshes a random scene may place: small enough for POV-Ray to
// parse in a moment (at most ~10k triangles), as `${cache}/corpus/...`
// paths, only those present in the cache.
std::vector<std::string> random_scene_meshes();
// The corpus images a random scene may use as textures.
std::vector<std::string> random_scene_textures();

// Scene `index` of the batch `seed`: the same (seed, index) always gives
// the same scene (on the same corpus). Small images (at most 160 x 120):
// differences are found per pixel, and many small scenes beat a few big ones.
nlohmann::json random_scene(std::uint64_t seed, int index);

}  // namespace ra
