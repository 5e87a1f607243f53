#include "golden_project.h"

#include <system_error>

namespace ra {

namespace fs = std::filesystem;

std::optional<fs::path> find_golden_project(const fs::path& start) {
  std::error_code ec;
  const fs::path from = fs::absolute(start, ec).lexically_normal();
  for (const char* marker : {kGoldenManifest, "scenes"})
    for (fs::path d = from;; d = d.parent_path()) {
      const fs::path m = d / marker;
      if (marker == std::string("scenes") ? fs::is_directory(m, ec) : fs::is_regular_file(m, ec)) return d;
      if (d == d.parent_path()) break;
    }
  return std::nullopt;
}

std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

fs::path real_path(const fs::path& p) {
  std::error_code ec;
  fs::path rest = fs::absolute(p, ec).lexically_normal();
  for (int hops = 0; hops <= 40; ++hops) {
    fs::path done = rest.root_path();
    const fs::path rel = rest.relative_path();  // iterated: not a temporary
    bool relinked = false;
    for (auto it = rel.begin(); it != rel.end(); ++it) {
      const fs::path next = done / *it;
      if (fs::is_symlink(fs::symlink_status(next, ec))) {
        const fs::path target = fs::read_symlink(next, ec);
        fs::path tail;
        for (auto jt = std::next(it); jt != rel.end(); ++jt) tail /= *jt;
        rest = (target.is_absolute() ? target : done / target).lexically_normal();
        if (!tail.empty()) rest = (rest / tail).lexically_normal();  // "a" / "" would be "a/"
        if (rest.has_relative_path() && rest.filename().empty()) rest = rest.parent_path();
        relinked = true;
        break;
      }
      done = next;
    }
    if (!relinked) return done.lexically_normal();
  }
  return rest;  // a loop: as far as it resolved
}

std::optional<fs::path> golden_folder_of(const fs::path& output, const fs::path& root) {
  std::error_code ec;
  const fs::path own = real_path(root / "golden");
  for (fs::path d = real_path(output);; d = d.parent_path()) {
    if (d == own || (d.filename() == "golden" && fs::is_regular_file(d / "manifest.json", ec))) return d;
    if (d == d.parent_path()) break;
  }
  return std::nullopt;
}

}  // namespace ra
