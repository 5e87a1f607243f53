// `rayaudit compare SCENE`: renders the scene with our tracer and with
// POV-Ray 3.7 at the same size, compares them (validation/images/image_compare.h)
// and judges the result against the scene's tolerance, scenes/pov/NAME.json
// (default: identical at 8 bits). Exit 1 when a difference is not explained.
//
// `rayaudit compare SCENE --image THEIRS.png` judges another renderer's image
// of the scene instead of ours, by the same tolerance, with the same diff;
// --explain then names our models' causes where that image agrees with our
// render (validation/images/their_image.h says which images are taken).
//
// `rayaudit compare --random N --seed S [--out DIR]` does the same
// on N random scenes (validation/pov/random_scene.h), explaining every differing
// pixel; a pixel no known cause explains is shrunk to a minimal scene
// (validation/pov/pov_shrink.h) written to DIR. Exit 1 if any remain.
#include <fstream>
#include <iostream>
#include <map>

#include "baseline/junit.h"
#include "io/atomic_file.h"
#include "command.h"
#include "errors.h"
#include <tuple>
#include "io/input_file.h"
#include "memory_budget.h"
#include "images/golden.h"
#include "images/image_compare.h"
#include "images/their_image.h"
#include "pov/pov_explain.h"
#include "pov/pov_export.h"
#include "pov/pov_runner.h"
#include "pov/pov_shrink.h"
#include "pov/pov_tolerance.h"
#include "pov/random_scene.h"
#include "render.h"
#include "scene/scene.h"
#include "scene/scene_mesh.h"

namespace {

// Exit code of --skip-inexpressible (ctest's SKIP_RETURN_CODE).
constexpr int kSkipped = 77;

struct Args {
  std::string scene, json_out, diff_out, ours_out, pov_out, tolerance, out_dir, image, junit;
  int bits = 8, width = 0, height = 0, threads = 0, random = 0;
  std::uint64_t seed = 1;
  bool keep = false, skip_inexpressible = false, explain = false, accept_explained = false;
  bool random_given = false, seed_given = false;
};

// The cause's name: its text up to the first colon ("float32", "shadow cache").
std::string cause_name(const std::string& cause) { return cause.substr(0, cause.find(':')); }

// One line per cause: how many pixels it explains.
std::string cause_counts(const std::vector<ra::PixelExplanation>& pixels) {
  std::map<std::string, int> n;
  for (const auto& p : pixels)
    if (!p.cause.empty()) ++n[cause_name(p.cause)];
  std::string out;
  for (const auto& [name, k] : n) out += (out.empty() ? "" : ", ") + name + " x" + std::to_string(k);
  return out;
}

// --random: N scenes, each compared and explained; unexplained pixels shrunk
// into DIR.
void run_random(const Args& a) {
  namespace fs = std::filesystem;
  if (a.random < 1 || a.random > 100000) throw ra::InputError("--random must be between 1 and 100000");
  if (!a.scene.empty()) throw ra::InputError("--random makes its own scenes: give no SCENE");
  for (const auto& [flag, set] :
       std::vector<std::pair<const char*, bool>>{{"--json", !a.json_out.empty()},
                                                 {"--diff", !a.diff_out.empty()},
                                                 {"--ours", !a.ours_out.empty()},
                                                 {"--pov", !a.pov_out.empty()},
                                                 {"--tolerance", !a.tolerance.empty()},
                                                 {"--width", a.width > 0},
                                                 {"--height", a.height > 0},
                                                 {"--bits", a.bits != 8},
                                                 {"--keep-pov-dir", a.keep},
                                                 {"--skip-inexpressible", a.skip_inexpressible},
                                                 {"--accept-explained", a.accept_explained},
                                                 {"--image", !a.image.empty()}})
    if (set)
      throw ra::InputError(std::string(flag) +
                           " cannot be used with --random (it compares at 8 bits and explains every pixel)");
  ra::find_povray();
  if (ra::random_scene_meshes().empty())
    std::cout << "note: no corpus meshes in " << ra::cache_dir().string()
              << "/corpus (ci/fetch-corpus.sh): the scenes hold spheres, planes and triangles only\n";
  if (!a.out_dir.empty()) {
    std::error_code ec;
    // One level, as every other command's output directory: a missing
    // parent is a mistyped path, not something to create.
    if (!fs::is_directory(fs::absolute(a.out_dir).parent_path()))
      throw ra::InputError(a.out_dir + ": its parent directory does not exist");
    fs::create_directory(a.out_dir, ec);
    if (ec || !fs::is_directory(a.out_dir)) throw ra::InputError(a.out_dir + ": cannot create the --out directory");
    ra::check_output_path(fs::path(a.out_dir) / "unexplained.json");
  }
  ra::OutputBatch outputs({a.junit});
  ra::junit::Suite junit{"rayaudit compare --random", {}};  // --junit: one test case per scene
  int differed = 0, unexplained_scenes = 0;
  std::map<std::string, int> causes;
  nlohmann::json report = nlohmann::json::array();
  for (int i = 0; i < a.random; ++i) {
    const std::string name = "random-" + std::to_string(a.seed) + "-" + std::to_string(i);
    const fs::path file = (a.out_dir.empty() ? fs::path(".") : fs::path(a.out_dir)) / (name + ".json");
    const nlohmann::json j = ra::random_scene(a.seed, i);
    const ra::Scene scene = ra::parse_scene_json(j.dump(), file);
    const ra::ExplainedComparison r = ra::compare_and_explain(scene, a.threads);
    for (const auto& p : r.pixels)
      if (!p.cause.empty()) ++causes[cause_name(p.cause)];
    if (r.differing == 0) {
      std::cout << name << ": identical" << std::endl;
      junit.cases.push_back({"compare", name, ra::junit::Case::Status::pass, "", "", 0});
      continue;
    }
    ++differed;
    if (r.unexplained() == 0) {
      std::cout << name << ": " << r.differing << " pixels differ, all explained (" << cause_counts(r.pixels) << ")"
                << std::endl;
      junit.cases.push_back({"compare", name, ra::junit::Case::Status::pass, "", "", 0});
      continue;
    }
    ++unexplained_scenes;
    const ra::PixelExplanation* first = nullptr;
    for (const auto& p : r.pixels)
      if (p.cause.empty() && (!first || p.levels > first->levels)) first = &p;
    std::cout << name << ": " << r.differing << " pixels differ, " << r.unexplained() << " unexplained (largest at ("
              << first->x << ", " << first->y << "), " << first->levels << " levels)";
    nlohmann::json entry = {{"scene", name},
                            {"x", first->x},
                            {"y", first->y},
                            {"levels", first->levels},
                            {"unexplained_pixels", r.unexplained()},
                            {"differing_pixels", r.differing}};
    if (!a.out_dir.empty()) {
      int tries = 0;
      const nlohmann::json small =
          ra::shrink_scene(j, ra::unexplained_pixel_persists(file, first->x, first->y, a.threads), 200, &tries);
      const fs::path small_file = fs::path(a.out_dir) / (name + ".json");
      ra::write_text_atomically(fs::path(a.out_dir) / (name + ".original.json"), ra::readable_json(j) + "\n");
      ra::write_text_atomically(small_file, ra::readable_json(small) + "\n");
      std::cout << "; shrunk in " << tries << " tries to " << small_file.string();
      entry["minimal_scene"] = small_file.string();
      entry["original_scene"] = (fs::path(a.out_dir) / (name + ".original.json")).string();
    }
    std::cout << std::endl;
    junit.cases.push_back({"compare", name, ra::junit::Case::Status::fail,
                           std::to_string(r.unexplained()) + " of " + std::to_string(r.differing) +
                               " differing pixels have no known cause (largest at (" + std::to_string(first->x) + ", " +
                               std::to_string(first->y) + "), " + std::to_string(first->levels) + " levels)",
                           entry.dump(1), 0});
    report.push_back(entry);
  }
  std::cout << "random scenes: " << a.random << " (seed " << a.seed << "), " << differed << " differed, "
            << unexplained_scenes << " with unexplained pixels\n";
  std::string counts;
  for (const auto& [name, k] : causes) counts += (counts.empty() ? "" : ", ") + name + " x" + std::to_string(k);
  if (!counts.empty()) std::cout << "explained pixels by cause: " << counts << "\n";
  if (!a.out_dir.empty())
    ra::write_text_atomically(fs::path(a.out_dir) / "unexplained.json",
                              report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (!a.junit.empty()) ra::junit::write(a.junit, {junit});
  outputs.commit();
  if (unexplained_scenes > 0)
    throw ra::CheckFailed(
        std::to_string(unexplained_scenes) + " random scenes have pixels no known cause explains" +
        (a.out_dir.empty() ? std::string(" (give --out DIR for minimal scenes)") : "; minimal scenes in " + a.out_dir));
}

// --explain for another renderer's image: our models explain a difference
// between our render and POV-Ray's, so they apply where the image equals
// our render at that pixel (the renderer does as ours does, POV-Ray as
// the model says); elsewhere the image differs from both, which no model
// of ours explains.
std::vector<ra::PixelExplanation> explain_their_differences(const ra::Scene& scene, const ra::Image& theirs,
                                                            const ra::Image& pov, const ra::ImageComparison& c,
                                                            const ra::RenderOptions& opt, int bits) {
  const ra::Image mine = ra::render(scene, opt);
  const ra::ImageComparison mc = ra::compare_images(mine, pov, bits);
  const std::vector<ra::PixelExplanation> ours =
      mc.differences.empty() ? std::vector<ra::PixelExplanation>{} : ra::explain_differences(scene, mine, pov, mc, opt);
  std::map<std::pair<int, int>, std::string> cause;
  for (const auto& e : ours) cause[{e.x, e.y}] = e.cause;
  const ra::Image q_theirs = ra::quantized(theirs, bits), q_mine = ra::quantized(mine, bits);
  std::vector<ra::PixelExplanation> out;
  for (const auto& d : c.differences) {
    ra::PixelExplanation e{d.x, d.y, d.levels, ""};
    const float *t = q_theirs.at(d.x, d.y), *m = q_mine.at(d.x, d.y);
    if (t[0] == m[0] && t[1] == m[1] && t[2] == m[2]) {
      auto it = cause.find({d.x, d.y});
      if (it != cause.end() && !it->second.empty()) e.cause = "as rayaudit's render, " + it->second;
    }
    out.push_back(e);
  }
  return out;
}

void run(const Args& a) {
  if (a.random_given) return run_random(a);
  if (a.scene.empty()) throw ra::InputError("compare needs a SCENE (or --random N)");
  if (!a.out_dir.empty()) throw ra::InputError("--out goes with --random");
  if (a.seed_given) throw ra::InputError("--seed goes with --random");
  if (a.bits != 8 && a.bits != 16) throw ra::InputError("--bits must be 8 or 16");
  if (!a.image.empty() && !a.ours_out.empty())
    throw ra::InputError("rayaudit compare: --ours cannot be used with --image (the image judged is " + a.image + ")");
  if (a.skip_inexpressible)
    if (const auto missing = ra::missing_cache_inputs(a.scene); !missing.empty()) {
      std::cout << "skipped: " << a.scene << " needs " << missing[0].string()
                << ", which is not there (ci/main.sh makes the teapot; ci/fetch-corpus.sh the corpus)\n";
      throw ra::cli::ExitCode{kSkipped};
    }
  // Image formats checked with the other destination checks, before both
  // renders (found only after minutes of POV-Ray).
  for (const std::string* out : {&a.diff_out, &a.ours_out, &a.pov_out}) {
    std::string ext = std::filesystem::path(*out).extension().string();
    for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (!out->empty() && ext != ".png" && ext != ".exr")
      throw ra::InputError(*out + ": unsupported output format (use .png or .exr)");
  }
  ra::OutputBatch outputs({a.json_out, a.diff_out, a.ours_out, a.pov_out, a.junit});
  // Image outputs' formats with the other destination checks, before both
  // renders (x.jpg failed after them: minutes of POV-Ray lost).
  for (auto [flag, path] : {std::pair{"--diff", &a.diff_out}, {"--ours", &a.ours_out}, {"--pov", &a.pov_out}}) {
    std::string ext = std::filesystem::path(*path).extension().string();
    for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (!path->empty() && ext != ".png" && ext != ".exr")
      throw ra::InputError(ra::located(*path, 0, std::string(flag) + ": unsupported output format (use .png or .exr)"));
  }
  ra::Scene scene = ra::load_scene(a.scene);
  if (a.width > 0) scene.width = a.width;
  if (a.height > 0) scene.height = a.height;
  // Ours, POV-Ray's as read, the difference and their encodings.
  ra::check_image_memory("compare", scene.width, scene.height, 64);
  if (auto reason = ra::pov_inexpressible(scene)) {
    if (a.skip_inexpressible) {
      std::cout << "skipped: POV-Ray cannot express " << a.scene << ": " << *reason << "\n";
      throw ra::cli::ExitCode{kSkipped};
    }
    throw ra::InputError(a.scene + ": POV-Ray cannot express this scene: " + *reason);
  }
  // The default tolerance file may be absent (identical at 8 bits); one named
  // on the command line must exist.
  if (!a.tolerance.empty()) {  // a FIFO or directory was "no such tolerance file"
    const std::string why = ra::input_file_problem(a.tolerance);
    if (!why.empty())
      throw ra::InputError(ra::located(a.tolerance, 0, why == "no such file" ? "no such tolerance file" : why));
  }
  const ra::PovTolerance tol = ra::load_pov_tolerance(a.tolerance.empty() ? ra::pov_tolerance_path(a.scene)
                                                                          : std::filesystem::path(a.tolerance));
  // A tolerance file named on the command line is for this image: one for
  // 16x16 silently judged nothing of an 8x8 render. The
  // scene's default file keeps its note ("for WxH, not this size: none
  // apply"), so compare at another --width still runs.
  if (!a.tolerance.empty())
    for (auto [key, want, got] : {std::tuple{"width", tol.width, scene.width}, {"height", tol.height, scene.height}})
      if (want && *want != got)
        throw ra::InputError(ra::located(a.tolerance, 0,
                                         std::string("/") + key + ": " + std::to_string(*want) + ", but the image is " +
                                             std::to_string(got) + (key[0] == 'w' ? " wide" : " high") +
                                             " (give --width/--height, or a tolerance for this size)"));

  // Another renderer's image, checked against the scene's render before
  // either render is made.
  ra::Image theirs;
  if (!a.image.empty()) {
    const std::string size = std::to_string(scene.width) + "x" + std::to_string(scene.height);
    theirs = ra::read_their_image(a.image, {scene.width, scene.height, a.bits,
                                            "the scene's render (" + size + ", --bits " + std::to_string(a.bits) + ")",
                                            "render the scene at its own size, or give --width/--height"});
  }

  ra::RenderOptions opt;
  opt.threads = a.threads;
  opt.progress = false;
  // `ours` is the image judged: our render, or theirs with --image (ours
  // then rendered only for --explain, as `mine`).
  const bool with_image = !a.image.empty();
  const ra::Image ours = with_image ? theirs : ra::render(scene, opt);
  ra::PovRunOptions popt;
  popt.bits = a.bits;
  popt.keep_dir = a.keep;
  const ra::PovRun pov = ra::render_with_povray(scene, popt);

  const ra::ImageComparison c = ra::compare_images(ours, pov.image, a.bits);
  const ra::PovVerdict v = ra::judge(c, tol);
  std::cout << "scene: " << a.scene << "\n";
  if (with_image) std::cout << "image: " << a.image << " (against POV-Ray's render)\n";
  std::cout << ra::summary(c);
  for (const auto& line : v.lines) std::cout << line << "\n";
  std::vector<ra::PixelExplanation> explained;
  if ((a.explain || a.accept_explained) && !c.differences.empty()) {
    std::cout << "likely causes (--explain):\n";
    explained = with_image ? explain_their_differences(scene, ours, pov.image, c, opt, a.bits)
                           : ra::explain_differences(scene, ours, pov.image, c, opt);
    for (const auto& e : explained)
      std::cout << "  (" << e.x << ", " << e.y << ") " << e.levels
                << " levels: " << (e.cause.empty() ? "none of the known causes" : e.cause) << "\n";
  }
  if (!tol.notes.empty()) std::cout << "notes (" << tol.file.string() << "): " << tol.notes << "\n";
  if (!pov.dir.empty()) std::cout << "POV-Ray's working directory: " << pov.dir.string() << "\n";
  if (!a.diff_out.empty()) {
    ra::write_image(a.diff_out, ra::difference_image(ours, pov.image, a.bits));
    std::cout << "difference image: " << a.diff_out << "\n" << ra::difference_key_text();
  }
  if (!a.ours_out.empty()) ra::write_image(a.ours_out, ours, {a.bits, false});
  if (!a.pov_out.empty()) ra::write_image(a.pov_out, pov.image, {a.bits, false});
  if (!a.json_out.empty()) {
    nlohmann::json j = ra::to_json(c);
    j["scene"] = a.scene;
    if (with_image) j["image"] = a.image;
    j["against"] = "pov";
    if (!a.diff_out.empty()) {
      j["diff_image"] = a.diff_out;
      j["diff_key"] = ra::difference_key_json();
    }
    j["tolerance_file"] = tol.file.string();
    j["within_tolerance"] = v.pass;
    j["verdict"] = v.lines;
    if (a.explain) {
      nlohmann::json ex = nlohmann::json::array();
      for (const auto& e : explained) ex.push_back({{"x", e.x}, {"y", e.y}, {"levels", e.levels}, {"cause", e.cause}});
      j["explanations"] = ex;
    }
    ra::write_text_atomically(a.json_out, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  }
  if (!a.junit.empty()) {
    // One test case for the scene, judged as the exit code below judges it.
    int unexplained = 0;
    for (const auto& e : explained) unexplained += e.cause.empty();
    const bool pass = a.accept_explained ? unexplained == 0 : v.pass;
    std::string lines;
    for (const auto& line : v.lines) lines += line + "\n";
    const std::string message = a.accept_explained
                                    ? std::to_string(unexplained) + " of " + std::to_string(c.differences.size()) +
                                          " differing pixels have no known cause"
                                    : "our render differs from POV-Ray's beyond the tolerance";
    ra::junit::write(a.junit,
                     {{"rayaudit compare",
                       {{"compare", a.scene, pass ? ra::junit::Case::Status::pass : ra::junit::Case::Status::fail,
                         pass ? "" : message, ra::summary(c) + lines, 0}}}});
  }
  outputs.commit();  // also when the check fails: the diff and JSON say why
  if (a.accept_explained) {
    // Every differing pixel must have a known cause (the corpus sweep).
    int unexplained = 0;
    for (const auto& e : explained) unexplained += e.cause.empty();
    if (unexplained > 0)
      throw ra::CheckFailed(a.scene + ": " + std::to_string(unexplained) + " of " +
                            std::to_string(c.differences.size()) + " differing pixels have no known cause");
    std::cout << "every differing pixel explained: yes (" << c.differences.size() << " pixels"
              << (explained.empty() ? "" : ": " + cause_counts(explained)) << ")\n";
    return;
  }
  if (!v.pass)
    throw ra::CheckFailed(
        a.scene + ": " + (with_image ? a.image : std::string("our render")) + " differs from POV-Ray's beyond what " +
        (tol.file.empty() ? std::string("the default (identical at 8 bits)") : tol.file.string()) + " explains");
  std::cout << "within tolerance: yes\n";
}

void setup(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("compare", "Render a scene with rayaudit and with POV-Ray 3.7 and compare them");
  cmd->add_option("scene", args->scene, "Scene file (.json) or mesh (.obj)");
  auto* random_opt =
      cmd->add_option("--random", args->random,
                      "Compare N random scenes (spheres, planes, triangles, corpus meshes), explaining every differing "
                      "pixel; exit 1 if any has no known cause");
  auto* seed_opt =
      cmd->add_option("--seed", args->seed, "Seed of the --random batch (default 1)")
          ->check(CLI::Validator(
              [](std::string& v) {
                return v.find('-') == std::string::npos ? std::string() : "the seed is a non-negative integer";
              },
              "UINT64"));
  cmd->add_option("--out", args->out_dir,
                  "With --random: write each unexplained difference here as a minimal scene (shrunk), with "
                  "unexplained.json listing them");
  cmd->add_flag("--accept-explained", args->accept_explained,
                "Pass when every differing pixel has a known cause (--explain), instead of judging by a tolerance "
                "file (the corpus sweep)");
  cmd->add_option("--bits", args->bits, "Compare at 8 or 16 bits per channel (default 8)");
  cmd->add_option("--image", args->image,
                  "Judge this PNG (another renderer's image of SCENE: the scene's size, --bits, RGB, linear values) "
                  "against POV-Ray's render instead of ours");
  cmd->add_option("--json", args->json_out, "Write the statistics as JSON");
  cmd->add_option("--junit", args->junit, "Write JUnit XML: one test case per scene, failing as the exit code does");
  cmd->add_option("--diff", args->diff_out, "Write a false-colour difference image (.png)");
  cmd->add_option("--ours", args->ours_out, "Write our render (.png)");
  cmd->add_option("--pov", args->pov_out, "Write POV-Ray's render (.png)");
  cmd->add_option("--tolerance", args->tolerance, "Tolerance file (default scenes/pov/NAME.json beside the scene)");
  cmd->add_option("--width", args->width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--threads", args->threads, "Threads for our render (default: all cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--explain", args->explain,
                "Test each differing pixel for the known causes (float32 mesh data, equal-normal triangles, "
                "POV's mesh2 hit point, its shadow cache)");
  cmd->add_flag("--keep-pov-dir", args->keep, "Keep POV-Ray's working directory (scene.pov, ini, images)");
  cmd->add_flag("--skip-inexpressible", args->skip_inexpressible,
                "Exit 77 (a skip for ctest) with the reason when POV-Ray cannot express the scene or a ${cache} "
                "input is missing");
  cmd->callback([args, random_opt, seed_opt] {
    args->random_given = random_opt->count() > 0;
    args->seed_given = seed_opt->count() > 0;
    run(*args);
  });
}

ra::cli::Registrar reg(50, setup);

}  // namespace
