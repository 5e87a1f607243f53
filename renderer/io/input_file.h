// What is wrong with an input path, said before it is opened: a directory,
// a FIFO (which would block forever), a device or a symlink loop is named.
#pragma once
#include <filesystem>
#include <string>

namespace ra {

// Empty if `path` is a regular file (after symlinks); otherwise what it is
// instead: "no such file", "is a directory, not a file", "is a FIFO, not a
// file", "is a device, not a file", or the system's reason (e.g. "Too many
// levels of symbolic links").
std::string input_file_problem(const std::filesystem::path& path);

// Throws InputError "PATH: problem" when input_file_problem() is not empty;
// otherwise notes the file as an input (file_identity.h).
void check_input_file(const std::filesystem::path& path);

}  // namespace ra
