// The image module (rayaudit_image.so): every call rayaudit makes into
// OpenImageIO, loaded on first use by renderer/image_module.cpp (see image_module.h).
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <exception>
#include <memory>
#include <new>
#include <stdexcept>

#include "../image_module.h"

namespace {

using ra::image_module::Api;
using ra::image_module::CompareStats;
using ra::image_module::Header;

// The first line of an OIIO error text (they can run to several).
std::string first_line(std::string s) {
  const auto nl = s.find('\n');
  if (nl != std::string::npos) s.resize(nl);
  return s.empty() ? "unreadable or unsupported image" : s;
}

// Encodes through an in-memory proxy: OIIO's PNG writer does not report a
// failed write to a file (full disk), so the caller writes the bytes itself.
bool encode(const OIIO::ImageSpec& spec, const void* pixels, const OIIO::ImageBuf* buf, std::vector<unsigned char>* out,
            std::string* err) {
  OIIO::Filesystem::IOVecOutput proxy(*out);
  auto o = OIIO::ImageOutput::create("png");
  if (!o) {
    *err = "cannot create PNG writer: " + first_line(OIIO::geterror());
    return false;
  }
  const bool ok = o->set_ioproxy(&proxy) && o->open("memory.png", spec) &&
                  (buf ? buf->write(o.get()) : o->write_image(spec.format, pixels)) && o->close();
  if (!ok) *err = first_line(o->geterror());
  return ok;
}

bool encode_png(int w, int h, int bits, const void* pixels, const char* colorspace, std::vector<unsigned char>* out,
                std::string* err) try {
  OIIO::ImageSpec spec(w, h, 3, bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  spec.attribute("oiio:ColorSpace", colorspace);
  return encode(spec, pixels, nullptr, out, err);
} catch (const std::exception& e) {
  *err = e.what();
  return false;
}

bool write_exr(const char* path, int w, int h, const float* rgb, std::string* err) try {
  auto o = OIIO::ImageOutput::create(path);
  if (!o) {
    *err = "cannot create: " + first_line(OIIO::geterror());
    return false;
  }
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
  // close() flushes: a failure there (disk full) is a failed write too.
  if (!o->open(path, spec) || !o->write_image(OIIO::TypeDesc::FLOAT, rgb) || !o->close()) {
    *err = "cannot write: " + first_line(o->geterror());
    return false;
  }
  return true;
} catch (const std::exception& e) {
  *err = e.what();
  return false;
}

// A reader's allocation for an absurd declared size fails inside the
// library ("vector::_M_default_append" for a 65535x65535 GIF): said as such.
std::string exception_text(const std::exception& e) {
  if (dynamic_cast<const std::length_error*>(&e) || dynamic_cast<const std::bad_alloc*>(&e))
    return "the size the file declares cannot be allocated (a corrupt header, or too little memory: `ulimit -v`?)";
  return e.what();
}

void* open(const char* path, Header* header, std::string* err) try {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    *err = first_line(OIIO::geterror());
    return nullptr;
  }
  const OIIO::ImageSpec& spec = in->spec();
  const int type = spec.format == OIIO::TypeDesc::UINT8    ? ra::image_module::kUint8
                   : spec.format == OIIO::TypeDesc::UINT16 ? ra::image_module::kUint16
                                                           : ra::image_module::kFloat;
  *header = Header{spec.width, spec.height, spec.nchannels, type};
  return in.release();
} catch (const std::exception& e) {
  *err = exception_text(e);
  return nullptr;
}

bool read(void* image, int channels, int type, void* dst, std::string* err) try {
  auto* in = static_cast<OIIO::ImageInput*>(image);
  const OIIO::TypeDesc td = type == ra::image_module::kUint8    ? OIIO::TypeDesc::UINT8
                            : type == ra::image_module::kUint16 ? OIIO::TypeDesc::UINT16
                                                                : OIIO::TypeDesc::FLOAT;
  if (!in->read_image(0, 0, 0, channels, td, dst)) {
    *err = first_line(in->geterror());
    return false;
  }
  // Some readers return true for a truncated file (a JPEG cut short, a PNG
  // without IEND) and only record the error: such a texture was used with
  // its missing part grey.
  if (in->has_error()) {
    *err = first_line(in->geterror());
    return false;
  }
  return true;
} catch (const std::exception& e) {
  *err = exception_text(e);
  return false;
}

void close(void* image) {
  std::unique_ptr<OIIO::ImageInput> in(static_cast<OIIO::ImageInput*>(image));
  if (in) in->close();
}

OIIO::ImageBuf to_buf(int w, int h, const float* rgb) {
  OIIO::ImageBuf buf(OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT));
  buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, rgb);
  return buf;
}

void compare(int w, int h, const float* a, const float* b, float fail, float warn, CompareStats* out) {
  const OIIO::ImageBuf A = to_buf(w, h, a), B = to_buf(w, h, b);
  const auto r = OIIO::ImageBufAlgo::compare(A, B, fail, warn);
  *out =
      CompareStats{r.meanerror, r.rms_error, r.PSNR, r.maxerror, r.maxx, r.maxy, r.maxc, long(r.nwarn), long(r.nfail)};
}

void absdiff(int w, int h, const float* a, const float* b, float* out) {
  const OIIO::ImageBuf diff = OIIO::ImageBufAlgo::absdiff(to_buf(w, h, a), to_buf(w, h, b));
  diff.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, out);
}

int rgb_png(const char* source, std::vector<unsigned char>* out, std::string* err) try {
  OIIO::ImageBuf in(source);
  if (!in.read(0, 0, true)) {
    *err = first_line(in.geterror());
    return 1;
  }
  const int nch = in.spec().nchannels;
  // RGB without alpha; a grey image becomes three equal channels.
  const int channels[3] = {0, nch >= 3 ? 1 : 0, nch >= 3 ? 2 : 0};
  const OIIO::ImageBuf rgb3 = OIIO::ImageBufAlgo::channels(in, 3, channels);
  OIIO::ImageSpec spec = rgb3.spec();
  spec.set_format(in.spec().format == OIIO::TypeDesc::UINT8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  return encode(spec, nullptr, &rgb3, out, err) ? 0 : 2;
} catch (const std::exception& e) {
  *err = e.what();
  return 2;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) const Api* rayaudit_image_module_api() {
  // OpenImageIO and OpenEXR start thread pools of their own (one thread a
  // core, each with a stack and a malloc arena of address space), which
  // abort or hang when the system refuses a thread (under an address-space
  // limit of 410-450 MB). Our images are small (textures,
  // goldens, one render): each call works on the calling thread.
  static const bool single = [] {
    OIIO::attribute("threads", 1);
    OIIO::attribute("exr_threads", -1);
    return true;
  }();
  (void)single;
  static const Api api{
      ra::image_module::kVersion, sizeof(Api), encode_png, write_exr, open, read, close, compare, absdiff, rgb_png};
  return &api;
}
