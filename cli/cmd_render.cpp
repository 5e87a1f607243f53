// `rayaudit render SCENE -o OUT`: renders a scene file (or a bare .obj).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>

#include "io/atomic_file.h"
#include "command.h"
#include "errors.h"
#include "io/file_identity.h"
#include "image_module.h"
#include "memory_budget.h"
#include "registry.h"
#include "render.h"
#include "scene/scene.h"

namespace {

struct Args {
  std::string scene, out;
  int width = 0, height = 0, threads = 0, spp = 1, bits = 8;
  std::vector<std::string> methods;
  std::string precision = "double", accel = "bvh", self_intersection = "pov";
  bool cull = false, srgb = false;
};

// --spp N means N samples per pixel on an n x n grid, so N must be a square.
int samples_per_axis(int spp) {
  for (int n = 1; n <= 16; ++n)
    if (n * n == spp) return n;
  throw ra::InputError("--spp must be a square number of samples per pixel (1, 4, 9, ... 256), got " +
                       std::to_string(spp));
}

// Absurd work is refused before it starts: at most kMaxPrimaryRays primary
// rays (16384x16384 at 16 spp); 16384x16384 at 256 spp would take hours.
constexpr std::uint64_t kMaxPrimaryRays = std::uint64_t(1) << 32;

void check_work(const ra::Scene& scene, int spp) {
  const std::uint64_t rays = std::uint64_t(scene.width) * std::uint64_t(scene.height) * std::uint64_t(spp);
  if (rays > kMaxPrimaryRays)
    throw ra::InputError(std::to_string(scene.width) + "x" + std::to_string(scene.height) + " at " +
                         std::to_string(spp) + " spp is " + std::to_string(rays) +
                         " primary rays, more than the limit of " + std::to_string(kMaxPrimaryRays) +
                         " (16384x16384 at 16 spp): lower --width, --height or --spp");
}

// A radiance that is not a finite float is a property of the scene
// (reflection above 1 compounding over max_depth levels: 2^256 overflows a
// float; times a zero channel it is NaN). POV-Ray keeps colours in float and
// clamps them into 8- and 16-bit files, so a PNG shows +inf as white, as
// POV's does; an EXR would hold +inf (which our own readers refuse) and
// NaN means nothing in either: refused, naming the scene and the pixel.
void check_finite(const ra::Scene& scene, const ra::Image& img, bool exr) {
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = img.at(x, y)[c];
        if (std::isfinite(v) || (!exr && !std::isnan(v))) continue;
        const std::string what = std::isnan(v) ? "nan" : v > 0 ? "+inf" : "-inf";
        throw ra::InputError(ra::located(
            scene.file.string(), 0,
            "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") has radiance " + what +
                (std::isnan(v) ? ": a texture holds NaN, or an overflowing reflection met a zero channel"
                               : ", beyond a float's range: reflection above 1 compounds over max_depth " +
                                     std::to_string(scene.max_depth) +
                                     " levels; lower them (a PNG output clamps +inf to white, as POV-Ray does)")));
      }
}

void run(const Args& a) {
  ra::RenderOptions opt;
  // At most one method per primitive kind: a second one of the same kind
  // would silently replace the first. The plane has one method only.
  const ra::Method* chosen_triangle = nullptr;
  const ra::Method* chosen_sphere = nullptr;
  for (const auto& name : a.methods) {
    const ra::Method* m = ra::find_method(name);
    if (!m || m->kind == ra::Kind::plane)
      throw ra::InputError("unknown method \"" + name +
                           "\" for --method; triangle methods: " + ra::method_names(ra::Kind::triangle) +
                           "; sphere methods: " + ra::method_names(ra::Kind::sphere));
    const ra::Method*& slot = m->kind == ra::Kind::triangle ? chosen_triangle : chosen_sphere;
    if (slot && slot != m)
      throw ra::InputError("--method given two " + std::string(m->kind == ra::Kind::triangle ? "triangle" : "sphere") +
                           " methods (\"" + std::string(slot->name) + "\" and \"" + name +
                           "\"); give one of each kind");
    slot = m;
    if (m->kind == ra::Kind::triangle)
      opt.triangle_method = name;
    else
      opt.sphere_method = name;
  }
  if (a.precision == "float")
    opt.use_double = false;
  else if (a.precision != "double")
    throw ra::InputError("--precision must be float or double, got \"" + a.precision + "\"");
  auto accel = ra::parse_accel(a.accel);
  if (!accel) throw ra::InputError("--accel must be none, sphere or bvh, got \"" + a.accel + "\"");
  opt.accel = *accel;
  auto si = ra::parse_self_intersection(a.self_intersection);
  if (!si)
    throw ra::InputError("--self-intersection must be one of " + std::string(ra::kSelfIntersectionNames) + ", got \"" +
                         a.self_intersection + "\"");
  opt.self_intersection = *si;
  opt.cull = a.cull;
  opt.threads = a.threads;
  opt.samples_per_axis = samples_per_axis(a.spp);
  if (a.bits != 8 && a.bits != 16) throw ra::InputError("--bits must be 8 or 16");
  {
    // Check the output path before the (possibly long) render.
    std::string ext = std::filesystem::path(a.out).extension().string();
    if (ext != ".png" && ext != ".exr" && ext != ".PNG" && ext != ".EXR")
      throw ra::InputError(a.out + ": output must be .png or .exr");
    // An EXR holds the linear floats: the PNG options would be ignored.
    if ((ext == ".exr" || ext == ".EXR") && (a.srgb || a.bits != 8))
      throw ra::InputError(a.out + ": --srgb and --bits apply to PNG; an EXR holds the linear float values");
    // Its directory too: a missing one used to be found after the render.
    ra::declare_output(a.out);  // and not an input (the scene's textures are checked on loading)
    // And the image module that will write it (loaded now, not after the render).
    ra::image_module::api();
  }
  ra::Scene scene = ra::load_scene(a.scene);
  if (a.width > 0) scene.width = a.width;
  if (a.height > 0) scene.height = a.height;
  if (a.width > 0 || a.height > 0) ra::apply_content_defaults(scene);
  check_work(scene, a.spp);
  // POV-Ray's windows (the default) drop hits nearer than 1e-4 and shadow
  // blockers within 1e-3 of a point: a scene a few thousandths across then
  // renders black or unshadowed, which exited 0 without a word (a 1e-5
  // quad as a bare .obj).
  if (opt.self_intersection == ra::SelfIntersection::pov) {
    const double r = ra::scene_bounds(scene).radius;
    if (r > 0 && r < 1e-2)
      std::fprintf(stderr,
                   "warning: %s: the scene is %.3g across; POV-Ray's rules (--self-intersection pov, the default) "
                   "drop hits nearer than 1e-4 and shadows within 1e-3, so it may render black or unshadowed: "
                   "scale it up, or use --self-intersection eps or ulp-offset\n",
                   a.scene.c_str(), 2 * r);
  }
  // The image (12 bytes a pixel) and its encoded copies (up to 6 + 6 at
  // 16 bits), refused now rather than as a bad_alloc after the render.
  ra::check_image_memory("render", scene.width, scene.height, 24);
  const ra::Image img = ra::render(scene, opt);
  std::string ext = std::filesystem::path(a.out).extension().string();
  check_finite(scene, img, ext == ".exr" || ext == ".EXR");
  ra::write_image(a.out, img, {a.bits, a.srgb});
}

void setup(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("render", "Render a scene (.json, or a bare .obj) to PNG or EXR");
  cmd->add_option("scene", args->scene, "Scene file (.json) or mesh (.obj)")->required();
  cmd->add_option("-o,--output", args->out, "Output image (.png or .exr)")->required();
  cmd->add_option("--width", args->width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  cmd->add_option("--threads", args->threads, "Threads (default: all cores)")->check(CLI::Range(0, 1024));
  cmd->add_option("--spp", args->spp, "Samples per pixel on an n x n grid: 1, 4, 9, ... (default 1)")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--method", args->methods,
                  "Intersection method by name (see `rayaudit methods`); a triangle and a sphere "
                  "method may both be given, as two --method options")
      ->allow_extra_args(false);  // one name per --method: `--method kraus SCENE` keeps SCENE
  cmd->add_option("--precision", args->precision, "Intersection precision: float or double (default double)");
  cmd->add_flag("--cull", args->cull, "Backface culling of triangles");
  cmd->add_option("--accel", args->accel,
                  "Acceleration: bvh (default), sphere (document 002's bounding sphere) or none");
  cmd->add_option("--self-intersection", args->self_intersection,
                  "Secondary-ray strategy: eps, pov (default), normal-offset, ulp-offset");
  cmd->add_option("--bits", args->bits, "PNG bits per channel: 8 or 16 (default 8)");
  cmd->add_flag("--srgb", args->srgb, "sRGB-encode the PNG (default: linear values)");
  cmd->callback([args] { run(*args); });
}

ra::cli::Registrar reg(10, setup);

}  // namespace
