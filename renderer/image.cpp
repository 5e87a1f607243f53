#include "image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "atomic_file.h"
#include "errors.h"

namespace ra {

unsigned quantize(float x, unsigned max) {
  const float c = std::clamp(x, 0.0f, 1.0f);
  return unsigned(std::floor(c * float(max) + 0.5f));
}

namespace {
float srgb_encode(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
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
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throw InputError(located(path.string(), 0, "cannot create: " + OIIO::geterror()));
    const std::size_t n = img.rgb.size();
    if (ext == ".exr") {
      OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::FLOAT);
      if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, img.rgb.data()))
        throw InputError(located(path.string(), 0, "cannot write: " + out->geterror()));
    } else if (opt.bits == 8) {
      std::vector<std::uint8_t> px(n);
      for (std::size_t i = 0; i < n; ++i)
        px[i] = std::uint8_t(quantize(opt.srgb ? srgb_encode(img.rgb[i]) : img.rgb[i], 255));
      OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::UINT8);
      spec.attribute("oiio:ColorSpace", opt.srgb ? "sRGB" : "Linear");
      if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, px.data()))
        throw InputError(located(path.string(), 0, "cannot write: " + out->geterror()));
    } else {
      std::vector<std::uint16_t> px(n);
      for (std::size_t i = 0; i < n; ++i)
        px[i] = std::uint16_t(quantize(opt.srgb ? srgb_encode(img.rgb[i]) : img.rgb[i], 65535));
      OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::UINT16);
      spec.attribute("oiio:ColorSpace", opt.srgb ? "sRGB" : "Linear");
      if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT16, px.data()))
        throw InputError(located(path.string(), 0, "cannot write: " + out->geterror()));
    }
    // close() flushes: a failure here (disk full) must not rename a
    // truncated file into place.
    if (!out->close()) throw InputError(located(path.string(), 0, "cannot write: " + out->geterror()));
  });
}

Image read_image(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) throw InputError(located(path.string(), 0, "cannot read image: " + OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> all(std::size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw InputError(located(path.string(), 0, "cannot read image: " + in->geterror()));
  Image img(spec.width, spec.height);
  for (std::size_t i = 0, n = std::size_t(spec.width) * spec.height; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      img.rgb[i * 3 + c] = all[i * spec.nchannels + std::min(c, spec.nchannels - 1)];
  in->close();
  return img;
}

}  // namespace ra
