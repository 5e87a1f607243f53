// Tests of `rayaudit audit` run as a user would (cli/cmd_audit.cpp): exit
// codes, the --cases JSON shape, malformed input, export round trip, determinism;
// --export-cases in one precision, streamed, safe on a full disk; merge's checks.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "run_rayaudit.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "registry.h"
#include "io/full_disk.h"

namespace {

namespace fs = std::filesystem;
using namespace ra::test;

struct Result {
  int code;
  std::string out, err;
};

fs::path tmp(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rayaudit_cli_audit_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

Result rayaudit(const std::string& args) {
  const auto r = ra::test::run_rayaudit(args);
  return {r.code, r.out, r.err};
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

const std::string kHeader = "ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n";

TEST(AuditCli, SummaryTableAndJson) {
  const fs::path json = tmp("audit.json");
  const Result r = rayaudit("audit --methods moller --families random,edge --rays 4000 --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("moller/float"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("moller/double"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << "no progress bar when stderr is not a terminal: " << r.err;
  const auto j = nlohmann::json::parse(slurp(json));
  ASSERT_EQ(j["subjects"].size(), 2u);
  EXPECT_EQ(j["cells"].size(), 2u * (3 + 5));  // random: 3 sweep values, edge: 5
}

TEST(AuditCli, ResultsDoNotDependOnThreads) {
  const fs::path a = tmp("t1.json"), b = tmp("t2.json");
  ASSERT_EQ(rayaudit("audit --methods moller,stable --rays 3000 --threads 1 --json " + a.string()).code, 0);
  ASSERT_EQ(rayaudit("audit --methods moller,stable --rays 3000 --threads 2 --json " + b.string()).code, 0);
  EXPECT_EQ(slurp(a), slurp(b));
}

TEST(AuditCli, CasesJsonHasExactlyTheDocumentedShape) {
  const fs::path csv = tmp("cases.csv"), json = tmp("cases.json");
  write(csv, kHeader +
                 "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n0x1p-1,0,1,0,0,-1,0,0,0,1,0,0,0,1,0\n5,5,1,0,0,-1,0,0,0,1,0,0,"
                 "0,1,0\n");
  const Result r = rayaudit("audit --cases " + csv.string() + " --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(json));
  ASSERT_EQ(j.size(), 1u);
  ASSERT_EQ(j["cases"].size(), 3u);
  std::size_t tri_methods = 0;
  for (const auto& m : ra::methods()) tri_methods += m.kind == ra::Kind::triangle;
  const char* verdicts[3] = {"hit", "boundary", "miss"};
  for (int i = 0; i < 3; ++i) {
    const auto& c = j["cases"][std::size_t(i)];
    EXPECT_EQ(c.size(), 4u);
    EXPECT_EQ(c["id"], i + 1);  // no id column: the 1-based row number
    EXPECT_EQ(c["verdict"], verdicts[i]);
    EXPECT_EQ(c["answers"].size(), 2 * tri_methods);
    for (const auto& [name, a] : c["answers"].items()) {
      EXPECT_EQ(a.size(), 2u) << name;
      EXPECT_TRUE(a["hit"].is_boolean()) << name;
      EXPECT_TRUE(a["hit"] ? a["t"].is_number() : a["t"].is_null()) << name;
    }
  }
  // Streamed row by row, yet exactly the document nlohmann writes whole.
  EXPECT_EQ(slurp(json), j.dump(2) + "\n");
  EXPECT_EQ(j["cases"][0]["t"], 1.0);
  EXPECT_TRUE(j["cases"][2]["t"].is_null());
  EXPECT_EQ(j["cases"][0]["answers"]["moller/float"]["hit"], true);
}

TEST(AuditCli, MalformedCasesExitTwoWithFileLineAndWriteNothing) {
  const fs::path csv = tmp("bad.csv"), json = tmp("bad.json");
  const std::string row = "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n";
  const std::pair<std::string, std::string> bad[] = {
      {"ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy\n" + row, ":1: missing column 'cz'"},
      {kHeader + row + "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1\n", ":3: expected 15 fields"},
      {kHeader + row + row + "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,one,0\n", ":4: column 'cy'"},
      {kHeader + "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0 0\n", ":2: column 'cz'"},
  };
  for (const auto& [text, msg] : bad) {
    write(csv, text);
    fs::remove(json);
    const Result r = rayaudit("audit --cases " + csv.string() + " --json " + json.string());
    EXPECT_EQ(r.code, 2) << text;
    EXPECT_NE(r.err.find(csv.string() + msg), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(json)) << text;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  const Result missing = rayaudit("audit --cases " + tmp("nope.csv").string() + " --json " + json.string());
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("nope.csv"), std::string::npos);
  EXPECT_FALSE(fs::exists(json));
}

TEST(AuditCli, ExportThenAuditAgreesOnEveryVerdict) {
  const fs::path csv = tmp("export.csv"), json = tmp("export.json");
  const Result e =
      rayaudit("audit --export-cases " + csv.string() + " --families edge,vertex,near-miss,degenerate --rays 2000");
  ASSERT_EQ(e.code, 0) << e.err;
  const Result r = rayaudit("audit --methods moller --cases " + csv.string() + " --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(json));
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // the stamp: # rayaudit-cases ...
  ASSERT_EQ(line.rfind("# rayaudit-cases ", 0), 0u) << line;
  std::getline(in, line);  // header: ...,verdict,t
  std::size_t i = 0;
  while (std::getline(in, line)) {
    const auto cut = line.rfind(',');
    const std::string t = line.substr(cut + 1);
    const auto cut2 = line.rfind(',', cut - 1);
    const std::string verdict = line.substr(cut2 + 1, cut - cut2 - 1);
    ASSERT_LT(i, j["cases"].size());
    const auto& c = j["cases"][i++];
    ASSERT_EQ(c["verdict"], verdict) << c["id"];
    if (!t.empty()) {
      ASSERT_EQ(c["t"].get<double>(), std::strtod(t.c_str(), nullptr)) << c["id"];
    }
    ASSERT_EQ(c["id"], line.substr(0, line.find(','))) << "ids are the exported id column";
  }
  EXPECT_EQ(i, j["cases"].size());
  EXPECT_GT(i, 1000u);
}

TEST(AuditCli, OneUnwritableOutputMeansNoOutputAtAll) {
  const fs::path json = tmp("half.json");
  fs::remove(json);
  const Result r =
      rayaudit("audit --methods moller --families random --rays 10 --csv /nonexistent/x.csv --json " + json.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/x.csv: output directory does not exist"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(json)) << "the JSON was written though the CSV could not be";
  // Both writable: both written, no temporary left behind.
  const fs::path csv = tmp("half.csv");
  ASSERT_EQ(
      rayaudit("audit --methods moller --families random --rays 10 --csv " + csv.string() + " --json " + json.string())
          .code,
      0);
  EXPECT_TRUE(fs::exists(json) && fs::exists(csv));
  for (const auto& e : fs::directory_iterator(json.parent_path()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
}

TEST(AuditCli, AbsurdCountsAndIgnoredOptionsAreUsageErrors) {
  Result r = rayaudit("audit --rays 99999999999999");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("above the limit of 10000000000 (1e10) rays per family"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_EQ(rayaudit("audit --rays 0").code, 2);
  r = rayaudit("audit --export-cases " + tmp("huge.csv").string() + " --rays 20000000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("above the export's limit of 10000000"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp("huge.csv")));
  EXPECT_EQ(rayaudit("audit --threads -1 --rays 10").code, 2);
  EXPECT_EQ(rayaudit("audit --seed -1 --rays 10").code, 2);
  // Options that would be silently ignored.
  const fs::path csv = tmp("ok.csv");
  write(csv, kHeader + "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n");
  r = rayaudit("audit --cases " + csv.string() + " --csv " + tmp("z.csv").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--csv"), std::string::npos) << r.err;
  r = rayaudit("audit --export-cases " + tmp("e.csv").string() + " --families edge --rays 5 --json " +
               tmp("e.json").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--json"), std::string::npos) << r.err;
  // A family none of the chosen methods can grade.
  r = rayaudit("audit --methods kraus --families edge --rays 10");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no triangle method"), std::string::npos) << r.err;
}

TEST(AuditCli, UnknownNamesAreUsageErrors) {
  EXPECT_EQ(rayaudit("audit --methods nosuch --rays 10").code, 2);
  EXPECT_EQ(rayaudit("audit --families nosuch --rays 10").code, 2);
  EXPECT_EQ(rayaudit("audit --precision half --rays 10").code, 2);
  EXPECT_EQ(rayaudit("audit --methods plane --rays 10").code, 2);
}

// ------------------------------------------------------- shards ---
TEST(AuditShards, TwoShardsMergedEqualTheUnshardedRunByteForByte) {
  const std::string run = "audit --methods moller,stable,codeproject --rays 6000 --seed 5";
  const fs::path u = tmp("u.json"), uc = tmp("u.csv"), a = tmp("s1.json"), b = tmp("s2.json"), m = tmp("m.json"),
                 mc = tmp("m.csv");
  ASSERT_EQ(rayaudit(run + " --json " + u.string() + " --csv " + uc.string()).code, 0);
  // Shards on different thread counts: the same rays either way.
  const Result r1 = rayaudit(run + " --shard 1/2 --threads 1 --json " + a.string());
  ASSERT_EQ(r1.code, 0) << r1.err;
  EXPECT_NE(r1.out.find("shard 1/2: partial counts"), std::string::npos) << r1.out;
  ASSERT_EQ(rayaudit(run + " --shard 2/2 --threads 3 --json " + b.string()).code, 0);
  // Each shard judged part of the rays, not all or none.
  const auto ja = nlohmann::json::parse(slurp(a)), ju = nlohmann::json::parse(slurp(u));
  const auto ta = ja["subjects"][0]["totals"]["tests"].get<std::uint64_t>(),
             tu = ju["subjects"][0]["totals"]["tests"].get<std::uint64_t>();
  EXPECT_GT(ta, tu / 4);
  EXPECT_LT(ta, 3 * tu / 4);
  EXPECT_EQ(ja["shard"]["k"], 1);
  EXPECT_EQ(ja["shard"]["n"], 2);
  const Result mr =
      rayaudit("audit merge " + b.string() + " " + a.string() + " --json " + m.string() + " --csv " + mc.string());
  ASSERT_EQ(mr.code, 0) << mr.err;
  EXPECT_EQ(slurp(m), slurp(u));
  EXPECT_EQ(slurp(mc), slurp(uc));
  EXPECT_FALSE(ju.contains("shard"));
  EXPECT_TRUE(ju.contains("version"));
}

TEST(AuditShards, MergingShardsOfDifferentRunsIsAnErrorNamingBothFiles) {
  const std::string run = "audit --methods moller --families random,edge --rays 1000";
  const fs::path a = tmp("d1.json"), b = tmp("d2.json"), seed = tmp("dseed.json"), rays = tmp("drays.json"),
                 meth = tmp("dmeth.json"), whole = tmp("dwhole.json"), out = tmp("dout.json");
  ASSERT_EQ(rayaudit(run + " --shard 1/2 --json " + a.string()).code, 0);
  ASSERT_EQ(rayaudit(run + " --shard 2/2 --json " + b.string()).code, 0);
  ASSERT_EQ(rayaudit(run + " --shard 2/2 --seed 9 --json " + seed.string()).code, 0);
  ASSERT_EQ(
      rayaudit("audit --methods moller --families random,edge --rays 2000 --shard 2/2 --json " + rays.string()).code,
      0);
  ASSERT_EQ(
      rayaudit("audit --methods cramer --families random,edge --rays 1000 --shard 2/2 --json " + meth.string()).code,
      0);
  ASSERT_EQ(rayaudit(run + " --json " + whole.string()).code, 0);
  const std::pair<fs::path, std::string> bad[] = {{seed, "seed"}, {rays, "rays per family"}, {meth, "methods"}};
  for (const auto& [other, what] : bad) {
    fs::remove(out);
    const Result r = rayaudit("audit merge " + a.string() + " " + other.string() + " --json " + out.string());
    EXPECT_EQ(r.code, 2) << what;
    EXPECT_NE(r.err.find(a.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(other.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // A version from another build: edit a copy of shard 2.
  auto j = nlohmann::json::parse(slurp(b));
  j["version"] = "0.0.0-other";
  const fs::path ver = tmp("dver.json");
  write(ver, j.dump());
  Result r = rayaudit("audit merge " + a.string() + " " + ver.string() + " --json " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("version"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(ver.string()), std::string::npos) << r.err;
  // The same shard twice, a missing shard, an unsharded output.
  r = rayaudit("audit merge " + a.string() + " " + a.string() + " --json " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("both shard 1/2"), std::string::npos) << r.err;
  r = rayaudit("audit merge " + b.string() + " --json " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("shard 1/2 is missing"), std::string::npos) << r.err;
  r = rayaudit("audit merge " + whole.string() + " --json " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(whole.string() + ": not a shard"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(rayaudit(run + " --shard 0/2").code, 2);
  EXPECT_EQ(rayaudit(run + " --shard 3/2").code, 2);
  EXPECT_EQ(rayaudit(run + " --shard 1").code, 2);
}

// Hostile shards: a count near 2^64 wrapped when
// merged, a shard count of 4e9 was a bad_alloc, a key given twice was
// resolved silently, a directory was a raw library error.
TEST(AuditShards, HostileShardsAreOneLineErrors) {
  const std::string run = "audit --methods moller --families edge --rays 200";
  const fs::path a = tmp("h1.json"), b = tmp("h2.json"), out = tmp("hout.json");
  ASSERT_EQ(rayaudit(run + " --shard 1/2 --json " + a.string()).code, 0);
  ASSERT_EQ(rayaudit(run + " --shard 2/2 --json " + b.string()).code, 0);
  auto one_error = [&](const fs::path& first, const fs::path& second, const std::string& says) {
    const Result r = rayaudit("audit merge " + first.string() + " " + second.string() + " --json " + out.string());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  };
  auto jb = nlohmann::json::parse(slurp(b));
  // tests at 2^64-1 with the verdict counts still adding up to it (merge
  // refuses counts that do not), merged with a shard of a few tests.
  auto& sb = jb["cells"][0]["stats"];
  const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
  sb["true_misses"] = sb["true_misses"].get<std::uint64_t>() + (max - sb["tests"].get<std::uint64_t>());
  sb["tests"] = max;
  const fs::path big = tmp("hbig.json");
  write(big, jb.dump());
  one_error(a, big, big.string() + ": a count overflows 2^64-1 when merged");
  auto huge = [&](const fs::path& from, const fs::path& to) {
    auto j = nlohmann::json::parse(slurp(from));
    j["shard"]["n"] = 4000000000ULL;
    write(to, j.dump());
  };
  const fs::path ha = tmp("hna.json"), hb = tmp("hnb.json");
  huge(a, ha);
  huge(b, hb);
  one_error(ha, hb, "audit merge: shard 3/4000000000 is missing");
  const std::string text = slurp(a);
  const fs::path dup = tmp("hdup.json");
  write(dup, "{\"seed\": 1,\n" + text.substr(text.find('{') + 1));
  one_error(dup, b, dup.string() + ":");
  one_error(dup, b, "given twice in one object");
  one_error(tmp(""), b, ": is a directory, not a file");
}

// -------------------------------------------------------- --grade ---
// The repository's example: textbook Moller-Trumbore in Python (numpy), its
// answers graded against exported cases. The exact oracle, not the script,
// decides: rays through shared edges and vertices that both neighbours miss.
TEST(AuditGrade, PythonMollerTrumboreLeaks) {
  const fs::path cases = tmp("py_cases.csv"), answers = tmp("py_mt.csv"), json = tmp("py_graded.json");
  ASSERT_EQ(rayaudit("audit --export-cases " + cases.string() + " --families edge,vertex,closed-mesh --rays 6000").code,
            0);
  const std::string script = std::string(RAYAUDIT_SOURCE_DIR) + "/examples/grade/moller_trumbore.py";
  ASSERT_EQ(std::system(("/usr/bin/python3 " + script + " " + cases.string() + " " + answers.string()).c_str()), 0)
      << "the example needs /usr/bin/python3 with numpy (ci/install-deps.sh)";
  const Result r =
      rayaudit("audit --grade " + answers.string() + " --cases " + cases.string() + " --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("py_mt/double"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(slurp(json));
  ASSERT_EQ(j["subjects"].size(), 1u);
  const auto& totals = j["subjects"][0]["totals"];
  EXPECT_GT(totals["groups"].get<int>(), 1000);
  EXPECT_GT(totals["leaks"].get<int>(), 0) << r.out;
  std::printf("%s", r.out.c_str());
  // Leaks per family, as for a registered method: at least the edge pairs leak.
  std::uint64_t edge_leaks = 0;
  for (const auto& c : j["cells"])
    if (c["family"] == "edge") edge_leaks += c["stats"]["leaks"].get<std::uint64_t>();
  EXPECT_GT(edge_leaks, 0u);
  EXPECT_EQ(j["cells"].size(), 5u + 5u + 4u);  // edge, vertex, closed-mesh sweep values
}

TEST(AuditGrade, BadAnswersExitTwoWithFileLineAndWriteNothing) {
  const fs::path cases = tmp("g_cases.csv"), answers = tmp("g_answers.csv"), json = tmp("g.json");
  write(cases,
        "id,ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n"
        "a,0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n"
        "b,5,5,1,0,0,-1,0,0,0,1,0,0,0,1,0\n");
  const std::pair<std::string, std::string> bad[] = {
      {"id,hit,t\na,true,1\n", cases.string() + ":3: case 'b' has no answer"},
      {"id,hit,t\na,true,1\nb,false,\na,true,1\n", answers.string() + ":4: duplicate id 'a'"},
      {"id,hit,t\na,true,1\nb,false,\nc,false,\n", answers.string() + ":4: id 'c' is not a case"},
      {"id,hit,t\na,yes,1\nb,false,\n", answers.string() + ":2: hit 'yes' is not a boolean"},
      {"id,hit,t\na,true,\nb,false,\n", answers.string() + ":2: a hit without t"},
      {"id,hit,t\na,true,0x1p+0\nb,false,\n", ""},  // good: hex t, so the others fail for their own reason
  };
  for (const auto& [text, msg] : bad) {
    write(answers, text);
    fs::remove(json);
    const Result r =
        rayaudit("audit --grade " + answers.string() + " --cases " + cases.string() + " --json " + json.string());
    if (msg.empty()) {
      EXPECT_EQ(r.code, 0) << r.err;
      EXPECT_TRUE(fs::exists(json));
      continue;
    }
    EXPECT_EQ(r.code, 2) << text;
    EXPECT_EQ(r.err.rfind(msg, 0), 0u) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    EXPECT_FALSE(fs::exists(json)) << text;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  EXPECT_EQ(rayaudit("audit --grade " + answers.string()).code, 2) << "--grade needs --cases";
}

// Hand-made cases, judged by hand: a is a hit at t = 1 inside the unit
// triangle; h lies 2^-53 beyond its hypotenuse in double (a miss) but
// exactly on it once rounded to float (a boundary case).
TEST(AuditGrade, NonFiniteTIsWrongAndFloatCasesAreRounded) {
  const fs::path cases = tmp("gn_cases.csv"), answers = tmp("gn_answers.csv"), json = tmp("gn.json"),
                 csv = tmp("gn.csv");
  write(cases,
        "id,ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n"
        "a,0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n"
        "h,0x1.0000000000001p-1,0x1p-1,-1,0,0,1,0,0,0,1,0,0,0,1,0\n");
  auto totals = [&](const std::string& extra) {
    fs::remove(json);
    const Result r = rayaudit("audit --grade " + answers.string() + " --cases " + cases.string() + " --json " +
                              json.string() + " " + extra);
    EXPECT_EQ(r.code, 0) << r.err;
    return nlohmann::json::parse(slurp(json))["cells"][0]["stats"];
  };
  for (const char* t : {"nan", "inf", "-inf"}) {
    write(answers, std::string("id,hit,t\na,true,") + t + "\nh,false,\n");
    const auto s = totals("");
    EXPECT_EQ(s["wrong_t"], 1) << t;
    EXPECT_EQ(s["wrong"], 1) << t;
    EXPECT_EQ(s["nan_inf"], 1) << t;
    EXPECT_EQ(s["true_hits"], 1) << t;
  }
  write(answers, "id,hit,t\na,true,1\nh,true,1\n");
  auto s = totals("--precision double");
  EXPECT_EQ(s["false_hits"], 1);
  EXPECT_EQ(s["wrong"], 1);
  s = totals("--precision float");
  EXPECT_EQ(s["false_hits"], 0);
  EXPECT_EQ(s["boundary_hits"], 1);
  EXPECT_EQ(s["wrong"], 0);
  // One file of answers is one precision; the generator's options do not apply.
  for (const char* opt : {"--precision float,double", "--rays 5", "--seed 9", "--families edge"}) {
    fs::remove(json);
    const Result r = rayaudit("audit --grade " + answers.string() + " --cases " + cases.string() + " --json " +
                              json.string() + " " + opt);
    EXPECT_EQ(r.code, 2) << opt;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    EXPECT_FALSE(fs::exists(json)) << opt;
  }
  // A subject named after an answers file with a comma and a quote: the CSV
  // quotes it, so every row has the header's number of fields.
  const fs::path odd = tmp("my,ans\"wer.csv");
  fs::copy_file(answers, odd, fs::copy_options::overwrite_existing);
  const Result r =
      rayaudit("audit --grade '" + odd.string() + "' --cases " + cases.string() + " --csv " + csv.string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::istringstream lines(slurp(csv));
  std::string header, row;
  std::getline(lines, header);
  std::getline(lines, row);
  EXPECT_EQ(row.rfind("\"my,ans\"\"wer\",double,", 0), 0u) << row;
  // Fields outside quotes: the header's count.
  int fields = 1;
  bool quoted = false;
  for (char ch : row) {
    if (ch == '"')
      quoted = !quoted;
    else if (ch == ',' && !quoted)
      ++fields;
  }
  EXPECT_EQ(fields, int(std::count(header.begin(), header.end(), ',')) + 1) << row;
}

// Answers as spreadsheets save them: a UTF-8 BOM is dropped (it read
// "missing column 'id'"); UTF-16 is named; a directory or FIFO as answers is
// named, not read as "empty file" or waited on.
TEST(AuditGrade, AnswersEncodingAndNonFilesAreNamed) {
  const fs::path cases = tmp("ge_cases.csv"), answers = tmp("ge_answers.csv"), json = tmp("ge.json");
  write(cases, "id,ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\na,0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n");
  const std::string grade =
      "audit --grade " + answers.string() + " --cases " + cases.string() + " --json " + json.string();
  write(answers, "\xEF\xBB\xBFid,hit,t\na,true,1\n");
  Result r = rayaudit(grade);
  EXPECT_EQ(r.code, 0) << r.err;
  write(answers, std::string("\xFF\xFEi\0d\0", 6));
  r = rayaudit(grade);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, answers.string() + ":1: the file is UTF-16 (or holds NUL bytes): save it as UTF-8 or ASCII\n");
  // A column named twice: which one counts would be a guess (the answers
  // reader now shares the cases reader's header check).
  write(answers, "id,hit,t,t\na,true,1,2\n");
  const std::string before = slurp(json);  // the BOM run's output, which must stay
  r = rayaudit(grade);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(answers.string() + ":1: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'t'"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_EQ(slurp(json), before) << "an existing output must be left untouched";
  fs::remove(answers);
  ASSERT_EQ(::mkfifo(answers.c_str(), 0644), 0);
  r = rayaudit(grade);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, answers.string() + ": is a FIFO, not a file\n");
  fs::remove(answers);
}

// ------------------------------------------------- --cases memory ---
// Peak resident memory (kB) of one rayaudit run, its output discarded.
long peak_rss_kb(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv = {const_cast<char*>(RAYAUDIT_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (!std::freopen("/dev/null", "w", stdout)) ::_exit(127);
    ::execv(RAYAUDIT_EXE, argv.data());
    ::_exit(127);
  }
  int status = 0;
  struct rusage ru {};
  ::wait4(pid, &status, 0, &ru);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  return ru.ru_maxrss;
}

// `audit --cases` held every row and its JSON (175x the CSV). Now
// streamed: 100k rows peak where 20k do (the old code grew ~3 kB per row).
TEST(AuditCli, CasesMemoryDoesNotGrowWithRows) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's quarantine keeps freed memory: peak RSS says nothing about our rows";
#endif
  auto make = [&](const fs::path& p, int rows) {
    std::ofstream out(p);
    out << kHeader;
    for (int i = 0; i < rows; ++i) out << 0.001 * (i % 997) << ",0.25,1,0,0,-1,0,0,0,1,0,0,0,1," << (i % 3) << "\n";
  };
  const fs::path small = tmp("rows20k.csv"), large = tmp("rows100k.csv"), json = tmp("rows.json");
  make(small, 20000);
  make(large, 100000);
  const long a = peak_rss_kb({"audit", "--cases", small.string(), "--methods", "moller", "--json", json.string()});
  const long b = peak_rss_kb({"audit", "--cases", large.string(), "--methods", "moller", "--json", json.string()});
  std::printf("peak RSS: 20k rows %ld kB, 100k rows %ld kB\n", a, b);
  EXPECT_LT(b, a + 25 * 1024) << "20k rows: " << a << " kB, 100k rows: " << b << " kB";
  EXPECT_EQ(nlohmann::json::parse(slurp(json))["cases"].size(), 100000u);
  fs::remove(small), fs::remove(large), fs::remove(json);
}

// A list of two precisions was taken as double, the float half dropped.
TEST(AuditExportCli, ExportCasesTakesOnePrecision) {
  const fs::path out = scratch("two-precisions.csv");
  fs::remove(out);
  for (const char* list : {"float,double", "double,float"}) {
    const auto r = run_rayaudit("audit --export-cases " + out.string() + " --precision " + list + " --rays 10");
    EXPECT_EQ(r.code, 2) << r.all;
    EXPECT_EQ(r.err,
              std::string("--precision: --export-cases takes one precision (float or double), got '") + list + "'\n");
    EXPECT_FALSE(fs::exists(out));
  }
  const auto ok = run_rayaudit("audit --export-cases " + out.string() + " --precision float --rays 10 --families edge");
  EXPECT_EQ(ok.code, 0) << ok.all;
  EXPECT_NE(ok.out.find("float cases"), std::string::npos) << ok.out;
}

// The export held every case in memory (840 bytes each: 300,000 cases
// did not fit in 200 MB of address space); it streams now.
TEST(AuditExportCli, ExportCasesStreamsWithinAFixedAddressSpace) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  const fs::path out = scratch("streamed.csv");
  const auto r =
      run_rayaudit("audit --export-cases " + out.string() + " --rays 300000 --families random --precision double",
                   "prlimit --as=200000000");
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("wrote 300000 double cases"), std::string::npos) << r.out;
  std::ifstream in(out);
  long lines = 0;
  for (std::string l; std::getline(in, l);) ++lines;
  EXPECT_EQ(lines, 300002);  // the stamp, the header, the rows
  fs::remove(out);
}

// Impossible counts and unknown keys in a shard were merged as given;
// a hostile shard was held at ~30x its size (a bare std::bad_alloc).
TEST(AuditShards, MergeRefusesImpossibleStatsUnknownKeysAndHugeShards) {
  const fs::path sh1 = scratch("sh1.json"), sh2 = scratch("sh2.json"), out = scratch("merged.json");
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 100 --shard 1/2 --json " + sh1.string()).code,
            0);
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 100 --shard 2/2 --json " + sh2.string()).code,
            0);
  const std::string text = slurp(sh1);
  auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    return scratch_variant(text, name, from, to);
  };
  // false_hits 1000 in a cell of 10 tests (the number replaced in place).
  const fs::path false_hits = scratch("m-false-hits.json");
  std::string fh = text;
  const auto at = fh.find("\"false_hits\": ");
  const auto end = fh.find(',', at);
  fh.replace(at, end - at, "\"false_hits\": 1000");
  std::ofstream(false_hits) << fh;
  struct Case {
    fs::path file;
    std::string message;
  };
  const std::vector<Case> cases = {
      {false_hits, ": cells[0].stats: the verdict counts add up to "},
      {variant("m-unknown.json", "\"tests\": ", "\"zz\": 1, \"tests\": "), ": cells[0].stats: 'zz': unknown key"},
      {variant("m-hist.json", "\"t_rel\": ", "\"zz\": [], \"t_rel\": "), ": cells[0].histograms: 'zz': unknown key"},
  };
  for (const auto& c : cases) {
    const auto r = run_rayaudit("audit merge " + c.file.string() + " " + sh2.string() + " --json " + out.string());
    EXPECT_EQ(r.code, 2) << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(c.file.string() + c.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // 9 MB of JSON (spaces are JSON too): refused by its size, before parsing.
  const fs::path big = scratch("m-big.json");
  std::ofstream(big) << text.substr(0, text.size() - 2) << std::string(9u << 20, ' ') << "}\n";
  const auto r = run_rayaudit("audit merge " + big.string() + " " + sh2.string() + " --json " + out.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err,
            big.string() + ": 9 MB is larger than a shard can be (at most 8 MB; a full audit's shard is about 1 MB)\n");
  EXPECT_FALSE(fs::exists(out));
  // The untouched shards still merge.
  EXPECT_EQ(run_rayaudit("audit merge " + sh1.string() + " " + sh2.string() + " --json " + out.string()).code, 0);
}

// The streamed export on a full disk: one line, exit 2, the old file kept
// (the rows now go to the file as they are made; the write is still checked
// through close and rename).
TEST(AuditExportCli, StreamedExportOnAFullDiskKeepsTheOldFile) {
  ra::test::FullDisk disk;
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const fs::path out = disk.dir() / "cases.csv";
  std::ofstream(out) << "good";
  const auto r = run_rayaudit("audit --export-cases " + out.string() + " --families edge --rays 1000");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find(out.string() + ": cannot write"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(out), "good");
}

// --families refracted: one name, a triangle and a sphere family, so every
// method of the registry is graded, in both precisions, under each of the
// four strategies at each of the four scales.
TEST(AuditCli, RefractedGradesEveryMethodAndStrategy) {
  const fs::path json = tmp("refracted.json");
  const Result r = rayaudit("audit --families refracted --rays 160 --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(json));
  std::size_t methods = 0;
  for (const auto& m : ra::methods()) methods += m.kind == ra::Kind::triangle || m.kind == ra::Kind::sphere;
  ASSERT_EQ(j["subjects"].size(), 2 * methods);
  EXPECT_EQ(j["cells"].size(), 2 * methods * 16);
  std::map<std::string, std::set<std::string>> sweeps;
  std::map<std::string, std::uint64_t> spawned;
  for (const auto& c : j["cells"]) {
    EXPECT_EQ(c["family"], "refracted");
    EXPECT_TRUE(c["stats"].contains("skipped_walls")) << c.dump();
    sweeps[c["subject"]].insert(c["sweep"].get<std::string>());
    spawned[c["subject"]] += c["stats"]["spawned"].get<std::uint64_t>();
  }
  for (const auto& s : j["subjects"]) {
    const std::string name = s["name"];
    EXPECT_EQ(sweeps[name].size(), 16u) << name;
    for (const char* st : {"eps", "pov", "normal-offset", "ulp-offset"})
      for (const char* sc : {"1e-08", "0.0001", "1", "10000"})
        EXPECT_TRUE(sweeps[name].count(std::string(st) + "@" + sc)) << name << " " << st << "@" << sc;
    EXPECT_GT(spawned[name], 0u) << name;
  }
  // The text table: a row per kind, precision and strategy.
  for (const char* kind : {"triangle", "sphere"})
    for (const char* prec : {"float", "double"})
      for (const char* st : {"eps", "pov", "normal-offset", "ulp-offset"}) {
        char row[64];
        std::snprintf(row, sizeof row, "%-9s %-7s %-14s", kind, prec, st);
        EXPECT_NE(r.out.find(row), std::string::npos) << row << "\n" << r.out;
      }
}

// The name a sphere method alone grades (the triangle family of that name
// has no subject), and a misspelt one refused in one line.
TEST(AuditCli, RefractedWithSphereMethodsOnlyAndAMisspeltFamily) {
  const fs::path json = tmp("refracted-sphere.json");
  const Result r = rayaudit("audit --methods kraus --families refracted --rays 64 --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(json));
  ASSERT_EQ(j["subjects"].size(), 2u);
  EXPECT_EQ(j["subjects"][0]["kind"], "sphere");
  EXPECT_EQ(j["cells"].size(), 2u * 16u);
  const Result bad = rayaudit("audit --families refracted,refraction --rays 64");
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(one_line(bad.err)) << bad.err;
  EXPECT_NE(bad.err.find("unknown family 'refraction'"), std::string::npos) << bad.err;
  EXPECT_EQ(bad.err.find("refracted, refracted"), std::string::npos) << "each name listed once: " << bad.err;
}

}  // namespace

namespace {

// --tracers: whole tracers graded beside the kernels, into the same JSON.
// Our BVH on the watertight method and Embree's robust mode do not leak on
// closed meshes (renderer/accel/README.md, validation/tracers/README.md).
TEST(AuditCli, TracersAreGradedIntoTheSameJson) {
  const fs::path json = tmp("tracers.json");
  fs::remove(json);
  const Result r = rayaudit(
      "audit --methods moller --families random --rays 1000 --precision float --tracers "
      "bvh:watertight/double,embree-robust --tracer-rays 40 --json " +
      json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("bvh/watertight/double"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(slurp(json));
  ASSERT_TRUE(j.contains("tracers")) << j.dump().substr(0, 400);
  EXPECT_EQ(j["tracers"]["subjects"], (nlohmann::json{"bvh/watertight/double", "embree-robust"}));
  ASSERT_FALSE(j["tracers"]["cells"].empty());
  for (const auto& c : j["tracers"]["cells"]) {
    EXPECT_GT(c["rays"].get<long long>(), 0) << c.dump();
    EXPECT_EQ(c["leaks"], 0) << c.dump();
  }
}

// Where tracers would be left out, or graded per shard and lost by the
// merge, the option is refused before any work, and nothing is written.
TEST(AuditCli, TracersWithCasesExportOrShardAreRefused) {
  const fs::path cases = tmp("tracers_cases.csv"), out = tmp("tracers_refused.json");
  write(cases, kHeader + "0,0,-1,0,0,1,-1,-1,0,1,-1,0,0,1,0\n");
  fs::remove(out);
  for (const std::string& extra : {"--cases " + cases.string() + " --methods moller", "--export-cases " + out.string(),
                                   "--methods moller --shard 1/2 --json " + out.string()}) {
    const Result r = rayaudit("audit --tracers bvh " + extra);
    EXPECT_EQ(r.code, 2) << extra << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find("--tracers"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << extra;
  }
  const Result r = rayaudit("audit --methods moller --tracer-rays 10 --json " + out.string());
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--tracer-rays"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
