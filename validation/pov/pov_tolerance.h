// What may differ between our render of a scene and POV-Ray's, and why:
// scenes/pov/NAME.json beside scenes/NAME.json. Without that file the bar
// is identical output at 8 bits. Every pixel allowed to differ is listed by
// position, with the largest difference measured there and its cause (e.g.
// POV's shadow cache, ../shared/POVRAY.md), so no difference hides behind a
// loose threshold:
//   {"notes": "...", "width": W, "height": H,
//    "pixels": [{"x": 10, "y": 20, "levels": 27, "cause": "..."}]}
// width/height: the size the pixel list is for (default the scene's).
// levels: the largest channel difference allowed at that pixel, in 8-bit
//   levels (required: a listed pixel that drifts further fails). At 16 bits
//   the same pixel may differ by up to 257 (levels + 1) 16-bit levels: two
//   values whose 8-bit levels are `levels` apart are less than
//   (levels + 1)/255 apart, i.e. 257 (levels + 1) 16-bit levels.
// Unlisted pixels: identical at 8 bits; at 16 bits within
//   kPovFloat32Levels16 (optional override "max_levels_16", 0..16).
#pragma once
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "../images/image_compare.h"

namespace ra {

struct ExplainedPixel {
  int x = 0, y = 0;
  int levels = 0;  // allowed difference at 8 bits (see above for 16)
  std::string cause;
};

// At 16 bits, unlisted pixels may differ by this many levels: POV-Ray keeps
// colours in float32, and ../shared/POVRAY.md measured at most 2/65535
// between POV-Ray and an exact reimplementation of its rules on seven
// scenes. (float32 carries 24 bits; a colour summed from a few float32
// terms is off by a few 2^-24, i.e. well under one 2^-16 level, so 2 levels
// also covers the rounding to 16 bits on either side.) At 8 bits the bar
// stays identical: 2^-24 moves an 8-bit level only on a rounding boundary,
// and such pixels are listed one by one.
inline constexpr int kPovFloat32Levels16 = 2;

// The largest 16-bit difference allowed at a pixel listed with `levels`.
constexpr int allowed_levels_16(int levels) { return 257 * (levels + 1); }

struct PovTolerance {
  std::filesystem::path file;  // empty: the default (identical at 8 bits)
  std::string notes;
  std::optional<int> width, height;
  std::vector<ExplainedPixel> pixels;
  int max_levels_16 = kPovFloat32Levels16;
};

// scenes/pov/NAME.json for scenes/NAME.json.
std::filesystem::path pov_tolerance_path(const std::filesystem::path& scene_file);

// Reads `file` if it exists, else returns the default. Throws InputError on a
// malformed file.
PovTolerance load_pov_tolerance(const std::filesystem::path& file);

struct PovVerdict {
  bool pass = true;
  std::vector<std::string> lines;  // one per explained or unexplained pixel, and notes
};

// Judges a comparison made at width x height.
PovVerdict judge(const ImageComparison& c, const PovTolerance& t);

}  // namespace ra
