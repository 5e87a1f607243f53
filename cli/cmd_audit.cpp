// `rayaudit audit`: grades the registry's methods against the exact oracle
// (validation/exact/audit.h) over generated families (whole or one --shard), user cases (--cases),
// answers from any language (--grade), exports cases (--export-cases), merges shards (audit merge).
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cerrno>
#include <map>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "baseline/gate.h"
#include "baseline/stamp.h"
#include "exact/audit.h"
#include "exact/cases_csv.h"
#include "command.h"
#include "errors.h"
#include "io/file_identity.h"
#include "exact/grade.h"
#include "io/input_file.h"
#include "io/json_input.h"
#include "peers.h"
#include "registry.h"
#include "tracers/tracers.h"

namespace {

using ra::cli::split_list;

using namespace ra::audit;

// Memory does not grow with --rays (chunks are numbered, not listed), so the
// bound is time: 1e10 rays per family is ~30 hours of the full registry on 2
// cores, what a release sign-off spreads over a CI matrix with --shard.
constexpr long long kMaxRays = 10000000000LL;
constexpr long long kMaxExportRays = 10000000;

struct Args {
  std::string methods, precision = "float,double", families, json, csv, cases, export_cases, grade, shard;
  std::string numbers = "hex";       // --export-cases: hex or decimal
  std::string tracers;               // --tracers: whole tracers on closed meshes (validation/tracers)
  long long tracer_rays = 2000;      // --tracer-rays: per shape, placement and scale
  std::string ids, baseline, junit;  // --ids (replay), --baseline BASE.json, --junit FILE
  long long rays = 200000;           // about 10 s for the full registry on 2 cores
  std::uint64_t seed = 1;
  int threads = 0;
  std::vector<std::string> merge_inputs;
  bool precision_given = false;  // --precision on the command line (not the default)
};

// "K/N" with 1 <= K <= N <= kMaxShards, or an error message.
std::string parse_shard(const std::string& text, Shard& out) {
  const auto slash = text.find('/');
  auto whole = [](const std::string& s, std::uint64_t& v) {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return false;
    v = std::stoull(s);
    return true;
  };
  if (slash == std::string::npos || !whole(text.substr(0, slash), out.k) || !whole(text.substr(slash + 1), out.n) ||
      out.k < 1 || out.k > out.n || out.n > kMaxShards)
    return "'" + text + "' is not K/N with 1 <= K <= N <= " + std::to_string(kMaxShards) +
           " (e.g. 2/8: the second of eight)";
  return {};
}

// --methods: the registry's methods and the peers (validation/peers), by
// name, or `peers` (every peer in this build) and `all` (every method and
// peer); none given: every registry method. A peer named but not built is
// an error saying how to get it; one reached through all/peers is skipped
// with a note on stderr.
struct Chosen {
  std::vector<const ra::Method*> methods;
  std::vector<const ra::peers::Peer*> peers;
  std::vector<bool> peer_named;  // per peer: named itself (not through all/peers)
};

Chosen chosen_subjects(const std::string& list) {
  Chosen out;
  auto add_method = [&](const ra::Method* m) {
    if (std::find(out.methods.begin(), out.methods.end(), m) == out.methods.end()) out.methods.push_back(m);
  };
  auto add_peer = [&](const ra::peers::Peer* p, bool named) {
    const auto it = std::find(out.peers.begin(), out.peers.end(), p);
    if (it != out.peers.end()) {
      if (named) out.peer_named[std::size_t(it - out.peers.begin())] = true;
      return;
    }
    if (!p->make) {
      if (named) throw ra::InputError("audit: peer '" + p->name + "' is not in this build: " + p->missing);
      std::fprintf(stderr, "audit: skipping peer %s: not in this build (%s)\n", p->name.c_str(), p->missing.c_str());
      return;
    }
    out.peers.push_back(p);
    out.peer_named.push_back(named);
  };
  if (list.empty()) {
    for (const auto& m : ra::methods())
      if (m.kind != ra::Kind::plane) add_method(&m);
    return out;
  }
  for (const auto& name : split_list(list, "--methods")) {
    if (name == "all" || name == "peers") {
      if (name == "all")
        for (const auto& m : ra::methods())
          if (m.kind != ra::Kind::plane) add_method(&m);
      for (const auto& p : ra::peers::peers()) add_peer(&p, false);
      continue;
    }
    if (const ra::peers::Peer* p = ra::peers::find_peer(name)) {
      add_peer(p, true);
      continue;
    }
    const ra::Method* m = ra::find_method(name);
    if (!m)
      throw ra::InputError("audit: unknown method '" + name + "' (triangle: " + ra::method_names(ra::Kind::triangle) +
                           "; sphere: " + ra::method_names(ra::Kind::sphere) + "; peers: " + ra::peers::peer_names() +
                           "; or all, peers)");
    if (m->kind == ra::Kind::plane)
      throw ra::InputError("audit: '" + name + "' is a plane method; the audit grades triangles and spheres");
    add_method(m);
  }
  return out;
}

// The registry's methods only (--cases grades them on given cases).
std::vector<const ra::Method*> chosen_methods(const std::string& list) {
  Chosen c = chosen_subjects(list);
  if (!c.peers.empty())
    throw ra::InputError("audit: --cases grades the registry's methods; peers (" + c.peers[0]->name +
                         ") are graded on generated cases, or through --export-cases and --grade");
  return c.methods;
}

std::vector<Precision> chosen_precisions(const std::string& list) {
  std::vector<Precision> out;
  for (const auto& p : split_list(list, "--precision")) {
    if (p == "float")
      out.push_back(Precision::f32);
    else if (p == "double")
      out.push_back(Precision::f64);
    else
      throw ra::InputError("audit: unknown precision '" + p + "' (float, double)");
  }
  if (out.empty()) throw ra::InputError("audit: --precision needs float and/or double");
  return out;
}

std::vector<std::string> chosen_families(const std::string& list) {
  const auto names = split_list(list, "--families");
  for (const auto& n : names)
    if (!find_family(n)) throw ra::InputError("audit: unknown family '" + n + "' (" + family_names() + ")");
  return names;
}

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& x : v) out += (out.empty() ? "" : ",") + x;
  return out;
}

// --ids: a case is chosen by its id, or by its ray's FAMILY:SWEEP:PROBE
// (the ids failures name; an export id adds :K, the triangle of the group).
struct IdFilter {
  std::vector<std::string> wanted;
  std::vector<char> matched;
  explicit IdFilter(const std::string& list) : wanted(split_list(list, "--ids")), matched(wanted.size(), 0) {}
  bool all() const { return wanted.empty(); }
  bool take(const std::string& id) {
    if (wanted.empty()) return true;
    const auto colon = id.rfind(':');
    bool hit = false;
    for (std::size_t i = 0; i < wanted.size(); ++i)
      if (wanted[i] == id || (colon != std::string::npos && wanted[i] == id.substr(0, colon)))
        hit = true, matched[i] = 1;
    return hit;
  }
  // The first id no case had, as the one-line refusal.
  void check(const std::string& file) const {
    for (std::size_t i = 0; i < wanted.size(); ++i)
      if (!matched[i]) throw ra::InputError("--ids: '" + wanted[i] + "' is not a case of " + file);
  }
};

// 1234567 -> "1.23M": counts and rates at a glance.
std::string si(double v) {
  const char* unit[] = {"", "k", "M", "G", "T"};
  int u = 0;
  while (v >= 999.5 && u < 4) v /= 1000, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, u ? "%.3g%s" : "%.0f%s", v, unit[u]);
  return buf;
}
std::string duration(double s) {
  if (!std::isfinite(s)) return "?";
  const long long t = (long long)std::llround(s);
  char buf[48];
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%lldh%02lldm", t / 3600, t / 60 % 60);
  else if (t >= 60)
    std::snprintf(buf, sizeof buf, "%lldm%02llds", t / 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%llds", t);
  return buf;
}

// Progress on stderr with rays/s and ETA: a bar redrawn in place on a
// terminal (4 times a second), else a plain line every 10 s, so CI logs show
// a long audit is alive while runs shorter than that stay silent.
std::function<void(std::uint64_t, std::uint64_t)> progress_reporter() {
  using clock = std::chrono::steady_clock;
  struct State {
    bool tty;
    clock::time_point start, last;
    bool printed = false;
  };
  auto st = std::make_shared<State>(State{isatty(STDERR_FILENO) != 0, clock::now(), clock::now()});
  return [st](std::uint64_t done, std::uint64_t total) {
    const auto now = clock::now();
    const bool finished = done >= total;
    const double period = st->tty ? 0.25 : 10.0;
    if (!finished && std::chrono::duration<double>(now - st->last).count() < period) return;
    if (finished && !st->printed) return;
    st->last = now;
    st->printed = true;
    const double elapsed = std::chrono::duration<double>(now - st->start).count();
    const double rate = elapsed > 0 ? double(done) / elapsed : 0;
    const double frac = total ? double(done) / double(total) : 1;
    const std::string eta = finished ? "done in " + duration(elapsed)
                                     : "ETA " + duration(rate > 0 ? double(total - done) / rate : INFINITY);
    if (st->tty) {
      const int width = 30, filled = int(double(width) * frac);
      std::fprintf(stderr, "\r[%s%s] %5.1f%% %s/%s rays  %s rays/s  %s   ",
                   std::string(std::size_t(filled), '#').c_str(), std::string(std::size_t(width - filled), ' ').c_str(),
                   100 * frac, si(double(done)).c_str(), si(double(total)).c_str(), si(rate).c_str(), eta.c_str());
      if (finished) std::fprintf(stderr, "\n");
    } else {
      std::fprintf(stderr, "audit: %5.1f%% %llu/%llu rays, %s rays/s, %s\n", 100 * frac, (unsigned long long)done,
                   (unsigned long long)total, si(rate).c_str(), eta.c_str());
    }
    std::fflush(stderr);
  };
}

// ---------------------------------------------------------- --cases ---
nlohmann::json t_json(double t) { return std::isfinite(t) ? nlohmann::json(t) : nlohmann::json(nullptr); }

// Streams the cases (memory independent of the number of rows):
// a first pass validates the whole file, so bad input prints and writes
// nothing; the second grades row by row, printing the table and writing the
// JSON (byte for byte what nlohmann's dump(2) of the whole document gives).
void audit_cases(const Args& a) {
  if (!a.csv.empty())
    throw ra::InputError("audit: --csv writes per-family rows, which --cases has none of; use --json");
  ra::OutputBatch outputs({a.json});
  IdFilter ids(a.ids);
  for_each_case(a.cases, [&](const UserCase& c, long) { ids.take(c.id); });  // throws before anything is written
  ids.check(a.cases);
  std::vector<const ra::Method*> tri_methods;
  for (const ra::Method* m : chosen_methods(a.methods))
    if (m->kind == ra::Kind::triangle) tri_methods.push_back(m);
  const auto ps = chosen_precisions(a.precision);
  const char* columns = ps.size() == 2 ? "float dbl" : ps[0] == Precision::f32 ? "float" : "dbl";
  auto grade_all = [&](std::ostream* json) {
    std::printf("%-16s %-10s %-24s", "ID", "VERDICT", "T (exact)");
    for (const auto* m : tri_methods) std::printf(" %-11.11s", m->name.c_str());
    std::printf("\n%-16s %-10s %-24s", "", "", "");
    for (std::size_t i = 0; i < tri_methods.size(); ++i) std::printf(" %-11s", columns);
    std::printf("\n");
    long wrong = 0, n = 0;
    // Rows of one exported ray (FAMILY:SWEEP:PROBE:K): a method that hits
    // none of them where the exact answer crosses one leaks there, which no
    // single row shows (each is a boundary case, never wrong alone).
    struct Group {
      std::string key;
      bool crossed[2] = {false, false};  // by precision: f32, f64
      std::map<std::string, bool> hit;   // METHOD/PRECISION -> any hit
    } group;
    auto end_group = [&] {
      for (const auto& [subject, any] : group.hit) {
        const bool f32 = subject.size() > 6 && subject.compare(subject.size() - 6, 6, "/float") == 0;
        if (!any && group.crossed[f32 ? 0 : 1])
          std::printf("  ray %s: %s hits none of its triangles where the exact answer crosses one: a leak\n",
                      group.key.c_str(), subject.c_str());
      }
      group = Group{};
    };
    for_each_case(a.cases, [&](const UserCase& c, long) {
      if (!ids.take(c.id)) return;
      const auto colon = c.id.rfind(':');
      const std::string key = std::count(c.id.begin(), c.id.end(), ':') == 3 ? c.id.substr(0, colon) : std::string();
      if (key != group.key) end_group(), group.key = key;
      const auto ans = ra::oracle::triangle(c.ray, c.tri.a, c.tri.b, c.tri.c);
      // Float answers are judged on the case rounded to float, what a float
      // method is given (the verdict can differ: a point 1 ulp off an edge
      // in double lies on it in float).
      const ra::Vec3f fa(c.tri.a), fb(c.tri.b), fc(c.tri.c);
      const ra::Rayf fray(c.ray);
      const auto ans_f = ra::oracle::triangle(ra::Rayd(fray), ra::Vec3d(fa), ra::Vec3d(fb), ra::Vec3d(fc));
      nlohmann::json answers = nlohmann::json::object();
      std::printf("%-16.16s %-10s %-24.17g", c.id.c_str(), std::string(ra::oracle::verdict_name(ans.verdict)).c_str(),
                  ans.t);
      for (const auto* m : tri_methods) {
        std::string cell;
        for (Precision p : {Precision::f32, Precision::f64}) {
          if (std::find(ps.begin(), ps.end(), p) == ps.end()) continue;
          std::optional<double> t;
          if (p == Precision::f32) {
            if (auto h = m->tri_f.hit(fray, fa, fb, fc, false)) t = double(h->t);
          } else if (auto h = m->tri_d.hit(c.ray, c.tri.a, c.tri.b, c.tri.c, false)) {
            t = h->t;
          }
          answers[m->name + "/" + precision_name(p)] = {{"hit", t.has_value()}, {"t", t ? t_json(*t) : nullptr}};
          // '!' marks an answer the exact verdict contradicts (boundary etc. never do).
          const auto verdict = p == Precision::f32 ? ans_f.verdict : ans.verdict;
          const auto& exact = p == Precision::f32 ? ans_f : ans;
          if (!key.empty()) {
            group.crossed[p == Precision::f32 ? 0 : 1] |=
                (verdict == ra::oracle::Verdict::hit || verdict == ra::oracle::Verdict::boundary) && exact.t > 0;
            group.hit[m->name + "/" + precision_name(p)] |= t.has_value();
          }
          const bool bad = (verdict == ra::oracle::Verdict::hit && !t) || (verdict == ra::oracle::Verdict::miss && t);
          wrong += bad;
          cell += std::string(t ? "hit" : "miss") + (bad ? "!" : "") + " ";
        }
        std::printf(" %-11s", cell.c_str());
      }
      std::printf("\n");
      if (json) {
        const nlohmann::json row = {{"id", c.id_is_row ? nlohmann::json(std::stol(c.id)) : nlohmann::json(c.id)},
                                    {"verdict", std::string(ra::oracle::verdict_name(ans.verdict))},
                                    {"t", t_json(ans.t)},
                                    {"answers", answers}};
        // An element of "cases" sits 4 spaces deep in the whole document.
        std::string text = row.dump(2, ' ', false, nlohmann::json::error_handler_t::replace), indented = "    ";
        for (char ch : text) {
          indented += ch;
          if (ch == '\n') indented += "    ";
        }
        *json << (n ? ",\n" : "\n") << indented;
      }
      ++n;
    });
    end_group();
    std::printf("%ld case(s); %ld answer(s) contradict the exact verdict (marked !)\n", n, wrong);
    return n;
  };
  if (a.json.empty()) {
    grade_all(nullptr);
  } else {
    ra::write_atomically(a.json, [&](const std::filesystem::path& tmp) {
      std::ofstream out(tmp, std::ios::binary);
      out << "{\n  \"cases\": [";
      out << (grade_all(&out) ? "\n  ]\n}\n" : "]\n}\n");
      out.close();
      if (!out) throw ra::InputError(ra::located(a.json, 0, "cannot write"));
    });
  }
  outputs.commit();
}

// ----------------------------------------------------------- --grade ---
void grade(const Args& a) {
  if (!a.methods.empty()) throw ra::InputError("audit: --grade grades the answers file, not --methods: drop --methods");
  if (!a.ids.empty())
    throw ra::InputError("audit: --grade grades every answer; --ids goes with --cases alone (to show cases)");
  ra::OutputBatch outputs({a.json, a.csv, a.junit});
  const std::optional<nlohmann::json> base =
      a.baseline.empty() ? std::nullopt : std::optional(ra::baseline::read_audit_json(a.baseline));
  const auto ps = chosen_precisions(a.precision);
  // One file of answers is one precision (as --export-cases).
  if (a.precision_given && ps.size() != 1)
    throw ra::InputError("--precision: --grade takes one precision (float or double), got '" + a.precision + "'");
  // The cases' stamp: which run they are (version, seed, rays, families)
  // and their precision, the default for the answers.
  const std::optional<CasesStamp> stamp = read_stamp(a.cases);
  if (stamp && stamp->version != RAYAUDIT_VERSION)
    throw ra::InputError(ra::located(a.cases, 1,
                                     "exported by rayaudit " + stamp->version + ", this is " + RAYAUDIT_VERSION +
                                         ": export the cases again with this version"));
  Precision p = Precision::f64;
  if (a.precision_given)
    p = ps[0];
  else if (stamp)
    p = stamp->precision == "float" ? Precision::f32 : Precision::f64;
  else if (answers_look_float(a.grade, a.cases))
    // Graded as double, float rounding would read as errors of 1e10 ulps.
    throw ra::InputError("audit: every t in " + a.grade + " and every coordinate of " + a.cases +
                         " is a float: give --precision float (or --precision double if your intersector "
                         "computes in double)");
  const std::string method = std::filesystem::path(a.grade).stem().string();
  Report rep = grade_answers(a.grade, a.cases, p, method.empty() ? "answers" : method);
  if (stamp) {
    rep.seed = stamp->seed;
    rep.rays = stamp->rays;
    for (const Cell& c : rep.cells)
      if (std::find(stamp->families.begin(), stamp->families.end(), c.family) == stamp->families.end())
        throw ra::InputError(ra::located(a.cases, 1,
                                         "the stamp lists the families " + join(stamp->families) +
                                             ", but rows of family '" + c.family + "' follow"));
  }
  std::fputs(rep.summary_table().c_str(), stdout);
  nlohmann::json j = rep.to_json();
  j["graded"] = {{"answers", a.grade}, {"cases", a.cases}};
  if (stamp)
    j["graded"]["stamp"] = {{"version", stamp->version},
                            {"seed", stamp->seed},
                            {"rays", stamp->rays},
                            {"precision", stamp->precision},
                            {"families", stamp->families}};
  const ra::baseline::GateResult g =
      ra::baseline::gate(j, base, {.baseline_name = a.baseline, .junit = a.junit, .suite = "rayaudit audit --grade"});
  if (!a.json.empty())
    ra::write_text_atomically(a.json, j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (!a.csv.empty()) ra::write_text_atomically(a.csv, rep.to_csv());
  outputs.commit();
  if (g.rose) throw ra::CheckFailed("audit: worse than the baseline " + a.baseline + " (the rows marked ROSE)");
}

// --------------------------------------------------- --export-cases ---
void export_cases(const Args& a) {
  if (!a.json.empty() || !a.csv.empty())
    throw ra::InputError("audit: --export-cases writes only the cases CSV; run the audit separately for --json/--csv");
  if (!a.methods.empty())
    throw ra::InputError("audit: --export-cases exports cases, not methods' answers: drop --methods");
  // The rows are streamed to the file (memory does not grow with --rays);
  // the limit bounds the file (about 350 bytes a case) and the time.
  if (a.rays > kMaxExportRays)
    throw ra::InputError("--rays: " + std::to_string(a.rays) + " is above the export's limit of " +
                         std::to_string(kMaxExportRays) + " cases per family (about 350 bytes each on disk)");
  const auto precisions = chosen_precisions(a.precision);
  // One file holds one precision's inputs (a list of two was
  // taken as double and the float half dropped silently).
  if (a.precision_given && precisions.size() != 1)
    throw ra::InputError("--precision: --export-cases takes one precision (float or double), got '" + a.precision +
                         "'");
  ra::declare_output(a.export_cases);
  // Exported inputs are double unless only float was asked for.
  const Precision p = precisions.size() == 1 ? precisions[0] : Precision::f64;
  auto fams = chosen_families(a.families);
  const ra::audit::Numbers numbers = a.numbers == "decimal" ? ra::audit::Numbers::decimal : ra::audit::Numbers::hex;
  // A family asked for by name is exported or refused by name (secondary
  // and the sphere families were skipped silently: exit 0 with edge only).
  for (const auto& name : fams) {
    const Family* f = find_family(name);
    if (f->kind != ra::Kind::triangle)
      throw ra::InputError("audit: --export-cases: '" + name +
                           "' is a sphere family; the cases CSV holds rays and triangles only");
    if (f->secondary)
      throw ra::InputError("audit: --export-cases: '" + name +
                           "' has no fixed cases (its rays start at each method's own hit point); audit it with "
                           "--families " +
                           name);
  }
  if (fams.empty())
    for (const Family& f : families())
      if (f.kind == ra::Kind::triangle && !f.secondary) fams.push_back(f.name);
  IdFilter ids(a.ids);
  CasesStamp stamp{RAYAUDIT_VERSION, a.seed, a.rays, precision_name(p), {}};
  for (const Family& f : families())  // the families' order, as the rows
    if (std::find(fams.begin(), fams.end(), f.name) != fams.end()) stamp.families.push_back(f.name);
  if (!ids.all()) {
    // A first pass: every id must name a case (nothing written otherwise).
    for_each_export_row(fams, p, a.seed, a.rays, [&](const ra::audit::ExportRow& r) { ids.take(r.id); });
    ids.check("the export (--families " + join(stamp.families) + ", --seed " + std::to_string(a.seed) + ", --rays " +
              std::to_string(a.rays) + ")");
  }
  long long rows = 0;
  ra::write_atomically(a.export_cases, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << stamp_line(stamp) << ra::audit::cases_csv_header();
    for_each_export_row(fams, p, a.seed, a.rays, [&](const ra::audit::ExportRow& r) {
      if (ids.take(r.id)) out << ra::audit::cases_csv_row(r, numbers), ++rows;
    });
    out.close();
    if (!out)
      throw ra::InputError(ra::located(a.export_cases, 0, std::string("cannot write: ") + std::strerror(errno)));
  });
  std::printf("wrote %lld %s cases to %s%s\n", rows, precision_name(p), a.export_cases.c_str(),
              numbers == ra::audit::Numbers::decimal ? " (decimal numbers)" : "");
}

// ------------------------------------------------------------ audit ---
void audit(const Args& a) {
  ra::OutputBatch outputs({a.json, a.csv, a.junit});
  if (!a.ids.empty()) throw ra::InputError("audit: --ids chooses cases of --cases or --export-cases");
  if (!a.shard.empty() && (!a.baseline.empty() || !a.junit.empty()))
    throw ra::InputError(std::string("audit: ") + (a.baseline.empty() ? "--junit" : "--baseline") +
                         " judges a whole run, not a shard's partial counts: merge the shards (audit merge), then "
                         "`rayaudit audit diff BASE.json MERGED.json`");
  std::optional<nlohmann::json> base;
  if (!a.baseline.empty()) {
    base = ra::baseline::read_audit_json(a.baseline);
    // Checked before the run: a mismatch found after an hour would waste it.
    try {
      ra::baseline::check_plan(*base, a.seed, a.rays);
    } catch (const ra::baseline::Mismatch& e) {
      throw ra::InputError(a.baseline + ": cannot be this run's baseline: " + e.what());
    }
  }
  // Whole tracers (--tracers): named before anything runs (an unknown name
  // lists the known ones); graded after the kernels, into the same JSON.
  std::vector<ra::tracers::Subject> tracer_subjects;
  if (!a.tracers.empty())
    for (const auto& name : split_list(a.tracers, "--tracers")) try {
        for (auto& s : ra::tracers::named(name)) tracer_subjects.push_back(std::move(s));
      } catch (const std::invalid_argument& e) {
        throw ra::InputError(std::string("audit: --tracers: ") + e.what());
      }
  const Chosen chosen = chosen_subjects(a.methods);
  const auto& ms = chosen.methods;
  const auto ps = chosen_precisions(a.precision);
  Options opt;
  opt.families = chosen_families(a.families);
  opt.rays = a.rays;
  opt.seed = a.seed;
  opt.threads = a.threads;
  opt.progress = progress_reporter();
  if (!a.shard.empty()) {
    Shard sh;
    if (const std::string bad = parse_shard(a.shard, sh); !bad.empty()) throw ra::InputError("--shard: " + bad);
    opt.shard = sh;
  }
  std::vector<TriangleSubject> tris;
  std::vector<SphereSubject> spheres;
  for (const ra::Method* m : ms)
    for (Precision p : ps) {
      if (m->kind == ra::Kind::triangle)
        tris.push_back(registry_triangle(*m, p));
      else
        spheres.push_back(registry_sphere(*m, p));
    }
  // A peer answers at its own precision only (Embree's API is float, CGAL's
  // Epick double): graded when --precision includes it.
  for (std::size_t i = 0; i < chosen.peers.size(); ++i) {
    const ra::peers::Peer& peer = *chosen.peers[i];
    if (std::find(ps.begin(), ps.end(), peer.precision) != ps.end()) {
      tris.push_back(ra::peers::subject(peer));
    } else if (chosen.peer_named[i]) {
      throw ra::InputError("audit: peer '" + peer.name + "' answers in " + precision_name(peer.precision) +
                           " only, which --precision " + a.precision + " leaves out");
    } else {
      std::fprintf(stderr, "audit: skipping peer %s: it answers in %s only (--precision %s)\n", peer.name.c_str(),
                   precision_name(peer.precision), a.precision.c_str());
    }
  }
  if (!a.families.empty()) {
    // A family graded by none of the chosen methods would be an empty table.
    for (const auto& name : opt.families) {
      // A name of both kinds (refracted) is graded by either kind of method.
      const auto named = ra::audit::families_named(name);
      const Family* f = named[0];
      const bool graded = std::any_of(named.begin(), named.end(), [&](const Family* g) {
        return g->kind == ra::Kind::triangle ? !tris.empty() : !spheres.empty();
      });
      if (!graded)
        throw ra::InputError("audit: family '" + name + "' is a " +
                             (f->kind == ra::Kind::triangle ? "triangle" : "sphere") + " family, but no " +
                             (f->kind == ra::Kind::triangle ? "triangle" : "sphere") + " method is chosen (--methods)");
    }
  }
  const Report rep = run(tris, spheres, opt);
  std::fputs(rep.summary_table().c_str(), stdout);
  if (opt.shard)
    std::printf("shard %s: partial counts; combine every shard's --json with `rayaudit audit merge`\n",
                a.shard.c_str());
  nlohmann::json out = rep.to_json();
  if (!tracer_subjects.empty()) {
    ra::tracers::Options to;
    to.rays = a.tracer_rays;
    to.seed = a.seed;
    const ra::tracers::Report tr = ra::tracers::run(tracer_subjects, to);
    std::fputs(tr.summary_table().c_str(), stdout);
    out["tracers"] = tr.to_json();
  }
  // The failing families' case ids and replay commands: for a few subjects
  // (a user's --methods), not the whole registry's documented failures.
  ra::baseline::GateResult g;
  if (!opt.shard)
    g = ra::baseline::gate(out, base,
                           {.baseline_name = a.baseline, .junit = a.junit, .failure_lines = rep.subjects.size() <= 4});
  if (!a.json.empty())
    ra::write_text_atomically(a.json, out.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (!a.csv.empty()) ra::write_text_atomically(a.csv, rep.to_csv());
  outputs.commit();
  if (g.rose) throw ra::CheckFailed("audit: worse than the baseline " + a.baseline + " (the rows marked ROSE)");
}

// ------------------------------------------------------------ merge ---
// One shard as merge needs it: its report and what must agree between the
// shards of one run; the parsed JSON is dropped once read, and shards are
// read one at a time (every shard's JSON was held at ~30x its
// size; 191 MB ended in a bare std::bad_alloc).
struct ShardFile {
  std::string path;
  std::string version;
  std::vector<std::pair<std::string, std::string>> identity;
  Report report;
};

// A full audit's shard is about 1 MB (1,232 cells at 2 shards); the limit
// leaves room for user subjects while keeping a merge in hundreds of MB.
constexpr std::uintmax_t kMaxShardBytes = 8u << 20;

// What must agree between shards of one run, as "name: value" texts.
std::vector<std::pair<std::string, std::string>> run_identity(const nlohmann::json& json, const Report& report) {
  std::string cells;
  for (const auto& c : json["cells"])
    cells += c.value("subject", "") + "|" + c.value("family", "") + "|" + c.value("sweep", "") + ";";
  std::string methods;
  for (const auto& s : report.subjects) methods += (methods.empty() ? "" : ",") + s;
  return {{"version", json.value("version", "(none)")},
          {"seed", std::to_string(report.seed)},
          {"rays per family", std::to_string(report.rays)},
          {"methods", methods},
          {"families", cells},
          {"shard count", std::to_string(report.shard->n)}};
}

ShardFile read_shard(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxShardBytes)
    throw ra::InputError(ra::located(path, 0,
                                     std::to_string(size >> 20) + " MB is larger than a shard can be (at most " +
                                         std::to_string(kMaxShardBytes >> 20) +
                                         " MB; a full audit's shard is about 1 MB)"));
  // read_json_file: a directory or FIFO named, not read or waited on; a
  // syntax error at its line; a key given twice refused.
  const nlohmann::json json = ra::read_json_file(path);
  if (!json.is_object() || !json.contains("shard"))
    throw ra::InputError(ra::located(path, 0, "not a shard's output (no \"shard\" key: run audit with --shard K/N)"));
  ShardFile f{path, "", {}, {}};
  try {
    f.report = Report::from_json(json);
    f.identity = run_identity(json, f.report);
    f.version = json.value("version", "(unknown)");
  } catch (const ra::InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw ra::InputError(ra::located(path, 0, ra::json_error_text(e)));  // no "[json.exception...]" prefix
  }
  return f;
}

void merge(const Args& a) {
  if (a.json.empty()) throw ra::InputError("audit merge: --json OUT is required");
  ra::OutputBatch outputs({a.json, a.csv});
  // The first shard read in full; each later one checked against it and
  // added to the sum, then dropped.
  const ShardFile first = read_shard(a.merge_inputs[0]);
  if (first.version != RAYAUDIT_VERSION)
    throw ra::InputError(ra::located(
        first.path, 0,
        "written by rayaudit " + first.version + "; merge with that version (this is " + RAYAUDIT_VERSION + ")"));
  // Shards by k in a map, not a table of n entries (n = 4e9 was a bad_alloc).
  const std::uint64_t n = first.report.shard->n;
  std::map<std::uint64_t, std::string> by_k;
  Report rep = first.report;
  rep.shard.reset();
  for (std::size_t i = 0; i < a.merge_inputs.size(); ++i) {
    const ShardFile later = i ? read_shard(a.merge_inputs[i]) : ShardFile{};
    const ShardFile& f = i ? later : first;
    for (std::size_t k = 0; k < f.identity.size(); ++k)
      if (f.identity[k].second != first.identity[k].second) {
        std::string mine = f.identity[k].second, theirs = first.identity[k].second;
        if (mine.size() > 60 || theirs.size() > 60) mine = theirs = "";  // the lists: just say they differ
        throw ra::InputError(ra::located("audit merge", 0,
                                         f.path + " and " + first.path +
                                             " are shards of different runs: " + f.identity[k].first +
                                             (mine.empty() ? " differ" : " " + mine + " vs " + theirs)));
      }
    const std::uint64_t k = f.report.shard->k;
    if (k < 1 || k > n) throw ra::InputError(ra::located(f.path, 0, "shard k out of range 1..n"));
    if (by_k.count(k))
      throw ra::InputError("audit merge: " + f.path + " and " + by_k[k] + " are both shard " + std::to_string(k) + "/" +
                           std::to_string(n));
    by_k[k] = f.path;
    if (i) try {
        for (std::size_t c = 0; c < rep.cells.size(); ++c) rep.cells[c].stats.merge(f.report.cells[c].stats);
      } catch (const std::overflow_error& e) {
        throw ra::InputError(ra::located(f.path, 0, e.what()));
      }
  }
  // The first k missing (at most files + 1 steps, whatever n says).
  for (std::uint64_t k = 1; k <= n; ++k)
    if (!by_k.count(k))
      throw ra::InputError("audit merge: shard " + std::to_string(k) + "/" + std::to_string(n) + " is missing (" +
                           std::to_string(a.merge_inputs.size()) + " file(s) given, the first " + first.path + ")");
  std::fputs(rep.summary_table().c_str(), stdout);
  ra::write_text_atomically(a.json, rep.to_json().dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (!a.csv.empty()) ra::write_text_atomically(a.csv, rep.to_csv());
  outputs.commit();
}

void setup(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "audit", "Grade intersection methods against exact arithmetic (CGAL/GMP) on generated or given cases");
  auto a = std::make_shared<Args>();
  cmd->add_option("--methods", a->methods,
                  "Comma-separated methods and peers (embree, embree-robust, cgal-epick, pov-mesh2), or all, peers "
                  "(default: every triangle and sphere method)")
      ->check(ra::cli::non_empty_list());
  cmd->add_option("--precision", a->precision, "float, double or both")
      ->capture_default_str()
      ->check(ra::cli::non_empty_list());
  cmd->add_option("--families", a->families, "Comma-separated families (default all): " + family_names())
      ->check(ra::cli::non_empty_list());
  cmd->add_option("--rays", a->rays,
                  "Ray/primitive tests per family per method and precision (a ray against a fan of 6 counts 6)")
      ->capture_default_str()
      ->transform(CLI::Validator(
          [](std::string& v) -> std::string {
            // Digits, or digits 'e' digits (1e6: as the limit is written).
            const std::size_t e = v.find_first_of("eE");
            const std::string mant = v.substr(0, e), ex = e == std::string::npos ? "" : v.substr(e + 1);
            auto digits = [](const std::string& x) {
              return !x.empty() && x.size() <= 18 && x.find_first_not_of("0123456789") == std::string::npos;
            };
            if (!digits(mant) || (e != std::string::npos && !digits(ex)))
              return "'" + v + "' is not a whole number of rays";
            long double n = std::stold(mant);
            for (long long k = e == std::string::npos ? 0 : std::stoll(ex); k > 0 && n <= kMaxRays; --k) n *= 10;
            if (n < 1) return "at least 1 ray";
            if (n > kMaxRays)
              return v +
                     " is above the limit of 10000000000 (1e10) rays per family, about 30 hours of every "
                     "method on 2 cores; spread a run that size over machines with --shard K/N";
            v = std::to_string((long long)n);  // what the option then holds: 1e6 as 1000000
            return {};
          },
          "1 to 1e10"));
  cmd->add_option("--seed", a->seed, "Seed of every generated case")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& v) {
            // CLI11 would saturate 2^64 and beyond to 2^64-1: out of range is an error.
            std::uint64_t x = 0;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
            if (ec == std::errc::result_out_of_range)
              return std::string("the seed is at most 18446744073709551615 (2^64-1)");
            if (ec != std::errc() || end != v.data() + v.size())
              return std::string("the seed is a non-negative integer");
            return std::string();
          },
          "UINT64"));
  cmd->add_option("--threads", a->threads, "Worker threads (0: all cores); results do not depend on it")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--json", a->json, "Write every count to this JSON file");
  cmd->add_option("--tracers", a->tracers,
                  "Also grade whole tracers on closed meshes placed out to 1e7 and scaled 1e-4..1e4 (the JSON's "
                  "\"tracers\"): " +
                      ra::tracers::known_names());
  cmd->add_option("--tracer-rays", a->tracer_rays,
                  "Rays per closed mesh, placement and scale for --tracers (default 2000)")
      ->check(CLI::Range(2LL, 100000000LL));
  cmd->add_option("--csv", a->csv, "Write one row per method x precision x family x sweep value");
  auto* cases = cmd->add_option("--cases", a->cases,
                                "Audit the cases of this CSV (columns ox..cz, optional id) instead of generating");
  auto* exp =
      cmd->add_option("--export-cases", a->export_cases,
                      "Write the generated cases with exact verdicts as a CSV (C99 hex floats, or --numbers decimal)")
          ->excludes(cases);
  cmd->add_option("--numbers", a->numbers,
                  "--export-cases writes numbers as C99 hex floats (hex) or as the shortest decimals that read back "
                  "exactly (decimal: for languages without hex floats)")
      ->capture_default_str()
      ->check(CLI::IsMember({"hex", "decimal"}))
      ->needs(exp);
  cmd->add_option("--grade", a->grade,
                  "Grade answers from your own intersector (CSV id,hit,t[,u,v], one row per case of --cases)")
      ->needs(cases);
  auto* shard = cmd->add_option("--shard", a->shard,
                                "Judge shard K of N (e.g. 2/8): the same 1/N of every family's rays for any "
                                "thread count; combine the --json of all N with `audit merge`")
                    ->excludes(cases)
                    ->excludes(exp);
  (void)shard;
  cmd->add_option("--ids", a->ids,
                  "With --cases or --export-cases: only these case ids (or FAMILY:SWEEP:PROBE, every triangle of "
                  "that ray), as a failing family names them")
      ->check(ra::cli::non_empty_list());
  cmd->add_option("--baseline", a->baseline,
                  "Compare with this earlier audit's --json (same version, seed, --rays, families): exit 1 if any "
                  "wrong count, leaks, double hits, NaN answers or t error rose");
  cmd->add_option("--junit", a->junit, "Write JUnit XML: one test case per method x precision x family");
  auto* merge_cmd = cmd->add_subcommand(
      "merge", "Combine the --json outputs of every shard of one audit into what the unsharded run writes");
  merge_cmd->add_option("shards", a->merge_inputs, "The shards' JSON files (audit --shard K/N --json)")->required();
  merge_cmd->add_option("--json", a->json, "Write the merged JSON here")->required();
  merge_cmd->add_option("--csv", a->csv, "Write the merged per-cell CSV here");
  merge_cmd->callback([a] { merge(*a); });
  cmd->callback([a, cmd] {
    if (!cmd->get_subcommands().empty()) return;  // merge, diff: their own callbacks
    if (!a->cases.empty() && a->grade.empty() && (!a->baseline.empty() || !a->junit.empty()))
      throw ra::InputError("audit: --baseline and --junit judge an audit of families or --grade, not --cases");
    if (!a->export_cases.empty() && (!a->baseline.empty() || !a->junit.empty()))
      throw ra::InputError("audit: --export-cases writes only the cases CSV: drop --baseline/--junit");
    a->precision_given = cmd->count("--precision") > 0;
    // Whole tracers are graded on their own generated meshes beside a full
    // (unsharded) audit; with given cases, an export or a shard they would be
    // silently left out, or graded once per shard and lost by the merge.
    if (cmd->count("--tracer-rays") && a->tracers.empty())
      throw ra::InputError("audit: --tracer-rays sets the rays of --tracers: add --tracers NAMES or drop it");
    if (!a->tracers.empty())
      for (const auto& [opt, given] : {std::pair<const char*, bool>{"--cases", !a->cases.empty()},
                                       {"--export-cases", !a->export_cases.empty()},
                                       {"--shard", !a->shard.empty()}})
        if (given)
          throw ra::InputError(std::string("audit: --tracers grades whole tracers in an audit of generated "
                                           "families, unsharded; it does not go with ") +
                               opt + ": run it separately");
    // Given cases are not generated: the generator's options would be ignored.
    if (!a->cases.empty())
      for (const char* opt : {"--rays", "--seed", "--families"})
        if (cmd->count(opt))
          throw ra::InputError(std::string("audit: ") + opt + " chooses generated cases; " +
                               (a->grade.empty() ? "--cases" : "--grade") + " takes the cases of " + a->cases +
                               ": drop " + opt);
    if (!a->grade.empty()) return grade(*a);
    if (!a->cases.empty()) return audit_cases(*a);
    if (!a->export_cases.empty()) return export_cases(*a);
    audit(*a);
  });
}

ra::cli::Registrar reg(30, setup);

}  // namespace
