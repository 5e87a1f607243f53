// Tests of `rayaudit audit` run as a user would (cli/cmd_audit.cpp): exit
// codes, the --cases JSON shape, malformed input, export round trip, determinism.
#include <gtest/gtest.h>

#include "run_rayaudit.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "registry.h"

namespace {

namespace fs = std::filesystem;

struct Result {
  int code;
  std::string out, err;
};

fs::path tmp(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rayaudit_cli_audit_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
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
  write(csv, kHeader + "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n0x1p-1,0,1,0,0,-1,0,0,0,1,0,0,0,1,0\n5,5,1,0,0,-1,0,0,0,1,0,0,0,1,0\n");
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
  const Result e = rayaudit("audit --export-cases " + csv.string() + " --families edge,vertex,near-miss,degenerate --rays 2000");
  ASSERT_EQ(e.code, 0) << e.err;
  const Result r = rayaudit("audit --methods moller --cases " + csv.string() + " --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(json));
  std::ifstream in(csv);
  std::string line;
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
  const Result r = rayaudit("audit --methods moller --families random --rays 10 --csv /nonexistent/x.csv --json " +
                            json.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/x.csv: output directory does not exist"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(json)) << "the JSON was written though the CSV could not be";
  // Both writable: both written, no temporary left behind.
  const fs::path csv = tmp("half.csv");
  ASSERT_EQ(rayaudit("audit --methods moller --families random --rays 10 --csv " + csv.string() + " --json " +
                     json.string()).code, 0);
  EXPECT_TRUE(fs::exists(json) && fs::exists(csv));
  for (const auto& e : fs::directory_iterator(json.parent_path()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
}

TEST(AuditCli, AbsurdCountsAndIgnoredOptionsAreUsageErrors) {
  Result r = rayaudit("audit --rays 99999999999999");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("not in range 1 to 100000000"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_EQ(rayaudit("audit --rays 0").code, 2);
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

}  // namespace
