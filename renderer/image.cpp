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
#include "image_checks.h"
#include "memory_budget.h"

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
    if (eight)
      px8[i] = std::uint8_t(q);
    else
      px16[i] = std::uint16_t(q);
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

namespace {

// The header's size is trusted only as far as the file can hold it: at
// most kMaxPixelsPerByte pixels a byte, and never beyond the render limit.
// bytes 0: unknown (not checked).
void check_declared_size(const std::string& name, const char* what, std::uint64_t w, std::uint64_t h,
                         std::uint64_t bytes) {
  const std::string dims = std::to_string(w) + "x" + std::to_string(h);
  if (w > kMaxImageSide || h > kMaxImageSide)
    throw InputError(located(name, 0,
                             what + std::string(" is ") + dims + ", more than the limit of " +
                                 std::to_string(kMaxImageSide) + " pixels a side"));
  if (bytes && w * h > bytes * kMaxPixelsPerByte)
    throw InputError(located(name, 0,
                             what + std::string(" header declares ") + dims + " pixels, more than its " +
                                 std::to_string(bytes) + " bytes can hold (the file is truncated or corrupt)"));
}

// An image opened by the module, its header checked against the limits.
struct OpenedImage {
  std::unique_ptr<void, void (*)(void*)> in{nullptr, [](void*) {}};
  image_module::Header spec;
  std::string name, dims;
};

OpenedImage open_checked(const std::filesystem::path& path, const char* what) {
  check_input_file(path);  // a FIFO would block OIIO forever; a directory is "not a PNG file"
  const std::string name = path.string();
  // What OIIO's readers accept silently (a PNG without IEND, a PNM maxval
  // of 0), or an empty file, said before OIIO is asked.
  const ImageProblem why = image_container_problem(path);
  if (!why.what.empty())
    throw InputError(located(name, why.line, std::string("cannot read ") + what + ": " + why.what));
  std::error_code ec;
  const std::uint64_t bytes = std::filesystem::file_size(path, ec);
  if (why.width || why.height) check_declared_size(name, what, why.width, why.height, ec ? 0 : bytes);
  const image_module::Api& oiio = image_module::api();
  OpenedImage o;
  o.name = name;
  std::string err;
  o.in = std::unique_ptr<void, void (*)(void*)>(oiio.open(name.c_str(), &o.spec, &err), oiio.close);
  if (!o.in)
    throw InputError(located(name, 0, std::string("cannot read ") + what + ": " + image_open_problem(path, err)));
  const image_module::Header& spec = o.spec;
  const std::uint64_t w = std::uint64_t(std::max(spec.width, 0)), h = std::uint64_t(std::max(spec.height, 0));
  o.dims = std::to_string(w) + "x" + std::to_string(h);
  if (w == 0 || h == 0 || spec.channels < 1 || spec.channels > 64)
    throw InputError(located(
        name, 0,
        what + std::string(" header declares ") + o.dims + " with " + std::to_string(spec.channels) + " channels"));
  check_declared_size(name, what, w, h, ec ? 0 : bytes);
  return o;
}

// A buffer of n values, its size checked against the memory left first.
template <class T>
void allocate(std::vector<T>& v, std::uint64_t n, const OpenedImage& o, const char* what) {
  const std::uint64_t need = n * sizeof(T), avail = available_memory();
  auto fail = [&] {
    throw InputError(located(o.name, 0,
                             what + std::string(" of ") + o.dims + " needs " +
                                 std::to_string((need + (1 << 20) - 1) >> 20) + " MB to read, but only " +
                                 std::to_string(avail >> 20) +
                                 " MB are available (free memory, or `ulimit -v`): not enough memory"));
  };
  if (need > avail) fail();
  try {
    v.resize(std::size_t(n));
  } catch (const std::bad_alloc&) {  // a legal size this machine cannot hold: still about this file
    fail();
  }
}

void read_into(const OpenedImage& o, int channels, int type, void* dst, const char* what) {
  std::string err;
  if (!image_module::api().read(o.in.get(), channels, type, dst, &err))
    throw InputError(located(o.name, 0, std::string("cannot read ") + what + ": " + err));
}

}  // namespace

std::vector<float> read_pixels(const std::filesystem::path& path, const char* what, int& width, int& height,
                               int& channels) {
  QuietStderr quiet;
  const OpenedImage o = open_checked(path, what);
  width = o.spec.width;
  height = o.spec.height;
  channels = o.spec.channels;
  std::vector<float> all;
  allocate(all, std::uint64_t(width) * std::uint64_t(height) * std::uint64_t(channels), o, what);
  read_into(o, channels, image_module::kFloat, all.data(), what);
  return all;
}

StoredPixels read_stored_pixels(const std::filesystem::path& path, const char* what) {
  QuietStderr quiet;
  const OpenedImage o = open_checked(path, what);
  StoredPixels p;
  p.width = o.spec.width;
  p.height = o.spec.height;
  p.channels = o.spec.channels >= 3 ? 3 : 1;
  const std::uint64_t n = std::uint64_t(p.width) * std::uint64_t(p.height) * std::uint64_t(p.channels);
  switch (o.spec.type) {
    case image_module::kUint8:
      allocate(p.u8, n, o, what);
      read_into(o, p.channels, image_module::kUint8, p.u8.data(), what);
      break;
    case image_module::kUint16:
      allocate(p.u16, n, o, what);
      read_into(o, p.channels, image_module::kUint16, p.u16.data(), what);
      break;
    default:
      allocate(p.f, n, o, what);
      read_into(o, p.channels, image_module::kFloat, p.f.data(), what);
      // A NaN or infinite texel (PFM, EXR) rendered black, silently: every
      // other reader refuses non-finite numbers.
      for (std::size_t i = 0; i < p.f.size(); ++i)
        if (!std::isfinite(p.f[i])) {
          const std::size_t px = i / std::size_t(p.channels);
          throw InputError(located(o.name, 0,
                                   std::string(what) + " texel (" + std::to_string(px % std::size_t(p.width)) + ", " +
                                       std::to_string(px / std::size_t(p.width)) + ") is " +
                                       (std::isnan(p.f[i]) ? "NaN" : "infinite") + ", not a colour"));
        }
  }
  return p;
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
