// Which files this run reads and which it will write, compared by identity
// (st_dev, st_ino): an output that is also an input, or two outputs on one path, is refused.
#pragma once
#include <filesystem>

namespace ra {

// Records `path` (an existing file) as read by this run. Throws InputError
// "OUTPUT: is also an input (PATH): ..." if an output declared earlier is
// the same file, so the command stops before its work, whichever of the
// two was named first.
void note_input(const std::filesystem::path& path);

// check_output_path(path), then: refused if it is the same file as an input
// noted so far, or the same path (after symlinks) as another declared output.
// OutputBatch::add and commands with a single output call it before the work.
void declare_output(const std::filesystem::path& path);

// Ends a declaration (an OutputBatch going out of scope).
void undeclare_output(const std::filesystem::path& path);

}  // namespace ra
