// `rayaudit generate teapot|texture`: the inputs of the shipped mesh and
// texture scenes, made by our own code so that nothing big is committed.
//
//   generate teapot INC -o OUT.obj [--steps N]
//     Tessellates the 32 bicubic Bezier patches of POV-Ray's teapot.inc
//     (Debian povray-examples) into N x N quads per patch, turned y-up
//     ((x, y, z) -> (x, z, -y)). Positions are welded (equal to 1e-9), so
//     smooth shading uses area-weighted vertex normals (no vn is written).
//     UVs are cylindrical about the y axis, u = 3 turns of the texture around
//     the pot (atan2(-z, x), increasing to the right seen from +z), v = 0 at
//     the bottom, 1 at the top of the knob; each patch is unwrapped on its
//     own so no triangle straddles the seam (the -x side, through the handle).
//     Degenerate triangles (the collapsed patch edges at the poles) are dropped.
//
//   generate texture uv-grid|heights|normals -o OUT.png [--size N]
//     uv-grid: 8 x 8 cells, red rising with u, green with v (so (0,0) is the
//       dark bottom-left cell), a checker in blue, and an arrow pointing to +v
//       in each cell: the texture is upright when the arrows point up.
//     heights: 4 x 4 raised round domes (height = grey level) on a flat
//       ground, for the height and pov bump variants.
//     normals: the tangent-space normal map of the same domes (document 002's
//       variant 1 as read in renderer/shading/bump.h): RGB = (n + 1) / 2.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "io/atomic_file.h"
#include "command.h"
#include "errors.h"
#include "io/file_identity.h"
#include "image.h"
#include "io/input_file.h"
#include "formats/mesh.h"
#include "vec.h"

namespace {

using ra::Vec3d;
using Patch = std::array<Vec3d, 16>;  // row-major: 4 rows of 4 control points

// 1-based line of byte `at`, for positions asked in increasing order
// (counted on from the last one: linear in the file, not quadratic).
struct LineOf {
  const std::string& text;
  std::size_t pos = 0;
  long line = 1;
  long operator()(std::size_t at) {
    at = std::min(at, text.size());
    if (at < pos) pos = 0, line = 1;
    line += long(std::count(text.begin() + std::ptrdiff_t(pos), text.begin() + std::ptrdiff_t(at), '\n'));
    pos = at;
    return line;
  }
};

// One number of a vector: all of the text a decimal number, finite and
// within the scene limit (1e400 was a bare "stod").
double inc_number(const std::string& file, long line, std::string s) {
  const auto b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  s = b == std::string::npos ? "" : s.substr(b, e - b + 1);
  char* end = nullptr;
  const double v =
      s.empty() || s.find_first_not_of("+-0123456789.eE") != std::string::npos ? NAN : std::strtod(s.c_str(), &end);
  if (s.empty() || !end || *end || !std::isfinite(v) || std::fabs(v) > 1e30)
    throw ra::InputError(
        ra::located(file, line, "number '" + s.substr(0, 40) + "' is not a finite number within 1e30"));
  return v;
}

// The bicubic_patch blocks of teapot.inc: each `{ ... }` closed and holding
// exactly 16 vectors <x, y, z>; anything else named with its line
// (20 points, an unclosed brace and <1,2> were accepted).
std::vector<Patch> read_teapot_inc(const std::string& file) {
  ra::check_input_file(file);  // /dev/zero, a FIFO or a directory named, not read
  std::ifstream in(file);
  if (!in) throw ra::InputError(ra::located(file, 0, "cannot open"));
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  std::vector<Patch> patches;
  LineOf line_of{text};
  for (std::size_t at = text.find("bicubic_patch"); at != std::string::npos; at = text.find("bicubic_patch", at + 1)) {
    const long line = line_of(at);
    const std::size_t open = text.find('{', at), close = text.find('}', at);
    if (open == std::string::npos || close == std::string::npos || close < open)
      throw ra::InputError(ra::located(file, line, "bicubic_patch without a closed { ... }"));
    Patch p;
    int k = 0;
    for (std::size_t v = text.find('<', open); v != std::string::npos && v < close; v = text.find('<', v + 1)) {
      const std::size_t e = text.find('>', v);
      const long vline = line_of(v);
      if (e == std::string::npos || e > close)
        throw ra::InputError(ra::located(file, vline, "vector '<' without its '>'"));
      const std::string body = text.substr(v + 1, e - v - 1);
      std::vector<std::string> parts;
      std::stringstream fields(body);
      for (std::string f; std::getline(fields, f, ',');) parts.push_back(f);
      if (parts.size() != 3)
        throw ra::InputError(
            ra::located(file, vline, "vector with " + std::to_string(parts.size()) + " components (3 needed)"));
      if (k < 16)
        p[k] = {inc_number(file, vline, parts[0]), inc_number(file, vline, parts[1]),
                inc_number(file, vline, parts[2])};
      ++k;
    }
    if (k != 16)
      throw ra::InputError(
          ra::located(file, line, "bicubic_patch with " + std::to_string(k) + " control points (16 needed)"));
    patches.push_back(p);
  }
  if (patches.empty()) throw ra::InputError(ra::located(file, 0, "no bicubic_patch found"));
  return patches;
}

// Cubic Bernstein basis at t.
std::array<double, 4> bernstein(double t) {
  const double s = 1 - t;
  return {s * s * s, 3 * t * s * s, 3 * t * t * s, t * t * t};
}

Vec3d eval_patch(const Patch& p, double u, double v) {
  const auto bu = bernstein(u), bv = bernstein(v);
  Vec3d out{0, 0, 0};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out += p[r * 4 + c] * (bv[r] * bu[c]);
  return {out.x, out.z, -out.y};  // z-up -> y-up
}

// About 400 bytes a triangle while tessellating (welding map, faces, text):
// 1M triangles (the real teapot at --steps 128) stay in hundreds of MB.
constexpr double kMaxTeapotTriangles = 1 << 20;

void generate_teapot(const std::string& inc, const std::string& out_path, int steps) {
  ra::declare_output(out_path);
  const auto patches = read_teapot_inc(inc);
  // The size of the work from the file and --steps, before it
  // (a 327 KB .inc at --steps 256 took 2.6 GB, a 32 MB one 16.8 GB).
  const double triangles = 2.0 * double(patches.size()) * steps * steps;
  if (triangles > kMaxTeapotTriangles)
    throw ra::InputError(ra::located(inc, 0,
                                     std::to_string(patches.size()) + " patches at --steps " + std::to_string(steps) +
                                         " make " + std::to_string((long long)triangles) + " triangles (about " +
                                         std::to_string((long long)(triangles * 400 / 1e6)) + " MB); at most " +
                                         std::to_string((long long)kMaxTeapotTriangles) + ": a smaller --steps"));
  std::vector<Vec3d> positions;
  std::map<std::array<long long, 3>, int> weld;
  auto vertex = [&](const Vec3d& p) {
    const std::array<long long, 3> key{std::llround(p.x * 1e9), std::llround(p.y * 1e9), std::llround(p.z * 1e9)};
    auto [it, fresh] = weld.emplace(key, int(positions.size()));
    if (fresh) positions.push_back(p);
    return it->second;
  };
  double ymin = 1e300, ymax = -1e300;
  for (const auto& p : patches)
    for (int i = 0; i <= steps; ++i)
      for (int j = 0; j <= steps; ++j) {
        const Vec3d q = eval_patch(p, double(i) / steps, double(j) / steps);
        ymin = std::min(ymin, q.y);
        ymax = std::max(ymax, q.y);
      }
  constexpr double kTurns = 3;  // texture repeats around the pot
  auto angle_u = [](const Vec3d& q) { return std::atan2(-q.z, q.x) / (2 * M_PI); };
  std::vector<std::array<double, 2>> uvs;
  std::vector<std::array<int, 6>> faces;  // v0 t0 v1 t1 v2 t2
  for (const auto& p : patches) {
    const double centre_u = angle_u(eval_patch(p, 0.5, 0.5));
    const int vbase = int(uvs.size());
    std::vector<int> vid((steps + 1) * (steps + 1));
    std::vector<Vec3d> pos((steps + 1) * (steps + 1));
    for (int j = 0; j <= steps; ++j)
      for (int i = 0; i <= steps; ++i) {
        const Vec3d q = eval_patch(p, double(i) / steps, double(j) / steps);
        double u = angle_u(q);
        if (std::hypot(q.x, q.z) < 1e-9) u = centre_u;  // on the axis: any angle
        while (u - centre_u > 0.5) u -= 1;
        while (u - centre_u < -0.5) u += 1;
        // All patches at one height (ymax = ymin): v = 0, not 0/0 = NaN,
        // which our own OBJ reader then refused.
        uvs.push_back({u * kTurns, ymax > ymin ? (q.y - ymin) / (ymax - ymin) : 0.0});
        vid[j * (steps + 1) + i] = vertex(q);
        pos[j * (steps + 1) + i] = q;
      }
    auto tri = [&](int a, int b, int c) {
      if (vid[a] == vid[b] || vid[b] == vid[c] || vid[a] == vid[c]) return;
      if (length(cross(pos[b] - pos[a], pos[c] - pos[a])) == 0) return;
      faces.push_back({vid[a], vbase + a, vid[b], vbase + b, vid[c], vbase + c});
    };
    for (int j = 0; j < steps; ++j)
      for (int i = 0; i < steps; ++i) {
        const int a = j * (steps + 1) + i, b = a + 1, c = a + steps + 1, d = c + 1;
        tri(a, b, d);
        tri(a, d, c);
      }
  }
  // Orient every triangle consistently across shared edges (the patches of
  // teapot.inc do not agree), then outward: positive signed volume.
  std::map<std::pair<int, int>, std::vector<int>> edges;
  for (int f = 0; f < int(faces.size()); ++f)
    for (int k = 0; k < 3; ++k) {
      int a = faces[f][2 * k], b = faces[f][2 * ((k + 1) % 3)];
      edges[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  std::vector<int> flip(faces.size(), -1);
  auto has_directed = [&](int f, int a, int b) {
    for (int k = 0; k < 3; ++k)
      if (faces[f][2 * k] == a && faces[f][2 * ((k + 1) % 3)] == b) return true;
    return false;
  };
  auto flip_face = [&](int f) {
    std::swap(faces[f][2], faces[f][4]);
    std::swap(faces[f][3], faces[f][5]);
  };
  for (int seed = 0; seed < int(faces.size()); ++seed) {
    if (flip[seed] >= 0) continue;
    std::vector<int> component{seed}, queue{seed};
    flip[seed] = 0;
    while (!queue.empty()) {
      const int f = queue.back();
      queue.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int a = faces[f][2 * k], b = faces[f][2 * ((k + 1) % 3)];
        const auto& nb = edges[{std::min(a, b), std::max(a, b)}];
        if (nb.size() != 2) continue;  // borders and non-manifold edges
        const int g = nb[0] == f ? nb[1] : nb[0];
        if (flip[g] >= 0) continue;
        // Consistent neighbours traverse the shared edge in opposite directions.
        flip[g] = 1;
        if (has_directed(g, a, b)) flip_face(g);
        queue.push_back(g);
        component.push_back(g);
      }
    }
    double volume = 0;
    for (int f : component)
      volume += dot(positions[faces[f][0]], cross(positions[faces[f][2]], positions[faces[f][4]]));
    if (volume < 0)
      for (int f : component) flip_face(f);
  }
  // Written through a temporary renamed into place: ci/fetch-corpus.sh takes
  // an existing teapot.obj for done, so an interrupted run must leave none.
  std::ostringstream out;
  out.precision(9);
  out << "# Utah teapot: " << patches.size() << " Bezier patches of POV-Ray's teapot.inc, " << steps << "x" << steps
      << " quads each (rayaudit generate teapot)\n";
  for (const auto& p : positions) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (const auto& t : uvs) out << "vt " << t[0] << ' ' << t[1] << '\n';
  for (const auto& f : faces)
    out << "f " << f[0] + 1 << '/' << f[1] + 1 << ' ' << f[2] + 1 << '/' << f[3] + 1 << ' ' << f[4] + 1 << '/'
        << f[5] + 1 << '\n';
  ra::write_text_atomically(out_path, out.str());
  std::printf("%s: %zu vertices, %zu triangles\n", out_path.c_str(), positions.size(), faces.size());
}

// Height of the dome field at image position (x, y) in [0,1)^2: 4 x 4 domes.
double dome_height(double x, double y) {
  const double fx = x * 4 - std::floor(x * 4) - 0.5, fy = y * 4 - std::floor(y * 4) - 0.5;
  const double r = std::hypot(fx, fy) / 0.4;
  return r < 1 ? std::sqrt(1 - r * r) : 0.0;
}

void generate_texture(const std::string& kind, const std::string& out, int n) {
  ra::Image img(n, n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      float* px = img.at(x, y);
      const double fx = (x + 0.5) / n, fy = (y + 0.5) / n;  // fy from the top
      if (kind == "uv-grid") {
        const int cx = int(fx * 8), cy = int((1 - fy) * 8);                    // cy counts from the bottom
        const double lx = fx * 8 - cx, ly = (1 - fy) * 8 - int((1 - fy) * 8);  // in the cell, ly up
        const bool checker = (cx + cy) % 2 == 0;
        double r = 0.15 + 0.8 * (cx + 0.5) / 8, g = 0.15 + 0.8 * (cy + 0.5) / 8, b = checker ? 0.85 : 0.25;
        // An arrow pointing to +v: a stem and a head.
        const bool stem = std::fabs(lx - 0.5) < 0.07 && ly > 0.15 && ly < 0.6;
        const bool head = ly >= 0.55 && ly < 0.85 && std::fabs(lx - 0.5) < (0.85 - ly) * 0.9;
        if (stem || head) r = g = b = checker ? 0.05 : 0.98;
        px[0] = float(r), px[1] = float(g), px[2] = float(b);
      } else if (kind == "heights") {
        const float h = float(dome_height(fx, fy));
        px[0] = px[1] = px[2] = h;
      } else if (kind == "normals") {
        // Slopes in texture units per unit u and v (v up = -y), scaled.
        const double e = 0.5 / n, k = 0.08;
        const double dhdu = (dome_height(fx + e, fy) - dome_height(fx - e, fy)) / (2 * e);
        const double dhdv = (dome_height(fx, fy - e) - dome_height(fx, fy + e)) / (2 * e);
        Vec3d nn = ra::normalize(Vec3d{-k * dhdu, -k * dhdv, 1});
        if (!std::isfinite(nn.x)) nn = {0, 0, 1};
        px[0] = float(0.5 * (nn.x + 1)), px[1] = float(0.5 * (nn.y + 1)), px[2] = float(0.5 * (nn.z + 1));
      } else {
        throw ra::InputError("generate texture: kind must be uv-grid, heights or normals, got \"" + kind + "\"");
      }
    }
  ra::write_image(out, img, {8, false});
}

void setup(CLI::App& app) {
  auto* cmd = app.add_subcommand("generate", "Generate the teapot mesh or a test texture (see cmd_generate.cpp)");
  cmd->require_subcommand(1);
  auto inc = std::make_shared<std::string>(), out = std::make_shared<std::string>();
  auto steps = std::make_shared<int>(8);
  auto* tp = cmd->add_subcommand("teapot", "Tessellate POV-Ray's teapot.inc into an OBJ with UVs");
  tp->add_option("inc", *inc, "teapot.inc (Debian povray-examples)")->required();
  tp->add_option("-o,--output", *out, "Output .obj")->required();
  tp->add_option("--steps", *steps, "Quads per patch side (default 8)")->check(CLI::Range(1, 256));
  tp->callback([=] {
    // As convert: an OBJ named .png was written without a word.
    const std::string ext = std::filesystem::path(*out).extension().string();
    if (ext != ".obj" && ext != ".OBJ") throw ra::InputError(*out + ": the output must be a .obj file");
    generate_teapot(*inc, *out, *steps);
  });
  auto kind = std::make_shared<std::string>(), tout = std::make_shared<std::string>();
  auto size = std::make_shared<int>(256);
  auto* tx = cmd->add_subcommand("texture", "Write a test texture: uv-grid, heights or normals");
  tx->add_option("kind", *kind, "uv-grid, heights or normals")->required();
  tx->add_option("-o,--output", *tout, "Output .png")->required();
  tx->add_option("--size", *size, "Width and height in pixels (default 256)")->check(CLI::Range(8, 4096));
  tx->callback([=] { generate_texture(*kind, *tout, *size); });
}

ra::cli::Registrar reg(60, setup);

}  // namespace
