// `rayaudit report`: the main job's product. Checks every input
// here, then validation/report/report.py (matplotlib) draws the page.
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <map>
#include <optional>
#include <sstream>

#include "io/atomic_file.h"
#include "command.h"
#include "io/json_input.h"
#include "errors.h"
#include "io/text_lines.h"
#include "io/input_file.h"
#include "registry.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Args {
  std::string audit, crack_maps, golden, stages, out, timings;
  std::vector<std::string> compare, bench;
  std::vector<std::string> audits;  // every --audit; `audit` is the first
};

// Debian's matplotlib is installed for the system interpreter only.
std::string python() {
  const char* p = std::getenv("RAYAUDIT_PYTHON");
  return p && *p ? p : "/usr/bin/python3";
}
fs::path script() { return fs::path(RAYAUDIT_SOURCE_DIR) / "validation" / "report" / "report.py"; }

std::string read_file(const fs::path& f) {
  ra::check_input_file(f);  // what it is if not a file; an output naming it is refused
  std::ifstream in(f, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  if (!in && !in.eof()) throw ra::InputError(f.string() + ": cannot read");
  return ss.str();
}

// Parses a JSON file; a syntax error names the file and line.
json read_json(const fs::path& f, bool gbench = false) {
  const std::string text = gbench ? ra::gbench_non_finite_to_null(read_file(f)) : read_file(f);
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    const std::size_t at = std::min<std::size_t>(e.byte ? e.byte - 1 : 0, text.size());
    const int line = 1 + int(std::count(text.begin(), text.begin() + std::ptrdiff_t(at), '\n'));
    std::string what = e.what();
    if (const auto p = what.find("syntax error"); p != std::string::npos) what = what.substr(p);
    throw ra::InputError(ra::located(f.string(), line, "malformed JSON: " + what));
  }
}

// `j` at `path` must hold `key` of the given type ("object", "array", "number", "string").
const json& need(const fs::path& f, const json& j, const std::string& where, const std::string& key,
                 const std::string& type) {
  if (!j.is_object() || !j.contains(key))
    throw ra::InputError(f.string() + ": " + (where.empty() ? "" : where + ": ") + "missing '" + key + "'");
  const json& v = j.at(key);
  const bool ok = type == "object"   ? v.is_object()
                  : type == "array"  ? v.is_array()
                  : type == "number" ? v.is_number()
                  : type == "string" ? v.is_string()
                                     : v.is_boolean();
  if (!ok)
    throw ra::InputError(f.string() + ": " + (where.empty() ? "" : where + ": ") + "'" + key + "' is not a " + type);
  return v;
}

json check_audit(const fs::path& f) {
  json j = read_json(f);
  if (!j.is_object()) throw ra::InputError(f.string() + ": not an audit JSON (rayaudit audit --json): not an object");
  if (j.contains("cases") && !j.contains("subjects"))
    throw ra::InputError(f.string() +
                         ": an `audit --cases` output; the report needs the families' audit (rayaudit audit --json)");
  need(f, j, "", "seed", "number");
  need(f, j, "", "rays_per_family", "number");
  const json& subs = need(f, j, "", "subjects", "array");
  if (subs.empty()) throw ra::InputError(f.string() + ": no subjects");
  for (std::size_t i = 0; i < subs.size(); ++i) {
    const std::string at = "subjects[" + std::to_string(i) + "]";
    for (const char* k : {"name", "method", "precision", "kind"}) need(f, subs[i], at, k, "string");
    const json& t = need(f, subs[i], at, "totals", "object");
    for (const char* k : {"tests", "wrong_pct", "leaks", "groups"}) need(f, t, at + ".totals", k, "number");
  }
  const json& cells = need(f, j, "", "cells", "array");
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const std::string at = "cells[" + std::to_string(i) + "]";
    for (const char* k : {"subject", "family", "param", "sweep"}) need(f, cells[i], at, k, "string");
    // The page splits the subject at its last '/' (a subject
    // without one, or a negative count, ended in a Python traceback).
    const std::string subject = cells[i]["subject"].get<std::string>();
    const std::size_t slash = subject.rfind('/');
    if (slash == std::string::npos || slash == 0 || slash + 1 == subject.size())
      throw ra::InputError(f.string() + ": " + at + ": subject '" + subject + "' is not METHOD/PRECISION");
    const json& s = need(f, cells[i], at, "stats", "object");
    for (const char* k : {"tests", "wrong_pct", "leaks", "groups", "double_hits", "spawned", "self_hits"}) {
      const json& v = need(f, s, at + ".stats", k, "number");
      if (!(v.get<double>() >= 0))
        throw ra::InputError(f.string() + ": " + at + ".stats." + k + ": " + v.dump() + " is negative");
    }
  }
  return j;
}

// Several audits on one page (the main run, users' graded or API runs):
// the same seed and rays, so their figures are of the same cases, and no
// subject twice.
void check_audits(const std::vector<std::string>& files) {
  json first;
  std::map<std::string, std::string> owner;
  for (const auto& f : files) {
    const json j = check_audit(f);
    if (first.is_null())
      first = j;
    else
      for (const char* k : {"seed", "rays_per_family"})
        if (j[k] != first[k])
          throw ra::InputError(f + ": " + k + " " + j[k].dump() + ", but " + files[0] + " has " + first[k].dump() +
                               " (--audit files must be runs of the same seed and rays; export the cases with "
                               "--seed and --rays as the main run)");
    for (const auto& s : j["subjects"]) {
      const std::string name = s["name"].get<std::string>();
      if (owner.count(name) && owner[name] != f)
        throw ra::InputError(f + ": subject '" + name + "' is also in " + owner[name] + " (rename the answers file)");
      owner[name] = f;
    }
  }
}

// subject,ns_per_test (validation/baseline/timing.h): users' kernels timed
// as the kernel/ rows are.
void check_timings(const fs::path& f) {
  std::istringstream in(read_file(f));
  std::string line;
  int n = 0;
  for (bool header = true; ra::read_text_line(in, line);) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      if (line != "subject,ns_per_test")
        throw ra::InputError(ra::located(f.string(), n, "expected the header subject,ns_per_test"));
      header = false;
      continue;
    }
    const auto comma = line.rfind(',');
    const std::string subject = comma == std::string::npos ? "" : line.substr(0, comma);
    const auto slash = subject.rfind('/');
    if (slash == std::string::npos || slash == 0 || slash + 1 == subject.size())
      throw ra::InputError(ra::located(f.string(), n, "expected METHOD/PRECISION,NS (e.g. mine/float,4.2)"));
    char* end = nullptr;
    const std::string num = line.substr(comma + 1);
    const double v = std::strtod(num.c_str(), &end);
    if (num.empty() || num.find_first_not_of("0123456789.eE+-") != std::string::npos || *end || !std::isfinite(v) ||
        v <= 0)
      throw ra::InputError(ra::located(f.string(), n, "ns_per_test '" + num + "' is not a positive number"));
  }
}

void check_bench(const fs::path& f) {
  const json j = read_json(f, true);
  const json& bs = need(f, j, "", "benchmarks", "array");
  need(f, j, "", "context", "object");
  for (std::size_t i = 0; i < bs.size(); ++i) {
    const std::string at = "benchmarks[" + std::to_string(i) + "]";
    need(f, bs[i], at, "name", "string");
    // NaN and Infinity (null here) only where Google Benchmark writes them,
    // the spread of a constant counter; a figure the page draws must be a
    // finite number >= 0 (NaN drew nothing and a negative time a point off
    // the chart).
    const bool spread = bs[i].contains("aggregate_name") && bs[i]["aggregate_name"].is_string() &&
                        (bs[i]["aggregate_name"] == "cv" || bs[i]["aggregate_name"] == "stddev");
    for (const char* k : {"ns_per_test", "Mrays_per_s", "ratio", "triangles"}) {
      if (!bs[i].contains(k) || (spread && bs[i][k].is_null())) continue;
      const json& v = bs[i][k];
      if (v.is_null()) throw ra::InputError(f.string() + ": " + at + ": '" + k + "' is NaN or infinite");
      if (!v.is_number()) throw ra::InputError(f.string() + ": " + at + ": '" + k + "' is not a number");
      if (!(v.get<double>() >= 0))
        throw ra::InputError(f.string() + ": " + at + ": '" + k + "' is negative (" + v.dump() + ")");
    }
  }
}

void check_compare_dir(const fs::path& d) {
  if (!fs::is_directory(d))
    throw ra::InputError(d.string() + ": not a directory (--compare takes a directory of `compare --json` outputs)");
  int found = 0;
  for (const auto& e : fs::directory_iterator(d)) {
    if (e.path().extension() != ".json") continue;
    const json j = read_json(e.path());
    for (const char* k : {"width", "height", "differing"}) need(e.path(), j, "", k, "number");
    need(e.path(), j, "", "identical", "boolean");
    const json& ds = need(e.path(), j, "", "differences", "array");
    for (std::size_t i = 0; i < ds.size(); ++i)
      for (const char* k : {"x", "y", "levels"})
        need(e.path(), ds[i], "differences[" + std::to_string(i) + "]", k, "number");
    if (j.contains("explanations")) {
      const json& ex = need(e.path(), j, "", "explanations", "array");
      for (std::size_t i = 0; i < ex.size(); ++i) {
        const std::string at = "explanations[" + std::to_string(i) + "]";
        for (const char* k : {"x", "y"}) need(e.path(), ex[i], at, k, "number");
        need(e.path(), ex[i], at, "cause", "string");
      }
    }
    ++found;
  }
  if (!found)
    throw ra::InputError(d.string() +
                         ": no compare JSON in this directory (rayaudit compare SCENE --json DIR/NAME.json)");
}

void check_crack_maps(const fs::path& d) {
  if (!fs::is_directory(d))
    throw ra::InputError(d.string() + ": not a directory (--crack-maps takes `rayaudit crack-maps -o DIR`'s DIR)");
  const fs::path f = d / "crack_maps.json";
  const json j = read_json(f);
  need(f, j, "", "legend", "string");
  const json& ms = need(f, j, "", "meshes", "array");
  for (std::size_t i = 0; i < ms.size(); ++i) {
    need(f, ms[i], "meshes[" + std::to_string(i) + "]", "name", "string");
    need(f, ms[i], "meshes[" + std::to_string(i) + "]", "source", "string");
  }
  const json& maps = need(f, j, "", "maps", "array");
  for (std::size_t i = 0; i < maps.size(); ++i) {
    const std::string at = "maps[" + std::to_string(i) + "]";
    for (const char* k : {"mesh", "method", "precision", "image"}) need(f, maps[i], at, k, "string");
    for (const char* k : {"offset", "pixels", "surface_pixels", "leaks", "false_hits"})
      need(f, maps[i], at, k, "number");
    const fs::path img = d / maps[i]["image"].get<std::string>();
    if (!fs::is_regular_file(img))
      throw ra::InputError(f.string() + ": " + at + ": image " + img.string() + " is missing");
  }
}

void check_golden(const fs::path& f) {
  const json j = read_json(f);
  const json& ss = need(f, j, "", "scenes", "array");
  for (std::size_t i = 0; i < ss.size(); ++i)
    for (const char* k : {"name", "status", "message"})
      need(f, ss[i], "scenes[" + std::to_string(i) + "]", k, "string");
}

// ci/main.sh's stage timings: one "NAME<TAB>SECONDS" a line.
void check_stages(const fs::path& f) {
  std::istringstream in(read_file(f));
  std::string line;
  for (int n = 1; ra::read_text_line(in, line); ++n) {  // \n, \r\n or a lone \r, as the page's Python reads it
    if (line.empty()) continue;
    const auto tab = line.rfind('\t');
    char* end = nullptr;
    double seconds = 0;
    if (tab != std::string::npos) seconds = std::strtod(line.c_str() + tab + 1, &end);
    // A NUL ends strtod's view early (the script then failed with a
    // traceback): the whole field must be the number.
    if (tab == std::string::npos || tab == 0 || !end || end != line.c_str() + line.size() ||
        end == line.c_str() + tab + 1)
      throw ra::InputError(ra::located(f.string(), n, "expected STAGE<TAB>SECONDS"));
    // Decimal only: strtod also takes C99 hex ("0x10"), which the page's
    // Python float() refuses.
    if (line.find_first_not_of("0123456789.eE+-", tab + 1) != std::string::npos)
      throw ra::InputError(
          ra::located(f.string(), n, "seconds '" + line.substr(tab + 1, 40) + "' is not a decimal number"));
    // nan, a negative time or 1e400 (inf) were drawn as given.
    if (!std::isfinite(seconds) || seconds < 0)
      throw ra::InputError(ra::located(f.string(), n, "seconds must be a finite number >= 0"));
  }
}

json methods_json() {
  json out = json::array();
  for (const auto& m : ra::methods())
    out.push_back({{"name", m.name},
                   {"kind", std::string(ra::kind_name(m.kind))},
                   {"source", m.source},
                   {"description", m.description},
                   {"wrong_on_purpose", m.wrong_on_purpose}});
  return out;
}

std::string absolute(const std::string& p) { return p.empty() ? p : fs::absolute(p).lexically_normal().string(); }

std::string hex_bytes(const std::string& s) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (unsigned char c : s) out += digits[c >> 4], out += digits[c & 15];
  return out;
}

// Runs the page script; its stderr passes through. Returns its exit status.
int run_script(const fs::path& ctx) {
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("report: cannot start " + python());
  if (pid == 0) {
    const std::string py = python(), sc = script().string(), c = ctx.string();
    // Matplotlib's cache beside the context (a read-only home printed a
    // warning line on stderr).
    ::setenv("MPLCONFIGDIR", ctx.parent_path().c_str(), 1);
    execl(py.c_str(), py.c_str(), sc.c_str(), c.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

void run(const Args& a) {
  // Every input and destination is checked before anything is drawn.
  const fs::path dir(a.out);
  if (fs::exists(dir) && !fs::is_directory(dir)) throw ra::InputError(a.out + ": exists and is not a directory");
  if (!fs::is_directory(fs::absolute(dir).parent_path()))
    throw ra::InputError(a.out + ": its parent directory does not exist");
  if (!fs::exists(dir) && ::access(fs::absolute(dir).parent_path().c_str(), W_OK) != 0)
    throw ra::InputError(ra::located(a.out, 0, std::string("cannot create the directory: ") + std::strerror(errno)));
  // Either alone makes a page: the audits' correctness, or (a
  // performance-only report) the benchmarks'.
  if (a.audits.empty() && a.bench.empty())
    throw ra::InputError("rayaudit report: needs --audit FILE, --bench FILE, or both");
  if (!a.audits.empty()) check_audits(a.audits);
  if (!a.timings.empty()) check_timings(a.timings);
  for (const auto& b : a.bench) check_bench(b);
  for (const auto& d : a.compare) check_compare_dir(d);
  if (!a.crack_maps.empty()) check_crack_maps(a.crack_maps);
  if (!a.golden.empty()) check_golden(a.golden);
  if (!a.stages.empty()) check_stages(a.stages);
  if (access(python().c_str(), X_OK) != 0)
    throw ra::InputError(python() + ": not found (the report needs Debian's python3-matplotlib; ci/install-deps.sh)");
  if (!fs::is_regular_file(script())) throw ra::InputError(script().string() + ": the report script is missing");
  // An existing directory's outputs are declared now: one that is an input
  // (`--audit rep/report.json -o rep`) is refused before the script runs.
  std::optional<ra::OutputBatch> early;
  if (fs::is_directory(dir)) early.emplace(std::vector<fs::path>{dir / "index.html", dir / "report.json"});

  char tmpl[] = "/tmp/rayaudit-report-XXXXXX";
  if (!mkdtemp(tmpl)) throw std::runtime_error("report: cannot make a temporary directory");
  const fs::path tmp(tmpl);
  struct Cleanup {
    fs::path p;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(p, ec);
    }
  } cleanup{tmp};
  json compare = json::array();
  for (const auto& d : a.compare) compare.push_back(absolute(d));
  json benches = json::array();
  for (const auto& b : a.bench) benches.push_back(absolute(b));
  json audits = json::array(), audits_hex = json::array();
  for (const auto& f : a.audits) audits.push_back(absolute(f)), audits_hex.push_back(hex_bytes(absolute(f)));
  json ctx = {{"audit", a.audit.empty() ? json(nullptr) : json(absolute(a.audit))},
              {"audits", audits},
              {"timings", a.timings.empty() ? json(nullptr) : json(absolute(a.timings))},
              {"bench", benches},
              {"compare", compare},
              {"crack_maps", a.crack_maps.empty() ? json(nullptr) : json(absolute(a.crack_maps))},
              {"golden", a.golden.empty() ? json(nullptr) : json(absolute(a.golden))},
              {"stages", a.stages.empty() ? json(nullptr) : json(absolute(a.stages))},
              {"methods", methods_json()},
              {"source_dir", RAYAUDIT_SOURCE_DIR},
              {"build",
               {{"compiler", RAYAUDIT_COMPILER},
                {"flags", RAYAUDIT_CXX_FLAGS},
                {"build_type", RAYAUDIT_BUILD_TYPE},
                {"version", std::string("rayaudit ") + RAYAUDIT_VERSION}}},
              {"out_dir", tmp.string()}};
  // JSON strings are UTF-8, file names are bytes: the paths again, as hex
  // of their bytes, which the script decodes with os.fsdecode
  // (a Latin-1 directory name could not be opened from the context).
  json fs_paths = json::object();
  for (const char* k : {"audit", "crack_maps", "golden", "stages", "out_dir"})
    if (ctx.at(k).is_string())
      fs_paths[k] = hex_bytes(k == std::string("out_dir")      ? tmp.string()
                              : k == std::string("audit")      ? absolute(a.audit)
                              : k == std::string("crack_maps") ? absolute(a.crack_maps)
                              : k == std::string("golden")     ? absolute(a.golden)
                                                               : absolute(a.stages));
  json cmp_hex = json::array();
  for (const auto& d : a.compare) cmp_hex.push_back(hex_bytes(absolute(d)));
  fs_paths["compare"] = cmp_hex;
  json bench_hex = json::array();
  for (const auto& b : a.bench) bench_hex.push_back(hex_bytes(absolute(b)));
  fs_paths["bench"] = bench_hex;
  fs_paths["audits"] = audits_hex;
  if (!a.timings.empty()) fs_paths["timings"] = hex_bytes(absolute(a.timings));
  ctx["fs_paths"] = fs_paths;
  std::ofstream(tmp / "context.json") << ctx.dump(1, ' ', false, nlohmann::json::error_handler_t::replace);
  const int rc = run_script(tmp / "context.json");
  // 2: the script named the bad input in one line itself (an image PIL
  // cannot read, too large to show); nothing more to say.
  if (rc == 2) throw ra::cli::ExitCode{2};
  if (rc != 0) throw std::runtime_error("report: " + script().string() + " failed (exit " + std::to_string(rc) + ")");
  const std::string page = read_file(tmp / "index.html"), data = read_file(tmp / "report.json");

  std::error_code ec;
  const bool made_dir = !fs::exists(dir, ec);
  fs::create_directories(dir, ec);
  if (ec) throw ra::InputError(ra::located(a.out, 0, "cannot create the directory: " + ec.message()));
  struct RemoveIfFailed {
    fs::path dir;
    bool armed;
    ~RemoveIfFailed() {
      std::error_code e;
      if (armed) fs::remove(dir, e);  // only if empty: nothing of ours is left in it
    }
  } undo{dir, made_dir};
  if (!early) early.emplace(std::vector<fs::path>{dir / "index.html", dir / "report.json"});
  ra::write_text_atomically(dir / "index.html", page);
  ra::write_text_atomically(dir / "report.json", data);
  early->commit();
  undo.armed = false;
  std::cout << "wrote " << (dir / "index.html").string() << " (" << page.size() / 1024 << " KiB) and "
            << (dir / "report.json").string() << "\n";
}

void setup(CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("report",
                                 "One self-contained HTML page (and report.json) from earlier outputs: speed against "
                                 "accuracy, stability, crack maps, optimisations, peers, images");
  cmd->add_option("--audit", a->audits,
                  "rayaudit audit --json output (repeat for users' graded (--grade) or API runs of the same seed "
                  "and rays, drawn beside the registry; without it: a performance-only report)");
  cmd->add_option("--timings", a->timings,
                  "CSV subject,ns_per_test timing users' subjects as the kernel/ rows are (validation/baseline/"
                  "timing.h), for the speed chart");
  cmd->add_option("--bench", a->bench,
                  "rayaudit bench --json output (repeatable: several runs are combined, each row the median of "
                  "their medians, runs whose calibration was slow left out and named)");
  cmd->add_option("--compare", a->compare,
                  "Directory of rayaudit compare --json outputs, with NAME-ours.png, NAME-pov.png, NAME-diff.png "
                  "beside them (repeatable)");
  cmd->add_option("--crack-maps", a->crack_maps, "Directory written by rayaudit crack-maps");
  cmd->add_option("--golden", a->golden, "rayaudit golden check --json output");
  cmd->add_option("--stages", a->stages, "Stage timings (STAGE<TAB>SECONDS lines, as ci/main.sh writes)");
  cmd->add_option("-o,--out", a->out, "Directory for index.html and report.json")->required();
  cmd->callback([a] {
    if (!a->audits.empty()) a->audit = a->audits.front();
    run(*a);
  });
}

ra::cli::Registrar reg(90, setup);

}  // namespace
