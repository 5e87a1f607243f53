// The OpenImageIO half of the image code, behind a table of functions in a
// module (rayaudit_image.so, renderer/oiio/) that is dlopen()ed on first use.
// Why: OIIO pulls in ~260 shared libraries (130 MB resident, 0.1-0.2 s at
// every start), which `rayaudit --version`, `info` or `audit` never need.
// image.cpp, image_compare.cpp and pov_export.cpp call through image_module::api().
// The module reports failures as strings (no exception crosses the dlopen
// boundary); the callers turn them into InputError lines naming the file.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace ra::image_module {

// Bumped whenever Api changes: a stale module beside a newer rayaudit is refused.
constexpr int kVersion = 2;

// Pixel types read() converts to (and a file's own, in Header::type).
enum PixelType : int { kFloat = 0, kUint8 = 1, kUint16 = 2 };

struct Header {
  int width = 0, height = 0, channels = 0;
  int type = kFloat;  // the file's own: kUint8, kUint16, or kFloat for anything else
};

// OIIO's ImageBufAlgo::compare, field for field.
struct CompareStats {
  double mean_error = 0, rms_error = 0, psnr = 0, max_error = 0;
  int max_x = 0, max_y = 0, max_channel = 0;
  long nwarn = 0, nfail = 0;
};

struct Api {
  int version;
  std::size_t size;  // sizeof(Api) in the module
  // PNG bytes of w x h RGB pixels (uint8 when bits == 8, else uint16),
  // tagged with `colorspace` ("sRGB" or "Linear"). false: *err says why.
  bool (*encode_png)(int w, int h, int bits, const void* pixels, const char* colorspace,
                     std::vector<unsigned char>* out, std::string* err);
  // A float RGB EXR written to `path`, close() checked (full disk).
  bool (*write_exr)(const char* path, int w, int h, const float* rgb, std::string* err);
  // Opens an image and reads its header; nullptr and *err (first line of
  // OIIO's text) on failure. read() fills w*h*channels values of `type` (a
  // PixelType) from the first `channels` channels; close() frees.
  void* (*open)(const char* path, Header* header, std::string* err);
  bool (*read)(void* image, int channels, int type, void* dst, std::string* err);
  void (*close)(void* image);
  // ImageBufAlgo::compare of two float RGB images of w x h.
  void (*compare)(int w, int h, const float* a, const float* b, float fail, float warn, CompareStats* out);
  // ImageBufAlgo::absdiff of two float RGB images into `out` (w*h*3 floats).
  void (*absdiff)(int w, int h, const float* a, const float* b, float* out);
  // The image at `source` as an RGB PNG (alpha dropped, grey made RGB,
  // 8 bits if the source is 8-bit, else 16). 0: done; 1: source unreadable;
  // 2: encoding failed. *err says why.
  int (*rgb_png)(const char* source, std::vector<unsigned char>* out, std::string* err);
};

// The module's table, loaded on the first call. Looked for, in order:
// $RAYAUDIT_IMAGE_MODULE (only there when set); beside the executable (the
// build tree); EXE_DIR/../LIBDIR/rayaudit/ (an installed rayaudit); by bare
// name through the executable's RUNPATH (programs linking the installed
// package get it from rayauditConfig.cmake); the configured install LIBDIR.
// Not found or unloadable: InputError, one line naming the module.
const Api& api();

// The module's file name.
constexpr const char* kFileName = "rayaudit_image.so";

}  // namespace ra::image_module

// The one symbol the module exports.
extern "C" const ra::image_module::Api* rayaudit_image_module_api();
