#include "atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <climits>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <system_error>

#include "../errors.h"
#include "file_identity.h"

namespace ra {

namespace {
// Control bytes (a NUL, CR or newline quoted from a bad input) and bytes
// that are not UTF-8 as \xNN: the message stays one printable line
// whatever the file held.
std::string printable(const std::string& s) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::size_t len = b < 0x80                 ? 1
                      : b >= 0xc2 && b <= 0xdf ? 2
                      : b >= 0xe0 && b <= 0xef ? 3
                      : b >= 0xf0 && b <= 0xf4 ? 4
                                               : 0;
    for (std::size_t k = 1; k < len; ++k)
      if (i + k >= s.size() || (static_cast<unsigned char>(s[i + k]) & 0xc0) != 0x80) len = 0;
    if (len == 1 && (b < 0x20 || b == 0x7f)) len = 0;
    if (len == 0) {
      out += "\\x";
      out += hex[b >> 4];
      out += hex[b & 15];
      ++i;
      continue;
    }
    out.append(s, i, len);
    i += len;
  }
  return out;
}
}  // namespace

namespace {
// A message quoting an input stays readable whatever the input held: text
// beyond `max` bytes is cut from the middle, saying how much (a 100 MB mesh
// path in a scene gave a 100 MB stderr line).
std::string shortened(const std::string& s, std::size_t max) {
  if (s.size() <= max) return s;
  const std::size_t head = max * 3 / 4, tail = max / 4;
  return s.substr(0, head) + "...(" + std::to_string(s.size() - head - tail) + " bytes cut)..." +
         s.substr(s.size() - tail);
}
}  // namespace

std::string located(const std::string& file, long line, const std::string& message) {
  const std::string f = printable(shortened(file, 1024)), m = printable(shortened(message, 2048));
  if (line > 0) return f + ":" + std::to_string(line) + ": " + m;
  return f + ": " + m;
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write) {
  namespace fs = std::filesystem;
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  check_output_path(path);
  std::random_device rd;
  // A name near NAME_MAX (255) would not fit with the prefix: keep only the
  // extension then (the image writers need it).
  std::string tmp_name = ".tmp-" + std::to_string(rd()) + "-" + path.filename().string();
  if (tmp_name.size() > 200) tmp_name = ".tmp-" + std::to_string(rd()) + path.extension().string().substr(0, 16);
  const fs::path tmp = dir / tmp_name;
  try {
    write(tmp);
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
  if (OutputBatch::stage(path, tmp)) return;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(located(path.string(), 0, "cannot write: " + ec.message()));
  }
}

void check_output_name(const std::filesystem::path& path) {
  const std::size_t n = path.filename().string().size();
  if (n > NAME_MAX)
    throw InputError(
        located(path.string(), 0,
                "file name too long (" + std::to_string(n) + " bytes; at most " + std::to_string(NAME_MAX) + ")"));
}

void check_output_path(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  check_output_name(path);
  if (!fs::is_directory(dir, ec)) {
    // A symlink loop or an unreadable parent is not "does not exist".
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
      throw InputError(located(path.string(), 0, "output directory: " + ec.message()));
    // A file where the directory should be (`-o notes.txt/x.png`) is not "does not exist".
    if (fs::exists(dir, ec))
      throw InputError(located(path.string(), 0, "output directory " + dir.string() + " is not a directory"));
    throw InputError(located(path.string(), 0, "output directory does not exist"));
  }
  // An existing output that is not a regular file is refused: the renamed
  // temporary would replace it (run as root, -o /dev/full turned the device
  // into a file).
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) return;
  if (ec) throw InputError(located(path.string(), 0, "cannot write: " + ec.message()));
  switch (st.type()) {
    case fs::file_type::regular:
      return;
    case fs::file_type::directory:
      throw InputError(located(path.string(), 0, "is a directory, not a file"));
    case fs::file_type::fifo:
      throw InputError(located(path.string(), 0, "is a FIFO, not a file: not replaced"));
    case fs::file_type::block:
    case fs::file_type::character:
      throw InputError(located(path.string(), 0, "is a device, not a file: not replaced"));
    default:
      throw InputError(located(path.string(), 0, "is not a regular file: not replaced"));
  }
}

namespace {
thread_local OutputBatch* g_batch = nullptr;
std::filesystem::path key(const std::filesystem::path& p) { return std::filesystem::absolute(p).lexically_normal(); }
}  // namespace

OutputBatch::OutputBatch(const std::vector<std::filesystem::path>& outputs) : outer_(g_batch) {
  for (const auto& p : outputs)
    if (!p.empty()) add(p);
  g_batch = this;
}

void OutputBatch::add(const std::filesystem::path& output) {
  declare_output(output);  // not an input, not another output's path
  outputs_.push_back(key(output));
  declared_.push_back(output);
}

void OutputBatch::add_replacement(const std::filesystem::path& output) {
  check_output_path(output);
  outputs_.push_back(key(output));
}

bool OutputBatch::stage(const std::filesystem::path& path, const std::filesystem::path& tmp) {
  OutputBatch* b = g_batch;
  if (!b) return false;
  const auto k = key(path);
  for (const auto& o : b->outputs_)
    if (o == k) {
      b->staged_.emplace_back(tmp, k);  // renamed in order: a file written twice ends as the later one
      return true;
    }
  return false;
}

void OutputBatch::commit() {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (std::size_t i = 0; i < staged_.size(); ++i) {
    fs::rename(staged_[i].first, staged_[i].second, ec);
    if (ec) {
      const std::string what = located(staged_[i].second.string(), 0, "cannot write: " + ec.message());
      for (std::size_t j = i; j < staged_.size(); ++j) fs::remove(staged_[j].first, ec);
      staged_.clear();
      throw InputError(what);
    }
  }
  staged_.clear();
}

OutputBatch::~OutputBatch() {
  std::error_code ec;
  for (const auto& s : staged_) std::filesystem::remove(s.first, ec);
  for (const auto& d : declared_) undeclare_output(d);
  g_batch = outer_;
}

void write_bytes_checked(const std::filesystem::path& file, const void* data, std::size_t size,
                         const std::string& shown) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw InputError(located(shown, 0, std::string("cannot write: ") + std::strerror(errno)));
  const char* p = static_cast<const char*>(data);
  std::size_t left = size;
  int err = 0;
  while (left > 0 && !err) {
    const ssize_t w = ::write(fd, p, left);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0)
      err = w < 0 ? errno : ENOSPC;  // write() of 0 bytes: no room
    else
      p += w, left -= std::size_t(w);
  }
  // Some file systems report a full disk only when the data is flushed.
  if (!err && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) err = errno;
  if (::close(fd) != 0 && !err) err = errno;
  if (err) throw InputError(located(shown, 0, std::string("cannot write: ") + std::strerror(err)));
}

void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    write_bytes_checked(tmp, text.data(), text.size(), path.string());
  });
}

}  // namespace ra
