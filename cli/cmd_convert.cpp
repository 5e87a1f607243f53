// `rayaudit convert IN -o OUT.obj [--from ply|off]`: PLY (ascii / binary) or
// OFF to OBJ by our own readers (renderer/formats/polymesh_io.h), written atomically.
#include <cstdio>

#include "io/atomic_file.h"
#include "command.h"
#include "errors.h"
#include "io/file_identity.h"
#include "formats/polymesh_io.h"

namespace {

struct Opts {
  std::string in, out, from;
};

void setup(CLI::App& app) {
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("convert", "Convert a PLY or OFF mesh to OBJ");
  cmd->add_option("IN", o->in, "Input mesh (.ply or .off)")->required();
  cmd->add_option("-o,--output", o->out, "Output .obj")->required();
  cmd->add_option("--from", o->from, "Input format when the extension does not say: ply or off")
      ->check(CLI::IsMember({"ply", "off"}));
  cmd->callback([o] {
    const std::string out_ext = std::filesystem::path(o->out).extension().string();
    if (out_ext != ".obj" && out_ext != ".OBJ") throw ra::InputError(o->out + ": the output must be a .obj file");
    ra::declare_output(o->out);  // reading the input refuses it if it is the output
    std::string fmt = o->from;
    if (fmt.empty()) {
      const std::string ext = std::filesystem::path(o->in).extension().string();
      if (ext == ".ply" || ext == ".PLY")
        fmt = "ply";
      else if (ext == ".off" || ext == ".OFF")
        fmt = "off";
      else
        throw ra::InputError(ra::located(o->in, 0, "unknown mesh format (use --from ply|off)"));
    }
    const ra::PolyMesh m = fmt == "ply" ? ra::read_ply(o->in) : ra::read_off(o->in);
    ra::write_obj(m, o->out, "converted by rayaudit convert from " + std::filesystem::path(o->in).filename().string());
    std::fprintf(stderr, "%s: %zu vertices, %zu faces\n", o->out.c_str(), m.positions.size(), m.faces());
  });
}

ra::cli::Registrar reg(31, setup);

}  // namespace
