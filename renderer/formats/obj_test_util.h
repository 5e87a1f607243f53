// Test helpers: write small OBJ/MTL texts into a fresh temp directory.
#pragma once
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "../errors.h"
#include "mesh.h"

namespace ra::test {

struct TempDir {
  std::filesystem::path dir;
  TempDir() {
    static std::atomic<int> n{0};
    dir = std::filesystem::temp_directory_path() /
          ("rayaudit-obj-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const auto p = dir / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

// Loads `text` written as DIR/t.obj (other files may be written first).
inline Mesh load_text(const TempDir& d, const std::string& text, const ObjOptions& opt = {}) {
  return load_obj(d.write("t.obj", text), opt);
}

// The InputError message of loading `text` as DIR/t.obj, with DIR/ removed
// (so tests compare "t.obj:LINE: ..."); "" if it loads.
inline std::string load_error(const std::string& text, const ObjOptions& opt = {}) {
  TempDir d;
  try {
    load_text(d, text, opt);
  } catch (const InputError& e) {
    std::string s = e.what();
    const std::string prefix = (d.dir / "").string();
    if (s.rfind(prefix, 0) == 0) s = s.substr(prefix.size());
    return s;
  }
  return "";
}

}  // namespace ra::test
