// `audit --export-cases --numbers decimal`: the same cases as the hex-float
// export, every number reading back as the same double, and answers graded
// alike whether their t is written in hex or in decimal.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rayaudit-numbers-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::vector<std::vector<std::string>> rows(const fs::path& p) {
  std::vector<std::vector<std::string>> out;
  std::istringstream in(slurp(p));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) continue;  // the export's stamp line
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string x;
    while (std::getline(ss, x, ',')) f.push_back(x);
    if (!line.empty() && line.back() == ',') f.push_back("");
    out.push_back(f);
  }
  return out;
}

}  // namespace

TEST(ExportNumbers, DecimalReadsBackAsTheHexExportsDoubles) {
  for (const char* prec : {"float", "double"}) {
    const fs::path hex = scratch(std::string("hex-") + prec + ".csv"),
                   dec = scratch(std::string("dec-") + prec + ".csv");
    const std::string common = std::string(" --precision ") + prec + " --families edge,vertex,near-miss --rays 600";
    ASSERT_EQ(run_rayaudit("audit --export-cases " + hex.string() + common).code, 0);
    const auto r = run_rayaudit("audit --export-cases " + dec.string() + common + " --numbers decimal");
    ASSERT_EQ(r.code, 0) << r.all;
    EXPECT_NE(r.out.find("(decimal numbers)"), std::string::npos) << r.out;
    const auto h = rows(hex), d = rows(dec);
    ASSERT_EQ(h.size(), d.size());
    ASSERT_GT(h.size(), 500u);
    ASSERT_EQ(h[0], d[0]) << "the same header";
    std::size_t numbers = 0;
    for (std::size_t i = 1; i < h.size(); ++i) {
      ASSERT_EQ(h[i].size(), d[i].size()) << i;
      for (std::size_t k = 0; k < h[i].size(); ++k) {
        const bool number = k >= 3 && k != 18;  // id,family,sweep and verdict are text
        if (!number || h[i][k].empty()) {
          EXPECT_EQ(h[i][k], d[i][k]) << i << "," << k;
          continue;
        }
        ASSERT_EQ(d[i][k].find("0x"), std::string::npos) << d[i][k];
        // Bit for bit the same double (strtod reads both forms exactly).
        EXPECT_EQ(std::strtod(h[i][k].c_str(), nullptr), std::strtod(d[i][k].c_str(), nullptr))
            << h[i][k] << " vs " << d[i][k];
        ++numbers;
      }
    }
    EXPECT_GT(numbers, 15 * (h.size() - 1) - 1);
  }
}

// The grader reads t in either form: hex and decimal answers grade alike.
TEST(ExportNumbers, GradeReadsHexAndDecimalAnswersAlike) {
  // Both answer files named alike, so both subjects are "ans/double".
  fs::create_directories(scratch("hex")), fs::create_directories(scratch("dec"));
  const fs::path cases = scratch("g-cases.csv"), hex = scratch("hex/ans.csv"), dec = scratch("dec/ans.csv");
  ASSERT_EQ(
      run_rayaudit("audit --export-cases " + cases.string() + " --numbers decimal --families edge --rays 2000").code,
      0);
  // The exact t of each crossing as the answer: hex from the value, decimal
  // as the export wrote it.
  const auto rs = rows(cases);
  std::ofstream h(hex), d(dec);
  h << "id,hit,t\n";
  d << "id,hit,t\n";
  for (std::size_t i = 1; i < rs.size(); ++i) {
    const std::string& t = rs[i][19];
    const bool hit = rs[i][18] == "hit";
    char buf[64] = "";
    if (hit) std::snprintf(buf, sizeof buf, "%a", std::strtod(t.c_str(), nullptr));
    h << rs[i][0] << ',' << (hit ? "true" : "false") << ',' << buf << '\n';
    d << rs[i][0] << ',' << (hit ? "true" : "false") << ',' << (hit ? t : "") << '\n';
  }
  h.close(), d.close();
  const fs::path jh = scratch("gh.json"), jd = scratch("gd.json");
  const auto a =
      run_rayaudit("audit --grade " + hex.string() + " --cases " + cases.string() + " --json " + jh.string());
  const auto b =
      run_rayaudit("audit --grade " + dec.string() + " --cases " + cases.string() + " --json " + jd.string());
  ASSERT_EQ(a.code, 0) << a.all;
  ASSERT_EQ(b.code, 0) << b.all;
  const auto ja = nlohmann::json::parse(slurp(jh)), jb = nlohmann::json::parse(slurp(jd));
  EXPECT_EQ(ja["cells"], jb["cells"]) << "the same counts, t errors included";
  EXPECT_EQ(ja["subjects"], jb["subjects"]);
  const auto& totals = ja["subjects"][0]["totals"];
  EXPECT_GT(totals["t_samples"].get<int>(), 100);
  EXPECT_EQ(totals["t_ulps_max"], 0) << "the exact t, read back exactly in either form";
}

TEST(ExportNumbers, NumbersNeedsExportAndAKnownForm) {
  EXPECT_EQ(run_rayaudit("audit --numbers decimal --methods moller --families edge --rays 10").code, 2);
  const fs::path out = scratch("bad-numbers.csv");
  const auto r = run_rayaudit("audit --export-cases " + out.string() + " --numbers octal --families edge --rays 10");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--numbers"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}
