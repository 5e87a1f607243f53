// Golden images: our own renders of every scene in scenes/, small, stored
// in golden/ as 8-bit PNGs with golden/manifest.json naming, for each, the
// scene, the size and render settings, and a hash of every input file (the
// scene, its meshes and their MTL files, textures). A check renders the
// scene again and compares with OpenImageIO: any pixel that differs fails,
// and a diff image is written. Only `bless` rewrites a golden, and only when
// asked; CI never blesses.
#pragma once
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "image_compare.h"
#include <rayaudit/io/atomic_file.h>
#include <rayaudit/scene/scene.h>

namespace ra {

// The default largest golden dimension: scenes are rendered at most this
// wide or tall (keeping the aspect ratio as well as whole pixels allow).
// Small, so that a golden is a few kB in git and checks in well under a
// second; a manifest entry's "max_side" sets another for its scene (its
// scene's long side or more: the scene's own size, which an image from
// another renderer must have to be judged against it pixel for pixel).
inline constexpr int kGoldenMaxSize = 160;

// What a golden check lets pass: at most max_pixels pixels differ, none by
// more than max_levels levels of the golden's bit depth. The default is
// identical (a rerun of our own renderer must give the same bytes); a
// manifest entry's "tolerance" sets another, e.g. for a user's renderer.
struct GoldenTolerance {
  int max_levels = 0;
  long max_pixels = 0;
  bool identical() const { return max_levels == 0 || max_pixels == 0; }
};

struct GoldenEntry {
  std::string name;   // the scene's stem: scenes/NAME.json
  std::string scene;  // relative to the root: "scenes/NAME.json"
  std::string image;  // relative to the root: "golden/NAME.png"
  int width = 0, height = 0, bits = 8;
  int max_side = kGoldenMaxSize;  // bless renders the scene at most this on its long side
  GoldenTolerance tolerance;
  nlohmann::json settings;                    // render options
  std::string inputs_hash;                    // over all inputs below
  std::map<std::string, std::string> inputs;  // relative path -> content hash
};

// Hashes (FNV-1a 64, hex) of a scene's input files, keyed by path relative to
// `root` (absolute when outside it): the scene file, each mesh's OBJ and its
// mtllib files, every texture and bump image.
std::map<std::string, std::string> scene_inputs(const Scene& scene, const std::filesystem::path& root);
std::string combined_hash(const std::map<std::string, std::string>& inputs);

// The "${cache}/..." files a scene file names that do not exist (the teapot
// ci/main.sh generates, the corpus ci/fetch-corpus.sh fetches): a test of
// such a scene is skipped, saying so, rather than failed.
std::vector<std::filesystem::path> missing_cache_inputs(const std::filesystem::path& scene_file);

class GoldenSet {
 public:
  // Reads root/golden/manifest.json (an empty set when there is none).
  explicit GoldenSet(std::filesystem::path root);

  // Scene names: scenes/*.json stems, and any entries whose scene is gone.
  std::vector<std::string> all_names() const;
  const std::filesystem::path& root() const { return root_; }
  // The files check(name) reads before any other: its scene and golden image.
  std::vector<std::filesystem::path> inputs_of(const std::string& name) const;

  // One scene's verdict, shaped for every writer (text, --json, JUnit):
  // `detail` holds compare --json's fields for this scene (see check()).
  struct Result {
    bool pass = false;
    std::string message;    // what was found, with the diff image's path on failure
    std::string hint;       // a command to paste (with --root), or empty
    nlohmann::json detail;  // the comparison, its verdict and files
  };
  // Renders `name` and compares with its golden; on failure writes
  // diff_dir/NAME.diff.png (false colour) and diff_dir/NAME.png (ours).
  // The images check() writes for `name` on failure, in this order.
  static std::vector<std::filesystem::path> diff_outputs(const std::string& name,
                                                         const std::filesystem::path& diff_dir);
  // before_write(path) is called before each diff image is written (after
  // its directory is made): a command declares outputs in new folders then.
  //
  // With `theirs` (an image from another renderer, read by
  // read_their_image against the golden), that image is judged instead of
  // a render of ours, and only NAME.diff.png is written.
  //
  // Coordinates in the message and detail are the scene's pixels (the
  // golden may be smaller); detail's differences also give golden_x/golden_y.
  Result check(const std::string& name, const std::filesystem::path& diff_dir,
               const std::function<void(const std::filesystem::path&)>& before_write = {},
               const std::filesystem::path* theirs = nullptr) const;

  // The golden `name` as an image to match (size, bits), for read_their_image;
  // throws InputError when there is none.
  struct Reference {
    int width = 0, height = 0, bits = 8;
    std::string image;  // relative to the root
  };
  Reference reference_of(const std::string& name) const;

  // The golden image files the manifest lists (absolute), each a file a
  // check must never write.
  std::vector<std::filesystem::path> images() const;

  // `rayaudit golden bless NAME --root 'ROOT'`: a hint that acts on this
  // project wherever it is pasted.
  std::string bless_command(const std::string& name) const;

  // Renders `name` and records it; returns a line saying what changed.
  // save() writes the manifest.
  // With `batch`, the image and (save) the manifest are staged in it: a
  // later failure leaves golden/ as it was (commit() renames them).
  std::string bless(const std::string& name, OutputBatch* batch = nullptr);
  void save(OutputBatch* batch = nullptr) const;

 private:
  std::filesystem::path root_;
  std::map<std::string, GoldenEntry> entries_;
  bool removed_ = false;
  std::vector<std::filesystem::path> to_remove_;  // goldens of removed scenes: deleted by save()
};

}  // namespace ra
