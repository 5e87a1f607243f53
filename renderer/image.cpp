#include "image.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <new>
#include <string>

#include "io/atomic_file.h"
#include "errors.h"
#include "image_module.h"
#include "io/input_file.h"

namespace ra {

unsigned quantize(float x, unsigned max) {
  if (std::isnan(x)) return 0;  // clamp would pass NaN on, and its cast is undefined
  const float c = std::clamp(x, 0.0f, 1.0f);
  return unsigned(std::floor(c * float(max) + 0.5f));
}

namespace {
float srgb_encode(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}
// The PNG file's bytes (8 or 16 bits per channel).
std::vector<unsigned char> encode_png(const Image& img, const ImageWriteOptions& opt,
                                      const std::filesystem::path& path) {
  const std::size_t n = img.rgb.size();
  const bool eight = opt.bits == 8;
  const unsigned max = eight ? 255 : 65535;
  std::vector<std::uint8_t> px8(eight ? n : 0);
  std::vector<std::uint16_t> px16(eight ? 0 : n);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned q = quantize(opt.srgb ? srgb_encode(img.rgb[i]) : img.rgb[i], max);
    if (eight) px8[i] = std::uint8_t(q);
    else px16[i] = std::uint16_t(q);
  }
  std::vector<unsigned char> bytes;
  std::string err;
  const void* px = eight ? static_cast<const void*>(px8.data()) : px16.data();
  if (!image_module::api().encode_png(img.width, img.height, opt.bits, px, opt.srgb ? "sRGB" : "Linear", &bytes, &err))
    throw InputError(located(path.string(), 0, "cannot encode PNG: " + err));
  return bytes;
}

}  // namespace

void write_image(const std::filesystem::path& path, const Image& img, const ImageWriteOptions& opt) {
  std::string ext = path.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png" && ext != ".exr")
    throw InputError(located(path.string(), 0, "unsupported output format (use .png or .exr)"));
  if (ext == ".png" && opt.bits != 8 && opt.bits != 16)
    throw InputError(located(path.string(), 0, "PNG bits must be 8 or 16"));
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    if (ext == ".exr") {
      std::string err;
      if (!image_module::api().write_exr(tmp.c_str(), img.width, img.height, img.rgb.data(), &err))
        throw InputError(located(path.string(), 0, err));
      return;
    }
    // OIIO's PNG writer does not report a failed write (full disk: exit 0
    // and a truncated file), so the PNG is encoded in memory and written
    // with every write, fsync and close checked.
    const std::vector<unsigned char> png = encode_png(img, opt, path);
    write_bytes_checked(tmp, png.data(), png.size(), path.string());
  });
}

namespace {

// libpng and some OIIO readers print their complaints on stderr themselves
// (4-5 lines for a truncated PNG, the first naming no file). While an image
// is read, fd 2 goes to a scratch file; the error thrown names the file.
class QuietStderr {
 public:
  QuietStderr() {
    std::fflush(stderr);
    saved_ = ::dup(2);
    std::FILE* sink = std::tmpfile();
    if (saved_ >= 0 && sink) ::dup2(::fileno(sink), 2);
    if (sink) std::fclose(sink);  // fd 2 keeps the (already unlinked) file open
  }
  ~QuietStderr() {
    std::fflush(stderr);
    if (saved_ >= 0) {
      ::dup2(saved_, 2);
      ::close(saved_);
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_ = -1;
};


}  // namespace

std::vector<float> read_pixels(const std::filesystem::path& path, const char* what, int& width, int& height,
                               int& channels) {
  check_input_file(path);  // a FIFO would block OIIO forever; a directory is "not a PNG file"
  std::error_code ec;
  const std::uint64_t bytes = std::filesystem::file_size(path, ec);
  const std::string name = path.string();
  const image_module::Api& oiio = image_module::api();
  QuietStderr quiet;
  image_module::Header spec;
  std::string err;
  const std::unique_ptr<void, void (*)(void*)> in(oiio.open(name.c_str(), &spec, &err), oiio.close);
  if (!in) throw InputError(located(name, 0, std::string("cannot read ") + what + ": " + err));
  const std::uint64_t w = std::uint64_t(std::max(spec.width, 0)), h = std::uint64_t(std::max(spec.height, 0));
  const std::string dims = std::to_string(w) + "x" + std::to_string(h);
  if (w == 0 || h == 0 || spec.channels < 1 || spec.channels > 64)
    throw InputError(located(name, 0, what + std::string(" header declares ") + dims + " with " +
                                          std::to_string(spec.channels) + " channels"));
  // The header's size is trusted only as far as the file can hold it: at
  // most kMaxPixelsPerByte pixels a byte, and never beyond the render limit.
  if (w > kMaxImageSide || h > kMaxImageSide)
    throw InputError(located(name, 0, what + std::string(" is ") + dims + ", more than the limit of " +
                                          std::to_string(kMaxImageSide) + " pixels a side"));
  if (!ec && w * h > bytes * kMaxPixelsPerByte)
    throw InputError(located(name, 0, what + std::string(" header declares ") + dims + " pixels, more than its " +
                                          std::to_string(bytes) + " bytes can hold (the file is truncated or corrupt)"));
  width = int(w);
  height = int(h);
  channels = spec.channels;
  std::vector<float> all;
  try {
    all.resize(std::size_t(w * h) * std::size_t(channels));
  } catch (const std::bad_alloc&) {  // a legal size this machine cannot hold: still about this file
    throw InputError(located(name, 0, what + std::string(" of ") + dims + " needs " +
                                          std::to_string(w * h * std::uint64_t(channels) * 4 >> 20) +
                                          " MB to read: not enough memory"));
  }
  if (!oiio.read(in.get(), channels, all.data(), &err))
    throw InputError(located(name, 0, std::string("cannot read ") + what + ": " + err));
  return all;
}

Image read_image(const std::filesystem::path& path) {
  int w = 0, h = 0, nc = 0;
  const std::vector<float> all = read_pixels(path, "image", w, h, nc);
  Image img(w, h);
  for (std::size_t i = 0, n = std::size_t(w) * h; i < n; ++i)
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = all[i * nc + std::min(c, nc - 1)];
  return img;
}

}  // namespace ra
