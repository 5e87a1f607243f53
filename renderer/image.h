// Linear float RGB images and their files, through OpenImageIO (loaded on
// first use: image_module.h): PNG 8 or 16 bits per channel (linear values
// unless sRGB is asked for), EXR float.
#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>

#include "vec.h"

namespace ra {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row-major, row 0 at the top, 3 floats a pixel
  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(std::size_t(w) * h * 3, 0.f) {}
  float* at(int x, int y) { return &rgb[(std::size_t(y) * width + x) * 3]; }
  const float* at(int x, int y) const { return &rgb[(std::size_t(y) * width + x) * 3]; }
};

struct ImageWriteOptions {
  int bits = 8;       // 8 or 16 for PNG; EXR is always float
  bool srgb = false;  // encode with the sRGB curve (PNG only)
};

// Quantises as POV-Ray does: floor(clamp(x, 0, 1) * max + 0.5).
unsigned quantize(float x, unsigned max);

// Writes atomically (temporary file renamed into place). The format comes
// from the extension: .png or .exr. Throws InputError on failure.
void write_image(const std::filesystem::path& path, const Image& img, const ImageWriteOptions& opt = {});

// Limits on an image read from a file (textures, goldens, POV-Ray's output):
// a side at most the render's limit (--width, --height), and at most
// kMaxPixelsPerByte pixels for each byte of the file (deflate's maximum ratio,
// 1032:1, at 1 bit a pixel: 8256), so a 69-byte PNG declaring 20000x20000 is
// refused from its header, not after 4.8 GB.
constexpr std::uint64_t kMaxImageSide = 16384;
constexpr std::uint64_t kMaxPixelsPerByte = 8 * 1032;

// The pixels of an image file as floats, `channels` per pixel, checking the
// limits above and the path (a directory or FIFO is named as such). `what`
// names the file's role in messages ("image", "texture"). libpng's own
// stderr text is suppressed: every failure is one InputError naming the file.
std::vector<float> read_pixels(const std::filesystem::path& path, const char* what, int& width, int& height,
                               int& channels);

// An image's pixels as a texture keeps them: grey (1 channel: a grey or
// grey + alpha file) or RGB (3: alpha and further channels dropped), in the
// file's own 8 or 16 bits when it has them (value v means v / 255 or
// v / 65535, as OpenImageIO converts), else float. A 16384 x 16384 1-bit
// PNG is 256 MB here, not the 1 GB + 3 GB of float channels it was.
struct StoredPixels {
  int width = 0, height = 0, channels = 0;
  std::vector<std::uint8_t> u8;
  std::vector<std::uint16_t> u16;
  std::vector<float> f;  // exactly one of the three holds width * height * channels values
};

// read_pixels' checks, then the pixels as StoredPixels. The decoded size is
// checked against the memory available (memory_budget.h) before anything is
// allocated: "texture of WxH needs N MB ...".
StoredPixels read_stored_pixels(const std::filesystem::path& path, const char* what);

// Reads any image OpenImageIO can read, as linear float RGB (no colour
// conversion: a PNG's 8-bit values v become v / 255).
Image read_image(const std::filesystem::path& path);

}  // namespace ra
