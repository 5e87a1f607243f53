// `rayaudit export-pov SCENE -o FILE.pov`: the scene as POV-Ray 3.7 SDL that
// renders the same image (validation/pov/pov_export.h). Images are copied beside
// the .pov under generated names; nothing from the scene is written as SDL.
#include <iostream>

#include "io/atomic_file.h"
#include "command.h"
#include "errors.h"
#include "pov/pov_export.h"
#include "pov/pov_runner.h"
#include "scene/scene.h"

namespace {

struct Args {
  std::string scene, out, ini;
  int width = 0, height = 0;
};

// The output's stem reduced to [A-Za-z0-9_.-], as the images' name prefix.
std::string safe_prefix(const std::filesystem::path& out) {
  std::string p = out.stem().string();
  for (char& c : p)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '.' && c != '-') c = '_';
  return p + "-";
}

void run(const Args& a) {
  const std::filesystem::path out(a.out);
  if (out.extension() != ".pov") throw ra::InputError(a.out + ": output must be a .pov file");
  // One path given twice would keep only the later file (the ini over the scene).
  if (!a.ini.empty() &&
      std::filesystem::absolute(a.ini).lexically_normal() == std::filesystem::absolute(out).lexically_normal())
    throw ra::InputError(a.ini + ": --ini names the same file as -o");
  ra::OutputBatch outputs({out, a.ini});
  ra::Scene scene = ra::load_scene(a.scene);
  if (a.width > 0) scene.width = a.width;
  if (a.height > 0) scene.height = a.height;
  const ra::PovExport ex = ra::export_pov(scene, safe_prefix(out));
  const std::filesystem::path dir = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
  for (const auto& img : ex.images) {
    outputs.add(dir / img.name);
    ra::copy_pov_image(img.source, dir / img.name);
  }
  ra::write_text_atomically(out, ex.sdl);
  if (!a.ini.empty()) ra::write_text_atomically(a.ini, ra::pov_ini(8));
  outputs.commit();
  std::cout << "wrote " << out.string();
  if (!ex.images.empty()) std::cout << " and " << ex.images.size() << " image(s) beside it";
  std::cout << "\nrender it from " << dir.string() << " with: povray " << (a.ini.empty() ? "YOUR.ini" : a.ini) << " +I"
            << out.filename().string() << " +W" << scene.width << " +H" << scene.height
            << " +WT1 (ini: Antialias=Off, File_Gamma=1.0, Output_File_Type=N; see --ini)\n";
}

void setup(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("export-pov", "Write a scene as POV-Ray 3.7 SDL (.pov) that renders the same image");
  cmd->add_option("scene", args->scene, "Scene file (.json) or mesh (.obj)")->required();
  cmd->add_option("-o,--output", args->out, "Output .pov file (images are copied beside it)")->required();
  cmd->add_option("--ini", args->ini, "Also write the POV-Ray ini that matches our renderer");
  cmd->add_option("--width", args->width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->callback([args] { run(*args); });
}

ra::cli::Registrar reg(40, setup);

}  // namespace
