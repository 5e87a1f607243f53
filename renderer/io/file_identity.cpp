// Inputs and outputs of one run, by file identity
// (`render s.json -o tex.png` replaced the scene's texture; `--json X --csv X` lost one).
#include "file_identity.h"

#include <sys/stat.h>

#include <algorithm>
#include <mutex>
#include <string>
#include <system_error>
#include <vector>

#include "atomic_file.h"
#include "../errors.h"

namespace ra {
namespace {

namespace fs = std::filesystem;

struct Id {
  dev_t dev = 0;
  ino_t ino = 0;
  bool operator==(const Id& o) const { return dev == o.dev && ino == o.ino; }
};

// stat() follows symlinks: a link to an input is that input.
bool identity(const fs::path& p, Id& out) {
  struct stat st {};
  if (::stat(p.c_str(), &st) != 0) return false;
  out = {st.st_dev, st.st_ino};
  return true;
}

// An output that does not exist yet has no identity: two of them are the
// same when their paths are, after the symlinks of the existing part.
fs::path path_key(const fs::path& p) {
  std::error_code ec;
  const fs::path abs = fs::absolute(p, ec).lexically_normal();
  fs::path k = fs::weakly_canonical(abs, ec);  // absolute first: "x" and "./x" meet
  return ec ? abs : k;
}

struct Input {
  Id id;
  fs::path path;
};

struct Registry {
  std::mutex mu;
  std::vector<Input> inputs;
  std::vector<fs::path> outputs;  // as given (their identity may change: created later)
};

Registry& registry() {
  static Registry r;
  return r;
}

[[noreturn]] void refuse_input_as_output(const fs::path& out, const fs::path& in) {
  throw InputError(
      located(out.string(), 0,
              "is also an input of this command (" + in.string() + "): it would be replaced; choose another output"));
}

}  // namespace

void note_input(const fs::path& path) {
  Id id;
  if (!identity(path, id)) return;  // the reader reports a missing file itself
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mu);
  for (const auto& in : r.inputs)
    if (in.id == id) return;
  for (const auto& out : r.outputs) {
    Id oid;
    if (identity(out, oid) && oid == id) refuse_input_as_output(out, path);
  }
  r.inputs.push_back({id, path});
}

void declare_output(const fs::path& path) {
  check_output_path(path);
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mu);
  Id id;
  const bool exists = identity(path, id);
  if (exists)
    for (const auto& in : r.inputs)
      if (in.id == id) refuse_input_as_output(path, in.path);
  const fs::path key = path_key(path);
  for (const auto& out : r.outputs) {
    Id oid;
    if (path_key(out) == key || (exists && identity(out, oid) && oid == id))
      throw InputError(located(path.string(), 0,
                               "is named as two outputs of this command" +
                                   (out.string() == path.string() ? std::string() : " (also as " + out.string() + ")") +
                                   ": one would be lost"));
  }
  r.outputs.push_back(path);
}

void undeclare_output(const fs::path& path) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mu);
  auto it = std::find(r.outputs.begin(), r.outputs.end(), path);
  if (it != r.outputs.end()) r.outputs.erase(it);
}

}  // namespace ra
