// Where a golden check finds its project, and where its outputs may not go.
//
// The project (--root's default): the nearest folder, from the current
// directory up, that holds golden/manifest.json; if none does, the nearest
// that holds a scenes/ folder (a project whose first golden is not blessed
// yet). Every hint a check prints names it with --root, so a command pasted
// from another directory acts on the same project.
//
// Diff images never go into a golden folder: a --diff-dir pointing at
// another checkout's golden/ overwrote that checkout's golden image. A
// golden folder is ROOT/golden of the project checked, or any folder named
// golden that holds a manifest.json; paths are compared after every symlink
// is resolved (dangling ones too: a diff folder not made yet may be a link).
#pragma once
#include <filesystem>
#include <optional>
#include <string>

namespace ra {

inline constexpr const char* kGoldenManifest = "golden/manifest.json";

// The project holding `start` by the rule above, or nothing.
std::optional<std::filesystem::path> find_golden_project(const std::filesystem::path& start);

// `s` quoted for a POSIX shell: 'it'\''s'.
std::string shell_quoted(const std::string& s);

// `p` absolute with every symlink in it resolved, also in the part that does
// not exist yet (up to 40 links, as the kernel allows).
std::filesystem::path real_path(const std::filesystem::path& p);

// The golden folder `output` (a file or folder to be written) would be in,
// by the rule above (`root` is the project checked); nothing when none.
std::optional<std::filesystem::path> golden_folder_of(const std::filesystem::path& output,
                                                      const std::filesystem::path& root);

}  // namespace ra
