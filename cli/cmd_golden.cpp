// `rayaudit golden check|bless [SCENE...]`: golden images of scenes/*.json
// (validation/images/golden.h). check renders and compares (exit 1 on any
// difference, writing a diff image); bless rewrites goldens, only when asked.
// `golden check --image THEIRS.png SCENE` judges another renderer's image
// of the scene against its golden instead of a render of ours. The project
// is --root, or the one holding the current directory
// (validation/images/golden_project.h).
#include <algorithm>
#include <iostream>
#include <set>
#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/file_identity.h"
#include "command.h"
#include "errors.h"
#include "baseline/junit.h"
#include "images/golden.h"
#include "images/golden_project.h"
#include "images/their_image.h"

namespace {

struct Args {
  std::vector<std::string> scenes;
  std::string root;  // empty: found from the current directory
  std::string diff_dir, json, image, junit;
  bool skip_unavailable = false;
};

// A scene's name is its path under scenes/ without ".json":
// "sphere-on-plane", "scenes/sphere-on-plane.json" -> "sphere-on-plane";
// "corpus/ladder-10-box", "scenes/corpus/ladder-10-box.json" -> "corpus/ladder-10-box".
// Any other path (e.g. absolute) names the scene by its stem, as before.
std::vector<std::string> names_of(const std::vector<std::string>& given, const ra::GoldenSet& set) {
  if (given.empty()) return set.all_names();
  std::vector<std::string> out;
  for (const auto& g : given) {
    std::filesystem::path p = std::filesystem::path(g).lexically_normal();
    if (p.extension() == ".json") p.replace_extension();
    std::string rel = p.generic_string();
    if (rel.rfind("scenes/", 0) == 0) rel = rel.substr(7);
    const bool plain = !p.is_absolute() && rel.find("..") == std::string::npos;
    if (!plain) {
      // A path elsewhere was checked as ROOT/scenes/<its stem>.json, and that
      // file named in the error: a path must be under scenes/.
      std::error_code ec;
      const std::filesystem::path scenes = std::filesystem::weakly_canonical(set.root() / "scenes", ec);
      const std::filesystem::path under = std::filesystem::weakly_canonical(p, ec).lexically_relative(scenes);
      if (under.empty() || *under.begin() == "..")
        throw ra::InputError(ra::located(
            g, 0,
            "not a scene under " + (set.root() / "scenes").string() + " (golden names scenes by their path there)"));
      rel = under.generic_string();
    }
    // A scene named twice is checked once (its diff images would be two
    // outputs on one path).
    if (std::find(out.begin(), out.end(), rel) == out.end()) out.push_back(rel);
  }
  return out;
}

// An output directory that may not exist yet (check creates it): the
// nearest existing ancestor must be a directory.
void check_creatable_dir(const std::filesystem::path& dir, const std::string& flag) {
  std::error_code ec;
  for (std::filesystem::path p = std::filesystem::absolute(dir, ec); !p.empty(); p = p.parent_path()) {
    const auto st = std::filesystem::status(p, ec);
    if (st.type() == std::filesystem::file_type::not_found) {
      if (p == p.parent_path()) break;
      continue;
    }
    if (st.type() != std::filesystem::file_type::directory)
      throw ra::InputError(ra::located(p.string(), 0, "is not a directory (" + flag + " " + dir.string() + ")"));
    return;
  }
}

// How --root is found when not given: said by --help and by the error.
constexpr const char* kRootRule =
    "the nearest folder, from the current directory up, holding golden/manifest.json, or failing that one holding "
    "scenes/";

// --root must be a checkout: scenes/ beside golden/ (bless may create golden/).
// Not given, it is the project holding the current directory (kRootRule),
// never this program's own checkout (pasting a hint blessed there).
void check_root(Args& a) {
  if (a.root.empty()) {
    std::error_code ec;
    const auto cwd = std::filesystem::current_path(ec);
    const auto found = ec ? std::nullopt : ra::find_golden_project(cwd);
    if (!found)
      throw ra::InputError("rayaudit golden: no project here: no folder from " + cwd.string() +
                           " up holds golden/manifest.json or scenes/ (give --root)");
    a.root = found->string();
  }
  if (!std::filesystem::is_directory(std::filesystem::path(a.root) / "scenes"))
    throw ra::InputError(a.root + ": not a rayaudit repository (no scenes/ directory)");
}

// A diff folder in a golden folder, or a diff image on a golden, is refused
// before any work: a --diff-dir naming another checkout's golden/ replaced
// its golden image. Real paths, so a symlink to either is refused too.
void check_diff_dir(const std::filesystem::path& diff_dir, const std::vector<std::string>& names,
                    const ra::GoldenSet& set) {
  if (const auto g = ra::golden_folder_of(diff_dir, set.root()))
    throw ra::InputError(ra::located(diff_dir.string(), 0,
                                     "--diff-dir is in the golden folder " + g->string() +
                                         " (its images would be overwritten); give a folder "
                                         "outside every golden/"));
  std::set<std::filesystem::path> goldens;
  for (const auto& img : set.images()) goldens.insert(ra::real_path(img));
  for (const auto& n : names)
    for (const auto& out : ra::GoldenSet::diff_outputs(n, diff_dir)) {
      if (const auto g = ra::golden_folder_of(out, set.root()))
        throw ra::InputError(ra::located(
            out.string(), 0,
            "would be written in the golden folder " + g->string() + " (--diff-dir " + diff_dir.string() + ")"));
      if (goldens.count(ra::real_path(out)))
        throw ra::InputError(ra::located(
            out.string(), 0, "is a golden image (--diff-dir " + diff_dir.string() + " would overwrite it)"));
    }
}

void check(Args a) {
  check_root(a);
  // Folders the diff images would need that are not there yet: removed
  // again if still empty when the command ends (a check that exits 2 on a
  // later scene left its new, empty diff folder behind). Declared before
  // the batch, so that it runs after the batch has removed its temporaries.
  struct RemoveMadeEmpty {
    std::vector<std::filesystem::path> dirs;  // parents before children
    ~RemoveMadeEmpty() {
      for (auto it = dirs.rbegin(); it != dirs.rend(); ++it) {
        std::error_code ec;
        if (std::filesystem::is_empty(*it, ec) && !ec) std::filesystem::remove(*it, ec);
      }
    }
  } made;
  ra::OutputBatch outputs({a.json, a.junit});
  const ra::GoldenSet set(a.root);
  ra::junit::Suite junit{"rayaudit golden check", {}};  // --junit: one test case per scene
  const std::filesystem::path diff_dir = a.diff_dir.empty() ? std::filesystem::temp_directory_path() / "rayaudit-golden"
                                                            : std::filesystem::path(a.diff_dir);
  int failed = 0, skipped = 0;
  nlohmann::json rows = nlohmann::json::array();  // for --json (the report's golden section)
  const auto names = names_of(a.scenes, set);
  if (!a.image.empty() && names.size() != 1)
    throw ra::InputError("rayaudit golden check: --image judges one scene's image: name exactly one SCENE");
  if (names.empty())
    throw ra::InputError((std::filesystem::path(a.root) / "golden" / "manifest.json").string() +
                         ": no golden images to check");
  // A name that is neither a scene nor a golden is refused before any render
  // (it was found after rendering the others). A golden whose
  // scene is gone is a failed check, reported in its turn.
  {
    const auto known = set.all_names();  // sorted: scenes/ and the manifest's entries
    for (const auto& n : names) {
      const std::filesystem::path scene = std::filesystem::path(a.root) / "scenes" / (n + ".json");
      if (!std::filesystem::exists(scene) && !std::binary_search(known.begin(), known.end(), n))
        throw ra::InputError(ra::located(scene.string(), 0, "no such file, and no golden of that name"));
    }
  }
  // Every image a failure may write, declared before the work: the golden
  // itself (--diff-dir ROOT/golden replaced it with this render, and the
  // next check passed), --json, or another scene's inputs are refused. In a
  // folder not there yet (check makes it) an image is declared when written,
  // so it is still renamed with the others at the end (none on exit 2).
  for (const auto& n : names)
    for (const std::filesystem::path& in : set.inputs_of(n))
      if (std::filesystem::is_regular_file(in)) ra::note_input(in);
  check_creatable_dir(diff_dir, "--diff-dir");
  check_diff_dir(diff_dir, names, set);
  // The image to judge, checked against its golden before anything else.
  const std::filesystem::path image(a.image);
  if (!a.image.empty()) {
    const auto ref = set.reference_of(names[0]);
    ra::read_their_image(image, {ref.width, ref.height, ref.bits, ref.image, ""});
  }
  // (Folders the diff images need that are not there yet: `made`, above.)
  for (const auto& n : names)
    for (const auto& out : ra::GoldenSet::diff_outputs(n, diff_dir)) {
      std::vector<std::filesystem::path> missing;
      std::error_code ec;
      for (auto d = std::filesystem::absolute(out).lexically_normal().parent_path();
           !d.empty() && !std::filesystem::exists(d, ec); d = d.parent_path()) {
        missing.push_back(d);
        if (d == d.parent_path()) break;
      }
      for (auto it = missing.rbegin(); it != missing.rend(); ++it)
        if (std::find(made.dirs.begin(), made.dirs.end(), *it) == made.dirs.end()) made.dirs.push_back(*it);
    }
  std::set<std::filesystem::path> later;
  for (const auto& n : names)
    for (const auto& out : ra::GoldenSet::diff_outputs(n, diff_dir)) {
      std::error_code ec;
      if (!a.image.empty() && out.filename() != std::filesystem::path(n).filename().string() + ".diff.png")
        continue;  // with --image, only the diff is written
      if (std::filesystem::is_directory(out.parent_path(), ec)) {
        outputs.add(out);
      } else if (!later.insert(std::filesystem::absolute(out).lexically_normal()).second) {
        throw ra::InputError(
            ra::located(out.string(), 0, "is named as two outputs of this command: one would be lost"));
      }
    }
  auto before_write = [&](const std::filesystem::path& out) {
    if (later.erase(std::filesystem::absolute(out).lexically_normal())) outputs.add(out);
  };
  for (const auto& n : names) {
    const std::filesystem::path scene_file = std::filesystem::path(a.root) / "scenes" / (n + ".json");
    const auto missing = std::filesystem::exists(scene_file) ? ra::missing_cache_inputs(scene_file)
                                                             : std::vector<std::filesystem::path>{};
    if (a.skip_unavailable && !missing.empty()) {
      const std::string why = "needs " + missing[0].string() +
                              ", which is not there (ci/main.sh makes the teapot; ci/fetch-corpus.sh the corpus)";
      std::cout << "skip " << n << ": " << why << "\n";
      rows.push_back({{"name", n}, {"status", "skip"}, {"message", why}, {"scene", "scenes/" + n + ".json"}});
      junit.cases.push_back({"golden", n, ra::junit::Case::Status::skip, why, "", 0});
      ++skipped;
      continue;
    }
    const auto r = set.check(n, diff_dir, before_write, a.image.empty() ? nullptr : &image);
    std::cout << (r.pass ? "ok   " : "FAIL ") << r.message << "\n";
    // One row a scene: its status and message (the report's golden section)
    // and, as compare --json has them, the comparison's fields.
    nlohmann::json row = r.detail;
    row["name"] = n;
    row["status"] = r.pass ? "ok" : "fail";
    row["message"] = r.message;
    rows.push_back(row);
    junit.cases.push_back(
        {"golden", n, r.pass ? ra::junit::Case::Status::pass : ra::junit::Case::Status::fail, r.message, r.message, 0});
    failed += !r.pass;
  }
  // Written whatever the verdict: a failed check is what the report must show.
  if (!a.json.empty()) {
    const nlohmann::json j = {{"root", std::filesystem::absolute(a.root).lexically_normal().string()},
                              {"against", a.image.empty() ? "render" : "image"},
                              {"checked", names.size()},
                              {"failed", failed},
                              {"skipped", skipped},
                              {"diff_key", ra::difference_key_json()},
                              {"scenes", rows}};
    ra::write_text_atomically(a.json, j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  }
  if (!a.junit.empty()) ra::junit::write(a.junit, {junit});
  outputs.commit();  // the JSON and the diff images
  if (failed)
    throw ra::CheckFailed(std::to_string(failed) + " of " + std::to_string(names.size()) + " golden image(s) failed");
  if (skipped == int(names.size())) throw ra::cli::ExitCode{77};
}

// Every scene is rendered before anything is renamed into golden/: a scene
// that fails (exit 2) leaves every golden and the manifest as they were
// (`bless A BAD` rewrote A's image, its manifest entry stale).
void bless(Args a) {
  check_root(a);
  ra::OutputBatch outputs({});
  ra::GoldenSet set(a.root);
  std::string said;
  for (const auto& n : names_of(a.scenes, set)) said += set.bless(n, &outputs) + "\n";
  set.save(&outputs);
  std::cout << said;
}

void setup(CLI::App& app) {
  auto* cmd = app.add_subcommand("golden", "Check scenes against their golden images, or bless new ones");
  cmd->require_subcommand(1);
  cmd->footer(std::string("The project is --root, or else ") + kRootRule +
              ". Hints name it with --root, so they work when pasted anywhere. Each golden is its scene at most "
              "160 pixels on the long side unless its manifest entry sets \"max_side\", and must be identical "
              "unless it sets \"tolerance\" {\"max_levels\": L, \"max_pixels\": P}.");
  auto add = [&](const char* name, const char* help, void (*fn)(Args)) {
    auto args = std::make_shared<Args>();
    auto* sub = cmd->add_subcommand(name, help);
    sub->add_option("scenes", args->scenes, "Scene names or files (default: every scene in scenes/)");
    sub->add_option("--root", args->root,
                    std::string("The project (holding scenes/ and golden/); default: ") + kRootRule);
    if (std::string(name) == "check") {
      sub->add_option("--diff-dir", args->diff_dir,
                      "Where to write diff images on failure (default /tmp/rayaudit-golden); never inside a golden/ "
                      "folder");
      sub->add_option("--image", args->image,
                      "Judge this PNG (another renderer's image of the one SCENE: the golden's size and bits, RGB, "
                      "linear) against the golden instead of a render of ours");
      sub->add_flag("--skip-unavailable", args->skip_unavailable,
                    "Skip scenes whose ${cache} inputs are missing; exit 77 when all were skipped");
      sub->add_option("--json", args->json,
                      "Write each scene's status (ok, fail, skip), message and comparison (compare --json's fields, "
                      "coordinates in scene pixels) as JSON");
      sub->add_option("--junit", args->junit, "Write JUnit XML: one test case per scene, failing with its message");
    }
    sub->callback([args, fn] { fn(*args); });
  };
  add("check", "Render each scene and compare with its golden image (exit 1 on any difference)", check);
  add("bless", "Render each scene and record it as its golden image, printing what changed", bless);
}

ra::cli::Registrar reg(60, setup);

}  // namespace
