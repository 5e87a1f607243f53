// Outputs are written to a temporary file beside the target and renamed into
// place, so a failed or interrupted run never leaves a partial output.
#pragma once
#include <filesystem>
#include <functional>
#include <string>

namespace ra {

// Calls write(tmp_path) and renames tmp_path to `path` if it returns without
// throwing; removes the temporary file otherwise. The temporary keeps the
// target's extension, because image writers choose the format from it.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

// Convenience: atomically writes a string.
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

}  // namespace ra
