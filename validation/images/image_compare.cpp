#include "image_compare.h"

#include <cmath>
#include <cstdio>

#include "errors.h"
#include "image_module.h"

namespace ra {
namespace {

unsigned max_level(int bits) { return bits == 16 ? 65535u : 255u; }

// The threshold for "more than k/255": half a level of `bits` above k/255.
float threshold(int k, int bits) {
  const double m = max_level(bits);
  return float((std::round(k * m / 255.0) + 0.5) / m);
}

}  // namespace

Image quantized(const Image& img, int bits) {
  const unsigned m = max_level(bits);
  Image q(img.width, img.height);
  for (std::size_t i = 0; i < img.rgb.size(); ++i) q.rgb[i] = float(quantize(img.rgb[i], m)) / float(m);
  return q;
}

ImageComparison compare_images(const Image& ours, const Image& theirs, int bits) {
  if (bits != 8 && bits != 16) throw InputError("bits must be 8 or 16");
  if (ours.width != theirs.width || ours.height != theirs.height)
    throw InputError("images differ in size: " + std::to_string(ours.width) + "x" + std::to_string(ours.height) +
                     " and " + std::to_string(theirs.width) + "x" + std::to_string(theirs.height));
  const Image a = quantized(ours, bits), b = quantized(theirs, bits);
  ImageComparison c;
  c.width = a.width;
  c.height = a.height;
  c.bits = bits;
  c.pixels = long(a.width) * a.height;
  // compare() also sets the error flag whenever nfail > 0, so its has_error()
  // is not a failure of the comparison itself (../shared/POVRAY.md).
  image_module::CompareStats r;
  image_module::api().compare(a.width, a.height, a.rgb.data(), b.rgb.data(), threshold(4, bits), threshold(1, bits),
                              &r);
  c.mean_error = r.mean_error;
  c.rms_error = r.rms_error;
  c.psnr = r.psnr;
  c.max_error = r.max_error;
  c.max_x = r.max_x;
  c.max_y = r.max_y;
  c.max_channel = r.max_channel;
  // OIIO 2.4 counts a pixel over both thresholds in nwarn and in nfail.
  c.over_4 = long(r.nfail);
  c.over_1 = long(r.nwarn);
  // Which pixels differ, exactly, in integer levels.
  const unsigned m = max_level(bits);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int worst = 0;
      for (int ch = 0; ch < 3; ++ch) {
        const int la = int(quantize(ours.at(x, y)[ch], m)), lb = int(quantize(theirs.at(x, y)[ch], m));
        worst = std::max(worst, std::abs(la - lb));
      }
      if (worst > 0) c.differences.push_back({x, y, worst});
    }
  return c;
}

Image difference_image(const Image& ours, const Image& theirs, int bits) {
  const Image a = quantized(ours, bits), b = quantized(theirs, bits);
  const double m = max_level(bits);
  Image out(a.width, a.height);
  std::vector<float> d(a.rgb.size());
  image_module::api().absdiff(a.width, a.height, a.rgb.data(), b.rgb.data(), d.data());
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const std::size_t i = (std::size_t(y) * a.width + x) * 3;
      const double levels = std::round(std::max({d[i], d[i + 1], d[i + 2]}) * m);
      float* px = out.at(x, y);
      if (levels == 0) {
        const float grey = 0.25f * (0.2126f * a.rgb[i] + 0.7152f * a.rgb[i + 1] + 0.0722f * a.rgb[i + 2]);
        px[0] = px[1] = px[2] = grey;
        continue;
      }
      // Brightness grows with the error in 8-bit levels, from 0.5 to 1.
      const double l8 = levels * 255.0 / m;
      const float v = float(0.5 + 0.5 * std::min(1.0, std::log2(1 + l8) / 8));
      if (l8 <= 1)
        px[0] = 0, px[1] = 0, px[2] = v;
      else if (l8 <= 4)
        px[0] = 0, px[1] = v, px[2] = 0;
      else if (l8 <= 16)
        px[0] = v, px[1] = v, px[2] = 0;
      else
        px[0] = v, px[1] = 0, px[2] = 0;
    }
  return out;
}

const std::vector<DifferenceBand>& difference_key() {
  // The bands difference_image() draws, in the same order as its tests.
  static const std::vector<DifferenceBand> key = {
      {"grey", 0, 0, "identical (the first image dimmed to a quarter)"},
      {"blue", 1, 1, "1 level"},
      {"green", 2, 4, "2 to 4 levels"},
      {"yellow", 5, 16, "5 to 16 levels"},
      {"red", 17, -1, "more than 16 levels"},
  };
  return key;
}

std::string difference_key_text() {
  std::string out = "diff colours (largest channel difference, 8-bit levels; brighter = larger):";
  for (const auto& b : difference_key()) out += " " + b.colour + " " + b.meaning + ";";
  out.back() = '\n';
  return out;
}

nlohmann::json difference_key_json() {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& b : difference_key())
    out.push_back({{"colour", b.colour},
                   {"min_levels", b.min_levels},
                   {"max_levels", b.max_levels < 0 ? nlohmann::json(nullptr) : nlohmann::json(b.max_levels)},
                   {"meaning", b.meaning}});
  return out;
}

nlohmann::json to_json(const ImageComparison& c) {
  nlohmann::json j;
  j["width"] = c.width;
  j["height"] = c.height;
  j["bits"] = c.bits;
  j["pixels"] = c.pixels;
  j["identical"] = c.identical();
  j["differing"] = c.differences.size();
  j["over_1"] = c.over_1;
  j["over_4"] = c.over_4;
  j["mean_error"] = c.mean_error;
  j["rms_error"] = c.rms_error;
  // JSON has no infinity: identical images have an unbounded PSNR, null here.
  j["psnr"] = std::isfinite(c.psnr) ? nlohmann::json(c.psnr) : nlohmann::json(nullptr);
  j["max_error"] = c.max_error;
  j["max_error_pixel"] = {{"x", c.max_x}, {"y", c.max_y}, {"channel", c.max_channel}};
  nlohmann::json diffs = nlohmann::json::array();
  for (const auto& d : c.differences) diffs.push_back({{"x", d.x}, {"y", d.y}, {"levels", d.levels}});
  j["differences"] = diffs;
  return j;
}

std::string summary(const ImageComparison& c) {
  char buf[512];
  const double m = max_level(c.bits);
  std::snprintf(buf, sizeof buf,
                "pixels: %ld (%dx%d, compared at %d bits)\n"
                "identical: %s (%zu pixels differ)\n"
                "mean error: %.3g  RMS: %.3g  PSNR: %s dB\n"
                "max error: %.6g (%g levels) at pixel (%d, %d) channel %d\n"
                "pixels off by more than 1/255: %ld; by more than 4/255: %ld\n",
                c.pixels, c.width, c.height, c.bits, c.identical() ? "true" : "false", c.differences.size(),
                c.mean_error, c.rms_error, std::isfinite(c.psnr) ? std::to_string(c.psnr).c_str() : "inf", c.max_error,
                std::round(c.max_error * m), c.max_x, c.max_y, c.max_channel, c.over_1, c.over_4);
  return buf;
}

}  // namespace ra
