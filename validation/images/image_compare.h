// Compares two renders as the files would hold them: both are quantised to
// `bits` (floor(clamp(x) * max + 0.5), as POV-Ray and our PNG writer do) and
// compared with OpenImageIO's ImageBufAlgo::compare. Errors are in [0, 1]
// units; "over 1" counts pixels off by MORE than 1/255 in some channel,
// i.e. by at least two 8-bit levels (the threshold sits half a level of
// `bits` above k/255, since quantised values are exact multiples of 1/max).
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <rayaudit/image.h>

namespace ra {

struct PixelDifference {
  int x = 0, y = 0;
  int levels = 0;  // largest channel difference, in levels of the bit depth
};

struct ImageComparison {
  int width = 0, height = 0, bits = 8;
  long pixels = 0;
  double mean_error = 0, rms_error = 0, psnr = 0, max_error = 0;
  int max_x = 0, max_y = 0, max_channel = 0;
  long over_1 = 0, over_4 = 0;               // pixels off by more than 1/255, 4/255
  std::vector<PixelDifference> differences;  // every pixel that differs at all, row by row
  bool identical() const { return differences.empty(); }
};

// Throws InputError when the sizes differ.
ImageComparison compare_images(const Image& ours, const Image& theirs, int bits);

// A false-colour difference image: pixels that agree show our image dimmed
// to a quarter in grey; differing ones are blue (1 level), green (2..4),
// yellow (5..16) or red (more), brighter for larger errors.
Image difference_image(const Image& ours, const Image& theirs, int bits);

// The colours difference_image() uses, for a reader of the image: each band
// of the largest channel difference, in 8-bit levels (at 16 bits, a
// difference counts as levels * 255 / 65535), with its colour.
struct DifferenceBand {
  std::string colour;                  // "grey", "blue", ...
  int min_levels = 0, max_levels = 0;  // 8-bit levels; max -1: no bound
  std::string meaning;
};
const std::vector<DifferenceBand>& difference_key();
// The key as lines ("  grey: ...") after a heading, and as a JSON array.
std::string difference_key_text();
nlohmann::json difference_key_json();

nlohmann::json to_json(const ImageComparison& c);
// Several lines: mean, RMS, PSNR, max error and where, over 1/255, over 4/255.
std::string summary(const ImageComparison& c);

// The image as a file of `bits` would hold it (values k / max).
Image quantized(const Image& img, int bits);

}  // namespace ra
