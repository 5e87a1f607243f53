#include "atomic_file.h"

#include <fstream>
#include <random>
#include <system_error>

#include "errors.h"

namespace ra {

std::string located(const std::string& file, long line, const std::string& message) {
  if (line > 0) return file + ":" + std::to_string(line) + ": " + message;
  return file + ": " + message;
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write) {
  namespace fs = std::filesystem;
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(located(path.string(), 0, "output directory does not exist"));
  std::random_device rd;
  const fs::path tmp = dir / (".tmp-" + std::to_string(rd()) + "-" + path.filename().string());
  try {
    write(tmp);
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(located(path.string(), 0, "cannot write: " + ec.message()));
  }
}

void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    f.close();
    if (!f) throw InputError(located(path.string(), 0, "cannot write"));
  });
}

}  // namespace ra
