// Image container checks before OpenImageIO (see image_checks.h). PNG chunk
// layout: PNG specification 1.2, sections 3.1-3.2 (signature, then length,
// type, data, CRC until IEND); PNM headers: netpbm's pnm(5).
#include "image_checks.h"

#include <cctype>
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
    if (len > 0x7FFFFFFFu) return "byte " + std::to_string(at) + ": PNG chunk length " + std::to_string(len) + " out of range";
    if (std::string(reinterpret_cast<char*>(h + 4), 4) == "IEND") return "";
    at += 12 + len;  // length, type, data, CRC
  }
}

// P1..P6: width, height and (but for P1, P4) maxval, with '#' comments.
ImageProblem pnm_problem(std::ifstream& in) {
  in.seekg(0);
  std::string head(512, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  const char kind = head[1];
  const int fields = kind == '1' || kind == '4' ? 2 : 3;
  std::size_t i = 2;
  long line = 1;
  for (int f = 0; f < fields; ++f) {
    for (;;) {  // whitespace and comments
      while (i < head.size() && std::isspace(static_cast<unsigned char>(head[i]))) line += head[i++] == '\n';
      if (i < head.size() && head[i] == '#') {
        while (i < head.size() && head[i] != '\n') ++i;
        continue;
      }
      break;
    }
    std::uint64_t v = 0;
    const std::size_t b = i;
    while (i < head.size() && std::isdigit(static_cast<unsigned char>(head[i])) && i - b < 12) v = v * 10 + std::uint64_t(head[i++] - '0');
    if (i == b) return {};  // not a number: OIIO's reader says what is wrong
    if (f == 2 && (v < 1 || v > 65535)) return {line, "PNM maxval " + std::to_string(v) + " (must be 1 to 65535)"};
  }
  return {};
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
  if (got >= 3 && sig[0] == 'P' && sig[1] >= '1' && sig[1] <= '6' && std::isspace(sig[2])) return pnm_problem(in);
  return {};
}

std::string image_open_problem(const std::filesystem::path& path, const std::string& oiio_err) {
  if (looks_like_text(head_of(path))) return "not an image (a text file)";
  if (oiio_err.find("could not find a format reader") != std::string::npos)
    return "not an image (no image format recognises it)";
  return oiio_err;
}

}  // namespace ra
