// Reading user cases and writing generated cases as CSV (see cases_csv.h);
// numbers are read with std::strtod and written as %a or as the shortest decimal
// that reads back the same (std::to_chars), so the round trip is exact either way.
#include "cases_csv.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string_view>
#include <unordered_set>

#include "audit.h"
#include "errors.h"
#include "io/input_file.h"
#include "io/text_lines.h"

namespace ra::audit {

namespace {

const char* const kColumns[15] = {"ox", "oy", "oz", "dx", "dy", "dz", "ax", "ay",
                                  "az", "bx", "by", "bz", "cx", "cy", "cz"};

std::string number(double x, Numbers n) {
  char buf[64];
  if (n == Numbers::hex) {
    std::snprintf(buf, sizeof buf, "%a", x);
    return buf;
  }
  // Shortest round trip: to_chars without a precision (C++17).
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, ec == std::errc() ? end : buf);
}

// A column named twice would make one of the two silently ignored.
void check_unique_columns(const std::string& path, long lineno, const std::vector<std::string>& header) {
  // A set, not all pairs: a header of 200k columns took over 20 s.
  std::unordered_set<std::string_view> seen;
  seen.reserve(header.size());
  for (const auto& h : header)
    if (!h.empty() && !seen.insert(h).second)
      throw InputError(located(path, lineno, "column '" + h + "' appears twice in the header"));
}

}  // namespace

// The header line as UTF-8 text: a UTF-8 byte-order mark (as spreadsheets
// write) is dropped; UTF-16 (a BOM or NUL bytes) is refused by name rather
// than reported as a missing column.
void check_header_encoding(const std::string& path, long lineno, std::string& line) {
  if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
  if (line.rfind("\xFF\xFE", 0) == 0 || line.rfind("\xFE\xFF", 0) == 0 || line.find('\0') != std::string::npos)
    throw InputError(located(path, lineno, "the file is UTF-16 (or holds NUL bytes): save it as UTF-8 or ASCII"));
}

std::vector<std::string> split_fields(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char ch : line) {
    if (ch == sep)
      out.push_back(cur), cur.clear();
    else
      cur += ch;
  }
  out.push_back(cur);
  for (auto& f : out) {
    const auto b = f.find_first_not_of(" \t"), e = f.find_last_not_of(" \t");
    f = b == std::string::npos ? "" : f.substr(b, e - b + 1);
  }
  return out;
}

// The whole field must be one number (decimal or hex float).
bool parse_double(const std::string& s, double& out) {
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  // Underflow to a subnormal is fine (an exported %a may be subnormal); overflow is not.
  return end == s.c_str() + s.size() && !(errno == ERANGE && std::isinf(out));
}

std::vector<UserCase> read_cases_csv(const std::string& path) {
  std::vector<UserCase> cases;
  for_each_case(path, [&](const UserCase& c, long) { cases.push_back(c); });
  return cases;
}

std::vector<std::string> read_csv_header(std::istream& in, const std::string& path, long& lineno) {
  std::string line;
  std::vector<std::string> header;
  while (header.empty() && read_text_line(in, line)) {
    ++lineno;
    check_header_encoding(path, lineno, line);
    // Lines starting with '#' before the header are comments (an export's
    // stamp, exact/../baseline/stamp.h).
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line[first] != '#') header = split_fields(line);
  }
  check_unique_columns(path, lineno, header);
  return header;
}

void for_each_case(const std::string& path, const std::function<void(const UserCase&, long line)>& visit) {
  check_input_file(path);  // a directory is not "empty", a FIFO does not block
  std::ifstream in(path);
  if (!in) throw InputError(located(path, 0, "cannot open the cases file"));
  std::string line;
  long lineno = 0;
  const std::vector<std::string> header = read_csv_header(in, path, lineno);
  if (header.empty()) throw InputError(located(path, lineno, "empty file: expected a header line"));
  int col[15];
  int id_col = -1;
  for (int k = 0; k < 15; ++k) {
    col[k] = -1;
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == kColumns[k]) col[k] = int(i);
    if (col[k] < 0)
      throw InputError(located(
          path, lineno,
          std::string("missing column '") + kColumns[k] + "' in the header (need ox,oy,oz,dx,dy,dz,ax,...,cz)"));
  }
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == "id") id_col = int(i);

  long row = 0;
  while (read_text_line(in, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    ++row;
    const auto f = split_fields(line);
    if (f.size() != header.size())
      throw InputError(located(
          path, lineno,
          "expected " + std::to_string(header.size()) + " fields as in the header, found " + std::to_string(f.size())));
    double v[15];
    for (int k = 0; k < 15; ++k) {
      const bool number = parse_double(f[std::size_t(col[k])], v[k]);
      if (!number || !std::isfinite(v[k])) {
        // A NaN or infinite coordinate was accepted and judged; a 2 MB
        // number was quoted whole.
        const std::string& t = f[std::size_t(col[k])];
        const std::string shown = t.size() > 40 ? t.substr(0, 40) + "... (" + std::to_string(t.size()) + " bytes)" : t;
        throw InputError(located(path, lineno,
                                 std::string("column '") + kColumns[k] + "': '" + shown +
                                     (number ? "' is not a finite number" : "' is not a number")));
      }
    }
    UserCase c;
    c.id_is_row = id_col < 0;
    c.id = id_col < 0 ? std::to_string(row) : f[std::size_t(id_col)];
    c.ray = Rayd{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    c.tri = {{v[6], v[7], v[8]}, {v[9], v[10], v[11]}, {v[12], v[13], v[14]}};
    visit(c, lineno);
  }
}

std::string cases_csv_header() {
  // Appends piece by piece (GCC 12 warns falsely on `"," + std::string`).
  std::string out = "id,family,sweep";
  for (const char* c : kColumns) out.append(",").append(c);
  out.append(",verdict,t\n");
  return out;
}

std::string cases_csv_row(const ExportRow& r, Numbers n) {
  std::string out;
  out.append(r.id).append(",").append(r.family).append(",").append(r.sweep);
  const double v[15] = {r.ray.o.x, r.ray.o.y, r.ray.o.z, r.ray.d.x, r.ray.d.y, r.ray.d.z, r.tri.a.x, r.tri.a.y,
                        r.tri.a.z, r.tri.b.x, r.tri.b.y, r.tri.b.z, r.tri.c.x, r.tri.c.y, r.tri.c.z};
  for (double x : v) out.append(",").append(number(x, n));
  out.append(",").append(oracle::verdict_name(r.answer.verdict)).append(",");
  if (std::isfinite(r.answer.t)) out.append(number(r.answer.t, n));
  out.append("\n");
  return out;
}

std::string cases_csv(const std::vector<ExportRow>& rows, Numbers n) {
  std::string out = cases_csv_header();
  for (const ExportRow& r : rows) out.append(cases_csv_row(r, n));
  return out;
}

long long for_each_export_row(const std::vector<std::string>& fams, Precision p, std::uint64_t seed, long long rays,
                              const std::function<void(const ExportRow&)>& visit) {
  long long n = 0;
  for (const Family& f : families()) {
    if (f.kind != Kind::triangle || f.secondary) continue;
    if (!fams.empty() && std::find(fams.begin(), fams.end(), f.name) == fams.end()) continue;
    for (int s = 0; s < int(f.sweep.size()); ++s) {
      long long i = 0;
      for_each_probe_case(f, s, p, seed, rays, [&](const ProbeCase& pc) {
        for (std::size_t k = 0; k < pc.tris.size(); ++k, ++n)
          visit({f.name + ":" + f.sweep[std::size_t(s)] + ":" + std::to_string(i) + ":" + std::to_string(k), f.name,
                 f.sweep[std::size_t(s)], pc.ray, pc.tris[k], pc.answers[k]});
        ++i;
      });
    }
  }
  return n;
}

std::vector<ExportRow> export_rows(const std::vector<std::string>& fams, Precision p, std::uint64_t seed,
                                   long long rays) {
  std::vector<ExportRow> rows;
  for_each_export_row(fams, p, seed, rays, [&](const ExportRow& r) { rows.push_back(r); });
  return rows;
}

}  // namespace ra::audit
