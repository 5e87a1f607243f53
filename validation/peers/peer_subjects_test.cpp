// The peers as audit subjects (peers.h), through the real rayaudit: what the
// audit reports for each peer agrees, cell for cell, with grading the same
// peer's answers to the exported cases through --grade; peers are marked in
// the JSON, CSV and table; bad --methods lists are refused whole.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "exact/cases_csv.h"
#include "peers.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rayaudit-peers-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::string hex(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", x);
  return buf;
}

// The peer's answer to every case of `cases`, as an --grade answers file.
void answer(const ra::peers::Peer& peer, const fs::path& cases, const fs::path& out) {
  const ra::audit::TriangleSubject s = ra::peers::subject(peer);
  std::ofstream os(out);
  os << "id,hit,t,u,v\n";
  ra::audit::for_each_case(cases.string(), [&](const ra::audit::UserCase& c, long) {
    double t = 0, u = 0, v = 0;
    bool hit;
    if (s.precision == ra::audit::Precision::f32) {
      const auto h = s.f32(ra::Rayf(c.ray), ra::Vec3f(c.tri.a), ra::Vec3f(c.tri.b), ra::Vec3f(c.tri.c));
      if ((hit = h.has_value())) t = h->t, u = h->b1, v = h->b2;
    } else {
      const auto h = s.f64(c.ray, c.tri.a, c.tri.b, c.tri.c);
      if ((hit = h.has_value())) t = h->t, u = h->b1, v = h->b2;
    }
    os << c.id << ',' << (hit ? "true" : "false") << ',' << (hit ? hex(t) : "") << ',' << (hit ? hex(u) : "") << ','
       << (hit ? hex(v) : "") << '\n';
  });
}

// family|sweep -> stats of one subject's cells.
std::map<std::string, nlohmann::json> cells_of(const nlohmann::json& j, const std::string& subject) {
  std::map<std::string, nlohmann::json> out;
  for (const auto& c : j["cells"])
    if (c["subject"] == subject) out[c["family"].get<std::string>() + "|" + c["sweep"].get<std::string>()] = c["stats"];
  return out;
}

const nlohmann::json* subject_of(const nlohmann::json& j, const std::string& name) {
  for (const auto& s : j["subjects"])
    if (s["name"] == name) return &s;
  return nullptr;
}

const char* const kFamilies = "edge,vertex,closed-mesh";
constexpr int kRays = 4000;

}  // namespace

// Two paths to the same verdicts: per-peer leaks and double hits (and every
// other count, cell by cell) of `audit --methods PEERS` equal those of
// grading the same peers' answers to the exported cases with --grade, so a
// user grading their own answers gets what the audit would have said.
TEST(PeerSubjects, AuditAgreesWithGradingThePeersAnswers) {
  std::string names;
  for (const auto& p : ra::peers::peers())
    if (p.make) names.append(names.empty() ? "" : ",").append(p.name);
  ASSERT_FALSE(names.empty());
  const fs::path json = scratch("peers.json"), csv = scratch("peers.csv");
  const auto run = run_rayaudit("audit --methods " + names + ",moller --families " + kFamilies + " --rays " +
                                std::to_string(kRays) + " --json " + json.string() + " --csv " + csv.string());
  ASSERT_EQ(run.code, 0) << run.all;
  const auto audit = nlohmann::json::parse(slurp(json));

  for (const char* prec : {"float", "double"}) {
    const fs::path cases = scratch(std::string("cases-") + prec + ".csv");
    const auto ex = run_rayaudit("audit --export-cases " + cases.string() + " --precision " + prec + " --families " +
                                 kFamilies + " --rays " + std::to_string(kRays));
    ASSERT_EQ(ex.code, 0) << ex.all;
    for (const auto& peer : ra::peers::peers()) {
      if (!peer.make || std::string(ra::audit::precision_name(peer.precision)) != prec) continue;
      SCOPED_TRACE(peer.name);
      const fs::path answers = scratch(peer.name + ".csv"), graded = scratch(peer.name + "-graded.json");
      answer(peer, cases, answers);
      const auto g = run_rayaudit("audit --grade " + answers.string() + " --cases " + cases.string() + " --precision " +
                                  prec + " --json " + graded.string());
      ASSERT_EQ(g.code, 0) << g.all;
      const std::string subject = peer.name + "/" + prec;
      const auto a = cells_of(audit, subject), b = cells_of(nlohmann::json::parse(slurp(graded)), subject);
      ASSERT_EQ(a.size(), 5u + 5u + 4u);  // the sweep values of edge, vertex and closed-mesh
      ASSERT_EQ(b.size(), a.size());
      std::uint64_t groups = 0;
      for (const auto& [cell, stats] : a) {
        ASSERT_TRUE(b.count(cell)) << cell;
        EXPECT_EQ(stats["leaks"], b.at(cell)["leaks"]) << cell;
        EXPECT_EQ(stats["double_hits"], b.at(cell)["double_hits"]) << cell;
        EXPECT_EQ(stats, b.at(cell)) << cell;  // every count, t errors included
        groups += stats["groups"].get<std::uint64_t>();
      }
      EXPECT_GT(groups, 1000u) << "the families judged groups";
    }
  }

  // Facts about the peers themselves, not about our code: Epick's predicates
  // are exact, so its verdicts never contradict the oracle and it never
  // leaks; Embree's default mode leaks through shared edges in float.
  const auto* cgal = subject_of(audit, "cgal-epick/double");
  ASSERT_NE(cgal, nullptr);
  EXPECT_EQ((*cgal)["totals"]["false_hits"], 0);
  EXPECT_EQ((*cgal)["totals"]["false_misses"], 0);
  EXPECT_EQ((*cgal)["totals"]["leaks"], 0);
  if (ra::peers::have_embree()) {
    const auto* embree = subject_of(audit, "embree/float");
    ASSERT_NE(embree, nullptr);
    EXPECT_GT((*embree)["totals"]["leaks"].get<std::uint64_t>(), 0u) << run.out;
  }
}

// Peers carry the same entries as registry methods, marked: "peer" and
// "speed_source" in the JSON, a peer column in the CSV, a line under the table.
TEST(PeerSubjects, MarkedAsPeersInTableJsonAndCsv) {
  const fs::path json = scratch("mark.json"), csv = scratch("mark.csv");
  const auto r = run_rayaudit("audit --methods cgal-epick,pov-mesh2,moller --families edge --rays 200 --json " +
                              json.string() + " --csv " + csv.string());
  ASSERT_EQ(r.code, 0) << r.all;
  const auto j = nlohmann::json::parse(slurp(json));
  for (const char* name : {"cgal-epick/double", "pov-mesh2/float"}) {
    const auto* s = subject_of(j, name);
    ASSERT_NE(s, nullptr) << name;
    EXPECT_EQ((*s)["peer"], true) << name;
    EXPECT_NE((*s)["speed_source"].get<std::string>().find("peer bench"), std::string::npos) << name;
    EXPECT_NE(r.out.find(std::string("peer ") + name + ": "), std::string::npos) << r.out;
  }
  for (const char* name : {"moller/float", "moller/double"}) {
    const auto* s = subject_of(j, name);
    ASSERT_NE(s, nullptr) << name;
    EXPECT_EQ((*s)["peer"], false) << name;
    EXPECT_FALSE(s->contains("speed_source")) << name;
  }
  std::ifstream in(csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  ASSERT_EQ(line.substr(line.rfind(',') + 1), "peer");
  int peer_rows = 0, rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    const bool peer = line.rfind("cgal-epick,", 0) == 0 || line.rfind("pov-mesh2,", 0) == 0;
    EXPECT_EQ(line.substr(line.rfind(',') + 1), peer ? "1" : "0") << line;
    peer_rows += peer;
  }
  EXPECT_EQ(peer_rows, 2 * 5);  // two peers, one precision each, 5 edge sweep values
  EXPECT_EQ(rows, 4 * 5);
}

// Bad --methods: one line, exit 2, nothing written.
TEST(PeerSubjects, BadSubjectsAreRefusedWholeAndWriteNothing) {
  const fs::path json = scratch("bad.json");
  struct Bad {
    std::string methods, extra, message;
  };
  std::vector<Bad> bad = {
      {"embre", "", "audit: unknown method 'embre' ("},
      {"cgal-epick", "--precision float", "audit: peer 'cgal-epick' answers in double only"},
      {"pov-mesh2,nope", "", "audit: unknown method 'nope'"},
  };
  for (const auto& p : ra::peers::peers())
    if (!p.make) bad.push_back({p.name, "", "audit: peer '" + p.name + "' is not in this build: " + p.missing});
  for (const Bad& b : bad) {
    fs::remove(json);
    const auto r = run_rayaudit("audit --methods " + b.methods + " " + b.extra + " --families edge --rays 10 --json " +
                                json.string());
    EXPECT_EQ(r.code, 2) << b.methods;
    EXPECT_EQ(r.err.rfind(b.message, 0), 0u) << r.err;
    EXPECT_TRUE(ra::test::one_line(r.err)) << r.err;
    EXPECT_FALSE(fs::exists(json)) << b.methods;
  }
  // The unknown name's message lists every peer beside the methods.
  const auto r = run_rayaudit("audit --methods embre --families edge --rays 10");
  EXPECT_NE(r.err.find("peers: " + ra::peers::peer_names()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("moller"), std::string::npos) << r.err;
}
