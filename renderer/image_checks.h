// Checks of image files before OpenImageIO reads them, for what its readers
// accept silently: a PNG cut short after its pixel
// data (no IEND), a PNM whose maxval is 0, and files that are no image at
// all (text, a mesh, an empty file), which OIIO describes in its own words.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

namespace ra {

// What these checks see wrong (what.empty(): nothing), with its line where
// the header is text (PNM) and "byte N: " in `what` where it is binary (PNG).
// Reads at most the chunk headers of a PNG and the header of a PNM.
struct ImageProblem {
  long line = 0;
  std::string what;
  // The size the header declares where OIIO's reader would allocate it in
  // open() already (GIF: a 35-byte file declaring 16384^2 took 1.2 GB), so
  // the caller can apply its limits first; 0 when not read here.
  std::uint64_t width = 0, height = 0;
};
ImageProblem image_container_problem(const std::filesystem::path& path);

// What to say when OpenImageIO cannot open `path`: "not an image (...)" for
// a text file or one no reader recognises, else OIIO's first line `oiio_err`.
std::string image_open_problem(const std::filesystem::path& path, const std::string& oiio_err);

}  // namespace ra
