// `rayaudit compare SCENE`: renders the scene with our tracer and with
// POV-Ray 3.7 at the same size, compares them (validation/image_compare.h)
// and judges the result against the scene's tolerance, scenes/pov/NAME.json
// (default: identical at 8 bits). Exit 1 when a difference is not explained.
#include <iostream>

#include "atomic_file.h"
#include "command.h"
#include "errors.h"
#include "golden.h"
#include "image_compare.h"
#include "pov_explain.h"
#include "pov_export.h"
#include "pov_runner.h"
#include "pov_tolerance.h"
#include "render.h"
#include "scene.h"

namespace {

// Exit code of --skip-inexpressible (ctest's SKIP_RETURN_CODE).
constexpr int kSkipped = 77;

struct Args {
  std::string scene, json_out, diff_out, ours_out, pov_out, tolerance;
  int bits = 8, width = 0, height = 0, threads = 0;
  bool keep = false, skip_inexpressible = false, explain = false;
};

void run(const Args& a) {
  if (a.bits != 8 && a.bits != 16) throw ra::InputError("--bits must be 8 or 16");
  if (a.skip_inexpressible)
    if (const auto missing = ra::missing_cache_inputs(a.scene); !missing.empty()) {
      std::cout << "skipped: " << a.scene << " needs " << missing[0].string()
                << ", which is not there (ci/main.sh makes the teapot; ci/fetch-corpus.sh the corpus)\n";
      throw ra::cli::ExitCode{kSkipped};
    }
  ra::OutputBatch outputs({a.json_out, a.diff_out, a.ours_out, a.pov_out});
  ra::Scene scene = ra::load_scene(a.scene);
  if (a.width > 0) scene.width = a.width;
  if (a.height > 0) scene.height = a.height;
  if (auto reason = ra::pov_inexpressible(scene)) {
    if (a.skip_inexpressible) {
      std::cout << "skipped: POV-Ray cannot express " << a.scene << ": " << *reason << "\n";
      throw ra::cli::ExitCode{kSkipped};
    }
    throw ra::InputError(a.scene + ": POV-Ray cannot express this scene: " + *reason);
  }
  // The default tolerance file may be absent (identical at 8 bits); one named
  // on the command line must exist.
  if (!a.tolerance.empty() && !std::filesystem::is_regular_file(a.tolerance))
    throw ra::InputError(a.tolerance + ": no such tolerance file");
  const ra::PovTolerance tol =
      ra::load_pov_tolerance(a.tolerance.empty() ? ra::pov_tolerance_path(a.scene) : std::filesystem::path(a.tolerance));

  ra::RenderOptions opt;
  opt.threads = a.threads;
  opt.progress = false;
  const ra::Image ours = ra::render(scene, opt);
  ra::PovRunOptions popt;
  popt.bits = a.bits;
  popt.keep_dir = a.keep;
  const ra::PovRun pov = ra::render_with_povray(scene, popt);

  const ra::ImageComparison c = ra::compare_images(ours, pov.image, a.bits);
  const ra::PovVerdict v = ra::judge(c, tol);
  std::cout << "scene: " << a.scene << "\n" << ra::summary(c);
  for (const auto& line : v.lines) std::cout << line << "\n";
  std::vector<ra::PixelExplanation> explained;
  if (a.explain && !c.differences.empty()) {
    std::cout << "likely causes (--explain):\n";
    explained = ra::explain_differences(scene, ours, pov.image, c, opt);
    for (const auto& e : explained)
      std::cout << "  (" << e.x << ", " << e.y << ") " << e.levels << " levels: "
                << (e.cause.empty() ? "none of the known causes" : e.cause) << "\n";
  }
  if (!tol.notes.empty()) std::cout << "notes (" << tol.file.string() << "): " << tol.notes << "\n";
  if (!pov.dir.empty()) std::cout << "POV-Ray's working directory: " << pov.dir.string() << "\n";
  if (!a.diff_out.empty()) {
    ra::write_image(a.diff_out, ra::difference_image(ours, pov.image, a.bits));
    std::cout << "difference image: " << a.diff_out << "\n";
  }
  if (!a.ours_out.empty()) ra::write_image(a.ours_out, ours, {a.bits, false});
  if (!a.pov_out.empty()) ra::write_image(a.pov_out, pov.image, {a.bits, false});
  if (!a.json_out.empty()) {
    nlohmann::json j = ra::to_json(c);
    j["scene"] = a.scene;
    j["tolerance_file"] = tol.file.string();
    j["within_tolerance"] = v.pass;
    j["verdict"] = v.lines;
    if (a.explain) {
      nlohmann::json ex = nlohmann::json::array();
      for (const auto& e : explained) ex.push_back({{"x", e.x}, {"y", e.y}, {"levels", e.levels}, {"cause", e.cause}});
      j["explanations"] = ex;
    }
    ra::write_text_atomically(a.json_out, j.dump(2) + "\n");
  }
  outputs.commit();  // also when the check fails: the diff and JSON say why
  if (!v.pass)
    throw ra::CheckFailed(a.scene + ": our render differs from POV-Ray's beyond what " +
                          (tol.file.empty() ? std::string("the default (identical at 8 bits)") : tol.file.string()) +
                          " explains");
  std::cout << "within tolerance: yes\n";
}

void setup(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("compare", "Render a scene with rayaudit and with POV-Ray 3.7 and compare them");
  cmd->add_option("scene", args->scene, "Scene file (.json) or mesh (.obj)")->required();
  cmd->add_option("--bits", args->bits, "Compare at 8 or 16 bits per channel (default 8)");
  cmd->add_option("--json", args->json_out, "Write the statistics as JSON");
  cmd->add_option("--diff", args->diff_out, "Write a false-colour difference image (.png)");
  cmd->add_option("--ours", args->ours_out, "Write our render (.png)");
  cmd->add_option("--pov", args->pov_out, "Write POV-Ray's render (.png)");
  cmd->add_option("--tolerance", args->tolerance, "Tolerance file (default scenes/pov/NAME.json beside the scene)");
  cmd->add_option("--width", args->width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--threads", args->threads, "Threads for our render (default: all cores)")->check(CLI::Range(0, 1024));
  cmd->add_flag("--explain", args->explain,
                "Test each differing pixel for the known causes (float32 mesh data, equal-normal triangles, "
                "POV's mesh2 hit point, its shadow cache)");
  cmd->add_flag("--keep-pov-dir", args->keep, "Keep POV-Ray's working directory (scene.pov, ini, images)");
  cmd->add_flag("--skip-inexpressible", args->skip_inexpressible,
                "Exit 77 (a skip for ctest) with the reason when POV-Ray cannot express the scene or a ${cache} "
                "input is missing");
  cmd->callback([args] { run(*args); });
}

ra::cli::Registrar reg(50, setup);

}  // namespace
