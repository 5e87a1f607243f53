// `rayaudit audit`: grades the registry's methods against the exact oracle
// (validation/audit.h) over generated families, user cases (--cases) or exports them (--export-cases).
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "atomic_file.h"
#include "audit.h"
#include "cases_csv.h"
#include "command.h"
#include "errors.h"
#include "registry.h"

namespace {

using namespace ra::audit;

// Above this an audit runs for hours and its task list alone takes gigabytes.
constexpr long long kMaxRays = 100000000;

struct Args {
  std::string methods, precision = "float,double", families, json, csv, cases, export_cases;
  long long rays = 200000;  // about 10 s for the full registry on 2 cores
  std::uint64_t seed = 1;
  int threads = 0;
};

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char ch : s + ",") {
    if (ch == ',') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else if (ch != ' ') {
      cur += ch;
    }
  }
  return out;
}

std::vector<const ra::Method*> chosen_methods(const std::string& list) {
  std::vector<const ra::Method*> out;
  if (list.empty()) {
    for (const auto& m : ra::methods())
      if (m.kind != ra::Kind::plane) out.push_back(&m);
    return out;
  }
  for (const auto& name : split_list(list)) {
    const ra::Method* m = ra::find_method(name);
    if (!m)
      throw ra::InputError("audit: unknown method '" + name + "' (triangle: " +
                           ra::method_names(ra::Kind::triangle) + "; sphere: " +
                           ra::method_names(ra::Kind::sphere) + ")");
    if (m->kind == ra::Kind::plane)
      throw ra::InputError("audit: '" + name + "' is a plane method; the audit grades triangles and spheres");
    out.push_back(m);
  }
  return out;
}

std::vector<Precision> chosen_precisions(const std::string& list) {
  std::vector<Precision> out;
  for (const auto& p : split_list(list)) {
    if (p == "float") out.push_back(Precision::f32);
    else if (p == "double") out.push_back(Precision::f64);
    else throw ra::InputError("audit: unknown precision '" + p + "' (float, double)");
  }
  if (out.empty()) throw ra::InputError("audit: --precision needs float and/or double");
  return out;
}

std::vector<std::string> chosen_families(const std::string& list) {
  const auto names = split_list(list);
  for (const auto& n : names)
    if (!find_family(n))
      throw ra::InputError("audit: unknown family '" + n + "' (" + family_names() + ")");
  return names;
}

// A one-line progress bar on stderr, only when stderr is a terminal.
std::function<void(std::size_t, std::size_t)> progress_bar() {
  if (!isatty(STDERR_FILENO)) return {};
  return [](std::size_t done, std::size_t total) {
    const int width = 40, filled = int(double(width) * double(done) / double(total));
    std::fprintf(stderr, "\r[%s%s] %3d%% %zu/%zu chunks", std::string(std::size_t(filled), '#').c_str(),
                 std::string(std::size_t(width - filled), ' ').c_str(), int(100.0 * double(done) / double(total)),
                 done, total);
    if (done == total) std::fprintf(stderr, "\r%*s\r", width + 40, "");
    std::fflush(stderr);
  };
}

// ---------------------------------------------------------- --cases ---
nlohmann::json t_json(double t) { return std::isfinite(t) ? nlohmann::json(t) : nlohmann::json(nullptr); }

void audit_cases(const Args& a) {
  if (!a.csv.empty())
    throw ra::InputError("audit: --csv writes per-family rows, which --cases has none of; use --json");
  ra::OutputBatch outputs({a.json});
  const auto cases = read_cases_csv(a.cases);  // throws before anything is written
  std::vector<const ra::Method*> tri_methods;
  for (const ra::Method* m : chosen_methods(a.methods))
    if (m->kind == ra::Kind::triangle) tri_methods.push_back(m);
  nlohmann::json out = nlohmann::json::array();
  std::printf("%-16s %-10s %-24s", "ID", "VERDICT", "T (exact)");
  for (const auto* m : tri_methods) std::printf(" %-11.11s", m->name.c_str());
  std::printf("\n%-16s %-10s %-24s", "", "", "");
  for (std::size_t i = 0; i < tri_methods.size(); ++i) std::printf(" %-11s", "float dbl");
  std::printf("\n");
  int wrong = 0;
  for (const UserCase& c : cases) {
    const auto ans = ra::oracle::triangle(c.ray, c.tri.a, c.tri.b, c.tri.c);
    nlohmann::json answers = nlohmann::json::object();
    std::printf("%-16.16s %-10s %-24.17g", c.id.c_str(), std::string(ra::oracle::verdict_name(ans.verdict)).c_str(), ans.t);
    for (const auto* m : tri_methods) {
      std::string cell;
      for (Precision p : {Precision::f32, Precision::f64}) {
        std::optional<double> t;
        if (p == Precision::f32) {
          if (auto h = m->tri_f.hit(ra::Rayf(c.ray), ra::Vec3f(c.tri.a), ra::Vec3f(c.tri.b), ra::Vec3f(c.tri.c), false))
            t = double(h->t);
        } else if (auto h = m->tri_d.hit(c.ray, c.tri.a, c.tri.b, c.tri.c, false)) {
          t = h->t;
        }
        answers[m->name + "/" + precision_name(p)] = {{"hit", t.has_value()}, {"t", t ? t_json(*t) : nullptr}};
        // '!' marks an answer the exact verdict contradicts (boundary etc. never do).
        const bool bad = (ans.verdict == ra::oracle::Verdict::hit && !t) ||
                         (ans.verdict == ra::oracle::Verdict::miss && t);
        wrong += bad;
        cell += std::string(t ? "hit" : "miss") + (bad ? "!" : "") + " ";
      }
      std::printf(" %-11s", cell.c_str());
    }
    std::printf("\n");
    out.push_back({{"id", c.id_is_row ? nlohmann::json(std::stol(c.id)) : nlohmann::json(c.id)},
                   {"verdict", std::string(ra::oracle::verdict_name(ans.verdict))},
                   {"t", t_json(ans.t)},
                   {"answers", answers}});
  }
  std::printf("%zu case(s); %d answer(s) contradict the exact verdict (marked !)\n", cases.size(), wrong);
  if (!a.json.empty()) ra::write_text_atomically(a.json, nlohmann::json{{"cases", out}}.dump(2) + "\n");
  outputs.commit();
}

// --------------------------------------------------- --export-cases ---
void export_cases(const Args& a) {
  if (!a.json.empty() || !a.csv.empty())
    throw ra::InputError("audit: --export-cases writes only the cases CSV; run the audit separately for --json/--csv");
  if (!a.methods.empty()) throw ra::InputError("audit: --export-cases exports cases, not methods' answers: drop --methods");
  ra::check_output_path(a.export_cases);
  const auto precisions = chosen_precisions(a.precision);
  // Exported inputs are double unless only float was asked for.
  const Precision p = precisions.size() == 1 ? precisions[0] : Precision::f64;
  const auto rows = export_rows(chosen_families(a.families), p, a.seed, a.rays);
  if (rows.empty())
    throw ra::InputError("audit: --export-cases needs at least one triangle family other than secondary");
  ra::write_text_atomically(a.export_cases, cases_csv(rows));
  std::printf("wrote %zu %s cases to %s\n", rows.size(), precision_name(p), a.export_cases.c_str());
}

// ------------------------------------------------------------ audit ---
void audit(const Args& a) {
  ra::OutputBatch outputs({a.json, a.csv});
  const auto ms = chosen_methods(a.methods);
  const auto ps = chosen_precisions(a.precision);
  Options opt;
  opt.families = chosen_families(a.families);
  opt.rays = a.rays;
  opt.seed = a.seed;
  opt.threads = a.threads;
  opt.progress = progress_bar();
  std::vector<TriangleSubject> tris;
  std::vector<SphereSubject> spheres;
  for (const ra::Method* m : ms)
    for (Precision p : ps) {
      if (m->kind == ra::Kind::triangle) tris.push_back(registry_triangle(*m, p));
      else spheres.push_back(registry_sphere(*m, p));
    }
  if (!a.families.empty()) {
    // A family graded by none of the chosen methods would be an empty table.
    for (const auto& name : opt.families) {
      const Family* f = find_family(name);
      const bool graded = f->kind == ra::Kind::triangle ? !tris.empty() : !spheres.empty();
      if (!graded)
        throw ra::InputError("audit: family '" + name + "' is a " + (f->kind == ra::Kind::triangle ? "triangle" : "sphere") +
                             " family, but no " + (f->kind == ra::Kind::triangle ? "triangle" : "sphere") +
                             " method is chosen (--methods)");
    }
  }
  const Report rep = run(tris, spheres, opt);
  std::fputs(rep.summary_table().c_str(), stdout);
  if (!a.json.empty()) ra::write_text_atomically(a.json, rep.to_json().dump(1) + "\n");
  if (!a.csv.empty()) ra::write_text_atomically(a.csv, rep.to_csv());
  outputs.commit();
}

void setup(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "audit", "Grade intersection methods against exact arithmetic (CGAL/GMP) on generated or given cases");
  auto a = std::make_shared<Args>();
  cmd->add_option("--methods", a->methods, "Comma-separated methods (default: every triangle and sphere method)");
  cmd->add_option("--precision", a->precision, "float, double or both")->capture_default_str();
  cmd->add_option("--families", a->families, "Comma-separated families (default all): " + family_names());
  cmd->add_option("--rays", a->rays,
                  "Ray/primitive tests per family per method and precision (a ray against a fan of 6 counts 6)")
      ->capture_default_str()
      ->check(CLI::Range(1LL, kMaxRays).description("1 to 100000000 (about 20 minutes on 2 cores)"));
  cmd->add_option("--seed", a->seed, "Seed of every generated case")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& v) {
            // CLI11 would saturate 2^64 and beyond to 2^64-1: out of range is an error.
            std::uint64_t x = 0;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
            if (ec == std::errc::result_out_of_range) return std::string("the seed is at most 18446744073709551615 (2^64-1)");
            if (ec != std::errc() || end != v.data() + v.size()) return std::string("the seed is a non-negative integer");
            return std::string();
          },
          "UINT64"));
  cmd->add_option("--threads", a->threads, "Worker threads (0: all cores); results do not depend on it")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--json", a->json, "Write every count to this JSON file");
  cmd->add_option("--csv", a->csv, "Write one row per method x precision x family x sweep value");
  auto* cases = cmd->add_option("--cases", a->cases,
                                "Audit the cases of this CSV (columns ox..cz, optional id) instead of generating");
  cmd->add_option("--export-cases", a->export_cases,
                  "Write the generated cases with exact verdicts as a CSV of C99 hex floats")
      ->excludes(cases);
  cmd->callback([a] {
    if (!a->cases.empty()) return audit_cases(*a);
    if (!a->export_cases.empty()) return export_cases(*a);
    audit(*a);
  });
}

ra::cli::Registrar reg(30, setup);

}  // namespace
