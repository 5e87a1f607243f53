// What may differ between our render of a scene and POV-Ray's, and why:
// scenes/pov/NAME.json beside scenes/NAME.json. Without that file the bar
// is identical output at 8 bits. Every pixel allowed to differ is listed by
// position with its cause (e.g. POV's shadow cache, ../shared/POVRAY.md),
// so no difference hides behind a loose threshold:
//   {"notes": "...", "width": W, "height": H,
//    "pixels": [{"x": 10, "y": 20, "cause": "..."}], "max_levels_16": 2}
// width/height: the size the pixel list is for (default the scene's).
// max_levels_16: at 16 bits, other pixels may differ by this many levels
// (default 2: POV keeps colours in float32; POVRAY.md measured 2/65535).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "image_compare.h"

namespace ra {

struct ExplainedPixel {
  int x = 0, y = 0;
  std::string cause;
};

struct PovTolerance {
  std::filesystem::path file;  // empty: the default (identical at 8 bits)
  std::string notes;
  std::optional<int> width, height;
  std::vector<ExplainedPixel> pixels;
  int max_levels_16 = 2;
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
