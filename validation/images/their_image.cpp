#include "their_image.h"

#include <array>
#include <cstdint>
#include <fstream>

#include "errors.h"
#include "io/file_identity.h"
#include "io/input_file.h"

namespace ra {
namespace {

namespace fs = std::filesystem;

std::uint32_t be32(const unsigned char* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}

// What the PNG's header chunks say (up to the first IDAT).
struct PngHeader {
  std::uint32_t width = 0, height = 0;
  int bit_depth = 0, colour_type = -1;
  bool srgb = false, iccp = false;
  long gamma = -1;  // gAMA * 100000; -1: none
};

[[noreturn]] void refuse(const fs::path& f, const std::string& what) { throw InputError(located(f.string(), 0, what)); }

PngHeader png_header(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::array<unsigned char, 8> sig{};
  static constexpr std::array<unsigned char, 8> kPng = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!in.read(reinterpret_cast<char*>(sig.data()), 8) || sig != kPng)
    refuse(f, "not a PNG file (the image to judge must be an RGB PNG of 8 or 16 bits)");
  PngHeader h;
  for (int chunk = 0; chunk < 1000; ++chunk) {
    unsigned char head[8];
    if (!in.read(reinterpret_cast<char*>(head), 8)) refuse(f, "PNG cut short before its pixel data");
    const std::uint32_t n = be32(head);
    const std::string type(reinterpret_cast<char*>(head + 4), 4);
    if (chunk == 0 && (type != "IHDR" || n != 13)) refuse(f, "PNG without its IHDR header first");
    if (type == "IDAT") return h;
    if (type == "IHDR" || type == "gAMA") {
      unsigned char d[13] = {};
      if (n > sizeof d || !in.read(reinterpret_cast<char*>(d), n)) refuse(f, "malformed " + type + " chunk");
      if (type == "IHDR") {
        h.width = be32(d);
        h.height = be32(d + 4);
        h.bit_depth = d[8];
        h.colour_type = d[9];
      } else if (n == 4) {
        h.gamma = long(be32(d));
      }
      in.seekg(4, std::ios::cur);  // CRC
    } else {
      h.srgb = h.srgb || type == "sRGB";
      h.iccp = h.iccp || type == "iCCP";
      in.seekg(std::streamoff(n) + 4, std::ios::cur);
    }
    if (!in) refuse(f, "PNG cut short before its pixel data");
  }
  refuse(f, "PNG with more than 1000 chunks before its pixel data");
}

}  // namespace

Image read_their_image(const fs::path& file, const ImageReference& want) {
  if (const std::string why = input_file_problem(file); !why.empty()) refuse(file, why);
  const PngHeader h = png_header(file);
  const std::string size = std::to_string(want.width) + "x" + std::to_string(want.height);
  if (h.width != std::uint32_t(want.width) || h.height != std::uint32_t(want.height))
    refuse(file, "is " + std::to_string(h.width) + "x" + std::to_string(h.height) + ", but " + want.what + " is " +
                     size + (want.remedy.empty() ? "" : " (" + want.remedy + ")"));
  switch (h.colour_type) {
    case 0:
    case 4:
      refuse(file, "is greyscale; " + want.what + " is RGB");
    case 3:
      refuse(file, "is a palette image; " + want.what + " is RGB (write 8 or 16 bits a channel)");
    case 2:
    case 6:
      break;
    default:
      refuse(file, "PNG colour type " + std::to_string(h.colour_type) + " is not RGB");
  }
  if (h.bit_depth != want.bits)
    refuse(file, "has " + std::to_string(h.bit_depth) + " bits a channel; " + want.what + " has " +
                     std::to_string(want.bits) +
                     (want.bits == 8 ? " (compare takes --bits 16 for 16-bit images)" : ""));
  if (h.srgb || h.iccp || (h.gamma >= 0 && h.gamma != 100000))
    refuse(file, std::string("is tagged as ") +
                     (h.srgb   ? "sRGB"
                      : h.iccp ? "an ICC profile"
                               : "gamma " + std::to_string(h.gamma / 1e5).substr(0, 7)) +
                     "; " + want.what +
                     " holds linear values (gAMA 1.0, or untagged): write the renderer's values "
                     "without a gamma curve");
  int w = 0, hh = 0, channels = 0;
  const std::vector<float> px = read_pixels(file, "image", w, hh, channels);
  if (w != want.width || hh != want.height || channels < 3) refuse(file, "is not an RGB image of " + size);
  Image img(w, hh);
  for (std::size_t i = 0, n = std::size_t(w) * hh; i < n; ++i) {
    if (channels == 4 && px[i * 4 + 3] < 1.0f)
      refuse(file, "pixel (" + std::to_string(i % w) + ", " + std::to_string(i / w) + ") is not opaque; " + want.what +
                       " has no alpha (write opaque pixels, or RGB)");
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = px[i * channels + c];
  }
  note_input(file);
  return img;
}

}  // namespace ra
