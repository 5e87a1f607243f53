// Outputs are written to a temporary file beside the target and renamed into
// place, so a failed or interrupted run never leaves a partial output.
#pragma once
#include <filesystem>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace ra {

// Calls write(tmp_path) and renames tmp_path to `path` if it returns without
// throwing; removes the temporary file otherwise. The temporary keeps the
// target's extension, because image writers choose the format from it.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

// Convenience: atomically writes a string.
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

// Writes `size` bytes to `file` (created or truncated), checking every
// write(), fsync() and close(): a full disk is an InputError naming `shown`
// (the final output name), never a truncated file reported as written.
void write_bytes_checked(const std::filesystem::path& file, const void* data, std::size_t size,
                         const std::string& shown);

// Throws InputError `PATH: ...` unless `path` can be an output: its directory
// exists and it is not itself a directory. Commands call it for every output
// before doing any work, so a bad path costs nothing.
void check_output_path(const std::filesystem::path& path);

// Throws InputError `PATH: file name too long` when the last component is
// longer than the file system takes (NAME_MAX): said before the work, not as
// "cannot write: Success" after it. check_output_path() calls it.
void check_output_name(const std::filesystem::path& path);

// A command with several outputs writes all of them or none. While a batch is
// alive, write_atomically() to one of its outputs leaves the finished
// temporary file in place; commit() renames them all; a batch destroyed
// without commit() (an error was thrown) removes them. Writes to paths the
// batch does not list (e.g. POV-Ray's scratch files) are not deferred.
class OutputBatch {
 public:
  // Checks each non-empty path with declare_output() (file_identity.h): an
  // input or a path given twice is refused.
  explicit OutputBatch(const std::vector<std::filesystem::path>& outputs);
  ~OutputBatch();
  OutputBatch(const OutputBatch&) = delete;
  OutputBatch& operator=(const OutputBatch&) = delete;
  // Adds an output known only later (e.g. a texture copied beside a .pov).
  void add(const std::filesystem::path& output);
  // Adds an output that rewrites one of the command's inputs on purpose
  // (golden bless: the golden it compared against): only the path is checked.
  void add_replacement(const std::filesystem::path& output);
  void commit();

  // Used by write_atomically: true if `path` is this batch's (the rename waits).
  static bool stage(const std::filesystem::path& path, const std::filesystem::path& tmp);

 private:
  std::vector<std::filesystem::path> outputs_;                                   // absolute, normalised
  std::vector<std::filesystem::path> declared_;                                  // as given to declare_output()
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_;  // tmp, final
  OutputBatch* outer_;
};

}  // namespace ra
