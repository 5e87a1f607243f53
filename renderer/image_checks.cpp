// Image container checks before OpenImageIO (see image_checks.h). PNG chunk
// layout: PNG specification 1.2, sections 3.1-3.2 (signature, then length,
// type, data, CRC until IEND); PNM headers: netpbm's pnm(5).
#include "image_checks.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <vector>

namespace ra {
namespace {

constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

std::uint32_t be32(const unsigned char* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}

// Walks the chunk headers (seeking over the data) up to IEND.
std::string png_problem(std::ifstream& in, std::uint64_t size) {
  std::uint64_t at = 8;
  for (;;) {
    unsigned char h[8];
    in.seekg(std::streamoff(at));
    if (at + 8 > size || !in.read(reinterpret_cast<char*>(h), 8))
      return "byte " + std::to_string(at) + ": the PNG ends before its IEND chunk (the file is truncated)";
    const std::uint64_t len = be32(h);
    if (len > 0x7FFFFFFFu)
      return "byte " + std::to_string(at) + ": PNG chunk length " + std::to_string(len) + " out of range";
    if (std::string(reinterpret_cast<char*>(h + 4), 4) == "IEND") return "";
    at += 12 + len;  // length, type, data, CRC
  }
}

// P1..P6: width, height and (but for P1, P4) maxval, with '#' comments;
// in the ASCII kinds (P1..P3) every sample too (999 above a maxval of 255,
// or -5, were read as given).
ImageProblem pnm_problem(std::ifstream& in, std::uint64_t size) {
  in.seekg(0);
  const char kind = [&] {
    char k[2] = {};
    in.read(k, 2);
    return k[1];
  }();
  const bool ascii = kind >= '1' && kind <= '3';
  in.seekg(0);
  std::string head(ascii ? std::size_t(size) : 512, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  const int fields = kind == '1' || kind == '4' ? 2 : 3;
  const char* names[3] = {"width", "height", "maxval"};
  std::size_t i = 2;
  long line = 1;
  std::uint64_t maxval = kind == '1' || kind == '4' ? 1 : 0;
  std::uint64_t dims[3] = {0, 0, 0};
  auto skip = [&] {
    for (;;) {  // whitespace and comments
      while (i < head.size() && std::isspace(static_cast<unsigned char>(head[i]))) line += head[i++] == '\n';
      if (i < head.size() && head[i] == '#') {
        while (i < head.size() && head[i] != '\n') ++i;
        continue;
      }
      return;
    }
  };
  auto token = [&] {
    std::size_t e = i;
    while (e < head.size() && !std::isspace(static_cast<unsigned char>(head[e])) && e - i < 20) ++e;
    return head.substr(i, e - i);
  };
  for (int f = 0; f < fields; ++f) {
    skip();
    std::uint64_t v = 0;
    const std::size_t b = i;
    while (i < head.size() && std::isdigit(static_cast<unsigned char>(head[i])) && i - b < 12)
      v = v * 10 + std::uint64_t(head[i++] - '0');
    if (i == b || (i < head.size() && !std::isspace(static_cast<unsigned char>(head[i])))) {
      i = b;
      return {line, std::string("PNM header: expected the ") + names[f] + ", found '" + token() + "'"};
    }
    if (f == 2 && (v < 1 || v > 65535)) return {line, "PNM maxval " + std::to_string(v) + " (must be 1 to 65535)"};
    if (f == 2) maxval = v;
    dims[f] = v;
  }
  // Samples the header promises: a file cut short was OIIO's "unreadable or
  // unsupported image" (binary) or read with the rest black.
  const std::uint64_t channels = kind == '3' || kind == '6' ? 3 : 1;
  const std::uint64_t want = dims[0] * dims[1] * channels;
  if (!ascii) {
    const std::uint64_t row = kind == '4' ? (dims[0] + 7) / 8 : dims[0] * channels * (maxval > 255 ? 2 : 1);
    const std::uint64_t bytes = kind == '4' ? row * dims[1] : row * dims[1];
    if (size - std::min<std::uint64_t>(size, i + 1) < bytes)
      return {0, "the PNM data is " + std::to_string(size - std::min<std::uint64_t>(size, i + 1)) + " bytes, " +
                     std::to_string(bytes) + " expected for " + std::to_string(dims[0]) + "x" +
                     std::to_string(dims[1]) + " (the file is truncated)"};
    return {};
  }
  if (i < head.size()) line += head[i++] == '\n';  // the one whitespace byte after the header
  std::uint64_t samples = 0;
  for (;;) {
    skip();
    if (i >= head.size()) {
      if (samples < want)
        return {line, "the PNM data ends after " + std::to_string(samples) + " of the " + std::to_string(want) +
                          " samples " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + " takes"};
      return {};
    }
    ++samples;
    if (kind == '1') {  // bits need no separator: "0101"
      if (head[i] != '0' && head[i] != '1') return {line, "PBM bit '" + token() + "' (must be 0 or 1)"};
      ++i;
      continue;
    }
    const std::size_t b = i;
    std::uint64_t v = 0;
    while (i < head.size() && std::isdigit(static_cast<unsigned char>(head[i])) && i - b < 12)
      v = v * 10 + std::uint64_t(head[i++] - '0');
    if (i == b || (i < head.size() && !std::isspace(static_cast<unsigned char>(head[i])) && head[i] != '#')) {
      i = b;
      return {line, "PNM sample '" + token() + "' is not a number from 0 to the maxval " + std::to_string(maxval)};
    }
    if (v > maxval) return {line, "PNM sample " + std::to_string(v) + " above the maxval " + std::to_string(maxval)};
  }
}

// PF / Pf (PFM): width, height and a scale whose sign is the byte order; 0
// (or not a number) is no scale.
ImageProblem pfm_problem(std::ifstream& in) {
  in.seekg(0);
  std::string head(256, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  std::istringstream s(head.substr(2));
  long w = 0, h = 0;
  std::string scale;
  if (!(s >> w >> h >> scale)) return {};
  char* end = nullptr;
  const double v = std::strtod(scale.c_str(), &end);
  if (end != scale.c_str() + scale.size() || !(std::fabs(v) > 0) || !std::isfinite(v))
    return {3, "PFM scale '" + scale + "' (must be a non-zero number: its sign gives the byte order)"};
  return {};
}

std::uint16_t le16(const unsigned char* p) { return std::uint16_t(p[0] | p[1] << 8); }

// GIF: the logical screen's size, and the first image's (OIIO's reader
// decodes the first frame when it opens the file).
ImageProblem gif_size(std::ifstream& in, std::uint64_t size) {
  in.seekg(0);
  std::vector<unsigned char> b(std::size_t(std::min<std::uint64_t>(size, 1 << 16)));
  in.read(reinterpret_cast<char*>(b.data()), std::streamsize(b.size()));
  b.resize(std::size_t(in.gcount()));
  if (b.size() < 13) return {};
  ImageProblem p;
  p.width = le16(&b[6]);
  p.height = le16(&b[8]);
  std::size_t i = 13 + ((b[10] & 0x80) ? 3u << ((b[10] & 7) + 1) : 0);
  while (i < b.size()) {
    if (b[i] == 0x21 && i + 2 < b.size()) {  // an extension: label, sub-blocks up to a 0
      i += 2;
      while (i < b.size() && b[i] != 0) i += std::size_t(b[i]) + 1;
      ++i;
    } else if (b[i] == 0x2C && i + 9 < b.size()) {  // the first image descriptor
      p.width = std::max<std::uint64_t>(p.width, le16(&b[i + 5]));
      p.height = std::max<std::uint64_t>(p.height, le16(&b[i + 7]));
      break;
    } else {
      break;
    }
  }
  return p;
}

// Text: no NUL and no control bytes but tab, line ends and form feed in the
// first 512 bytes (an OBJ, an MTL, a JSON scene named as an image).
bool looks_like_text(const std::string& head) {
  if (head.empty()) return false;
  for (unsigned char c : head)
    if (c == 0 || (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f')) return false;
  return true;
}

std::string head_of(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(512, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  return head;
}

}  // namespace

ImageProblem image_container_problem(const std::filesystem::path& path) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return {};
  if (size == 0) return {0, "not an image (an empty file)"};
  std::ifstream in(path, std::ios::binary);
  unsigned char sig[8] = {};
  in.read(reinterpret_cast<char*>(sig), 8);
  const std::size_t got = std::size_t(in.gcount());
  in.clear();
  if (got == 8 && std::equal(sig, sig + 8, kPngSignature)) return {0, png_problem(in, size)};
  if (got >= 3 && sig[0] == 'P' && sig[1] >= '1' && sig[1] <= '6' && std::isspace(sig[2])) return pnm_problem(in, size);
  if (got >= 3 && sig[0] == 'P' && (sig[1] == 'F' || sig[1] == 'f') && std::isspace(sig[2])) return pfm_problem(in);
  if (got >= 6 && (std::string(reinterpret_cast<char*>(sig), 6) == "GIF87a" ||
                   std::string(reinterpret_cast<char*>(sig), 6) == "GIF89a"))
    return gif_size(in, size);
  return {};
}

std::string image_open_problem(const std::filesystem::path& path, const std::string& oiio_err) {
  const std::string head = head_of(path);
  if (looks_like_text(head)) return "not an image (a text file)";
  if (head.rfind("GIF8", 0) == 0 && oiio_err.find("could not find a format reader") != std::string::npos)
    return "not a readable GIF (no image in it, or a corrupt header)";
  if (oiio_err.find("could not find a format reader") != std::string::npos)
    return "not an image (no image format recognises it)";
  return oiio_err;
}

}  // namespace ra
