// Wavefront MTL reader: newmtl, Ka, Kd, Ks, Ns, Ni, d, Tr, Tf, illum and the
// maps map_Ka, map_Kd, map_Ks, map_d, map_bump (also `bump`, `map_Bump`).
// Keywords are matched case-insensitively (exporters differ). Decisions:
// - `Tr t` means d = 1 - t, unless the material also has `d` (which wins:
//   some exporters write both, with Tr already inverted). d and Tr outside
//   0..1 are errors at their line.
// - Ka/Kd/Ks with one value mean grey (r = g = b); `spectral` / `xyz`
//   forms are ignored with a warning.
// - Map statements: the known options (-blendu -blendv -boost -mm -o -s -t
//   -texres -clamp -bm -imfchan -type -colorspace -cc) with their values come
//   first; the rest of the line is the file name, spaces included
//   (`-s 2 2 1 -bm 0.5 my tex.png` is "my tex.png" with bump_multiplier 0.5).
//   Backslashes become '/', relative names are resolved against the .mtl's
//   directory, a missing file is a warning.
// - Statements before the first newmtl, unknown ones and `newmtl` without
//   a name are warnings. The last stays accepted, as the material named "":
//   Blender writes `newmtl ` with `usemtl ` (the assimp test model
//   empty_mat.obj), so refusing it would refuse real exporter output.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unordered_set>

#include "mesh.h"
#include "../io/file_identity.h"
#include "../io/input_file.h"
#include "obj_text.h"

namespace ra {
namespace {

using namespace objtext;

bool is_kw(const char* k, const char* kend, const char* word) {
  const size_t n = std::strlen(word);
  return size_t(kend - k) == n && starts_with_ci(k, kend, word);
}

// Upper-cases ASCII for starts_with_ci, which compares with an upper word.
std::string upper(const char* s) {
  std::string u(s);
  for (auto& c : u)
    if (c >= 'a' && c <= 'z') c = char(c - 32);
  return u;
}

struct MtlParser {
  const std::string& name;
  const std::filesystem::path& base;
  bool check_files;
  std::vector<std::string>& warnings;
  Where w{&name};
  std::vector<MtlMaterial> out;
  std::vector<bool> has_d;
  std::unordered_set<std::string> unknown;  // a set: distinct unknown statements were a quadratic scan
  CappedWarnings missing{warnings, name, "more textures not found"};
  CappedWarnings early{warnings, name, "more statements before the first newmtl ignored"};
  CappedWarnings unsupported{warnings, name, "more unsupported MTL statements ignored"};

  MtlParser(const std::string& n, const std::filesystem::path& b, bool check, std::vector<std::string>& warn)
      : name(n), base(b), check_files(check), warnings(warn) {}
  void finish() {
    missing.finish();
    early.finish();
    unsupported.finish();
  }

  bool kw(const char* k, const char* kend, const char* word) { return is_kw(k, kend, upper(word).c_str()); }

  void color(Vec3d& c, const char* p, const char* se, long line, const char* what) {
    const char* q = skip_ws(p, se);
    if (q < se && (starts_with_ci(q, se, "SPECTRAL") || starts_with_ci(q, se, "XYZ"))) {
      warnings.push_back(located(name, line, std::string(what) + " spectral/xyz form is not supported (ignored)"));
      return;
    }
    double x[3];
    const int n = parse_numbers(p, se, x, 3, w, line, what);
    bounded(x, n, line, what);
    if (n == 1)
      c = {x[0], x[0], x[0]};
    else if (n == 3)
      c = {x[0], x[1], x[2]};
    else
      w.fail(line, std::string(what) + " needs 1 or 3 values (" + std::to_string(n) + " given)");
  }

  // `bound`: refuse magnitudes above 1e30 (illum has its own 0..1000 rule).
  double scalar(const char* p, const char* se, long line, const char* what, bool bound = true) {
    double x;
    if (parse_numbers(p, se, &x, 1, w, line, what) != 1) w.fail(line, std::string(what) + " needs a value");
    if (bound) bounded(&x, 1, line, what);
    return x;
  }
  // As a scene's numbers (scene.cpp): a Kd of 1e308 overflowed the shading
  // to +inf, reported as a reflection problem of the render.
  void bounded(const double* x, int n, long line, const char* what) {
    for (int i = 0; i < n; ++i)
      if (!(std::abs(x[i]) <= 1e30)) {
        char num[32];
        std::snprintf(num, sizeof num, "%.6g", x[i]);
        w.fail(line, std::string(what) + " value " + num + " has a magnitude above 1e30");
      }
  }

  // True when the token at p is a number (for the optional values of -o -s -t).
  static bool number_at(const char* p, const char* se) {
    double v;
    if (p < se && *p == '+') ++p;
    auto [q, ec] = std::from_chars(p, se, v);
    return ec == std::errc() && at_separator(q, se);
  }

  void map(std::string& dst, const char* p, const char* se, long line, bool bump, std::string* at = nullptr,
           std::string_view keyword = {}) {
    MtlMaterial& m = out.back();
    for (;;) {
      p = skip_ws(p, se);
      if (p >= se || *p != '-') break;
      const char* q = p;
      while (!at_separator(q, se)) ++q;
      const std::string opt(p, q);
      int min = 1, max = 1;
      bool numeric = true;
      if (opt == "-o" || opt == "-s" || opt == "-t") {
        max = 3;
      } else if (opt == "-mm") {
        min = max = 2;
      } else if (opt == "-blendu" || opt == "-blendv" || opt == "-clamp" || opt == "-imfchan" || opt == "-type" ||
                 opt == "-colorspace" || opt == "-cc") {
        numeric = false;
      } else if (opt != "-boost" && opt != "-texres" && opt != "-bm") {
        break;  // not an option: the file name starts with '-'
      }
      p = q;
      for (int i = 0; i < max; ++i) {
        p = skip_ws(p, se);
        if (numeric) {
          if (i >= min && !number_at(p, se)) break;
          double v;
          p = parse_double(p, se, v, w, line);
          if (opt == "-bm" && bump) m.bump_multiplier = v;
        } else {
          const char* e = p;
          while (!at_separator(e, se)) ++e;
          if (e == p) w.fail(line, "texture option " + opt + " needs a value");
          p = e;
        }
      }
    }
    std::string file(rest_as_name(p, se));
    if (file.empty()) w.fail(line, "texture statement without a file name");
    std::replace(file.begin(), file.end(), '\\', '/');
    std::filesystem::path path(file);
    if (path.is_relative()) path = (base / path).lexically_normal();
    dst = path.string();
    if (at) *at = located(name, line, std::string(keyword) + " '" + file + "'");
    // Missing: a warning (the material renders without it). Anything else
    // that is not a file (a directory, a FIFO, a symlink loop) is an error
    // here, naming this line, not later as a bare path or a library text.
    if (!check_files) return;
    const std::string why = input_file_problem(path);
    if (why == "no such file")
      missing.add(line, located(name, line, "texture '" + file + "' not found (" + dst + ")"));
    else if (!why.empty())
      w.fail(line, "texture '" + file + "': " + why + " (" + dst + ")");
    else
      note_input(path);  // never replaced by an output
  }

  void statement(const char* p, const char* se, long line) {
    p = skip_ws(p, se);
    if (p >= se || *p == '#') return;
    const char* k = p;
    while (!at_separator(p, se)) ++p;
    if (kw(k, p, "newmtl")) {
      std::string n(rest_as_name(p, se));
      if (n.empty()) warnings.push_back(located(name, line, "newmtl without a name (material named '')"));
      out.emplace_back();
      out.back().name = std::move(n);
      has_d.push_back(false);
      return;
    }
    if (out.empty()) {
      early.add(line, located(name, line, "statement before the first newmtl ignored"));
      return;
    }
    MtlMaterial& m = out.back();
    if (kw(k, p, "Ka")) {
      m.Ka_at = located(name, line, "Ka");
      return color(m.Ka, p, se, line, "Ka");
    }
    if (kw(k, p, "Kd")) return color(m.Kd, p, se, line, "Kd");
    if (kw(k, p, "Ks")) return color(m.Ks, p, se, line, "Ks");
    if (kw(k, p, "Ns")) return void(m.Ns = scalar(p, se, line, "Ns"));
    if (kw(k, p, "Ni")) {
      m.Ni = scalar(p, se, line, "Ni");
      m.Ni_at = located(name, line, "Ni");
      return;
    }
    if (kw(k, p, "d")) {
      m.d = scalar(p, se, line, "d");
      if (!(m.d >= 0 && m.d <= 1)) w.fail(line, "d (opacity) must be between 0 and 1");
      has_d.back() = true;
      return;
    }
    if (kw(k, p, "Tr")) {
      const double t = scalar(p, se, line, "Tr");
      if (!(t >= 0 && t <= 1)) w.fail(line, "Tr (transparency, 1 - d) must be between 0 and 1");
      if (!has_d.back()) m.d = 1 - t;
      return;
    }
    if (kw(k, p, "Tf")) {
      color(m.Tf, p, se, line, "Tf");
      m.has_Tf = true;
      return;
    }
    if (kw(k, p, "illum")) {
      const double v = scalar(p, se, line, "illum", false);
      if (!(v >= 0 && v <= 1000) || v != std::floor(v)) w.fail(line, "illum needs an integer 0..1000");
      m.illum = int(v);
      return;
    }
    if (kw(k, p, "map_Ka")) return map(m.map_Ka, p, se, line, false);
    if (kw(k, p, "map_Kd")) return map(m.map_Kd, p, se, line, false, &m.map_Kd_at, {k, size_t(p - k)});
    if (kw(k, p, "map_Ks")) return map(m.map_Ks, p, se, line, false);
    if (kw(k, p, "map_d")) return map(m.map_d, p, se, line, false);
    if (kw(k, p, "map_bump") || kw(k, p, "bump"))
      return map(m.map_bump, p, se, line, true, &m.map_bump_at, {k, size_t(p - k)});
    const std::string key(k, p);
    if (unknown.insert(key).second)
      unsupported.add(line, located(name, line, "unsupported MTL statement '" + key + "' ignored"));
  }
};

}  // namespace

std::vector<MtlMaterial> parse_mtl(std::string_view text, const std::string& name,
                                   const std::filesystem::path& base_dir, bool check_files,
                                   std::vector<std::string>& warnings) {
  text = check_encoding(text, name);
  MtlParser parser{name, base_dir, check_files, warnings};
  const char* p = text.data();
  const char* end = p + text.size();
  long line = 1;
  while (p < end) {
    long extra = 0;
    const char* se = statement_end(p, end, extra);
    parser.statement(p, se, line);
    line += extra + 1;
    p = se + 1;
  }
  parser.finish();
  return std::move(parser.out);
}

std::vector<MtlMaterial> load_mtl(const std::filesystem::path& file, std::vector<std::string>& warnings) {
  const std::string buf = read_file_bytes(file, kMaxObjFileBytes);
  return parse_mtl(buf, file.string(), file.parent_path(), true, warnings);
}

}  // namespace ra
