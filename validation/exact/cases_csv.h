// User-supplied ray/triangle cases as CSV (`rayaudit audit --cases`), and the
// export of generated cases with their exact verdicts as portable test vectors.
//
// Format: a header line naming the columns; required ox,oy,oz,dx,dy,dz,
// ax,ay,az,bx,by,bz,cx,cy,cz (decimal or C99 hex floats, whole field
// consumed by std::strtod); optional id; every other column ignored. Fields
// are separated by commas, without quoting; blank lines are skipped. The ray
// is {o + t d : t >= 0}. The export writes id,family,sweep, the 15 inputs as
// %a (or, with Numbers::decimal, the shortest decimal that reads back the
// same double), then verdict and t (likewise, empty when there is no crossing).
#pragma once
#include <functional>
#include <istream>
#include <string>
#include <vector>

#include "families.h"
#include "oracle.h"

namespace ra::audit {

struct UserCase {
  std::string id;  // the id column, or the 1-based data row number
  bool id_is_row = false;
  Rayd ray;
  Tri tri;
};

// Throws ra::InputError "FILE:LINE: what is wrong" on a missing file, a
// missing column, a wrong field count or a bad number.
std::vector<UserCase> read_cases_csv(const std::string& path);

// The same parser, streaming: calls visit(case, line) for each data row in
// file order, holding one row at a time, so memory does not grow with the
// file. Rows before a malformed one have been visited when it
// throws: callers that must write nothing on bad input read twice (a first
// pass with a no-op visitor).
void for_each_case(const std::string& path, const std::function<void(const UserCase&, long line)>& visit);

struct ExportRow {
  std::string id, family, sweep;
  Rayd ray;
  Tri tri;
  oracle::Answer answer;
};
// How the export writes numbers: C99 hex floats (%a), or decimal, the
// shortest text that reads back as the same double (std::to_chars), for
// languages without a hex-float parser (JavaScript's Number() reads it
// exactly). Both read back exactly through std::strtod.
enum class Numbers { hex, decimal };
std::string cases_csv(const std::vector<ExportRow>& rows, Numbers n = Numbers::hex);
// The header line of cases_csv(), and one row of it.
std::string cases_csv_header();
std::string cases_csv_row(const ExportRow& r, Numbers n = Numbers::hex);

// The generated cases of the given triangle families (the secondary family,
// whose rays depend on each method, and sphere families are skipped).
std::vector<ExportRow> export_rows(const std::vector<std::string>& families, Precision p, std::uint64_t seed,
                                   long long rays);
// The same rows one at a time, in the same order, holding one probe's cases
// at a time (2M rows held 1.7 GB). Returns the number of rows.
long long for_each_export_row(const std::vector<std::string>& families, Precision p, std::uint64_t seed, long long rays,
                              const std::function<void(const ExportRow&)>& visit);

// The fields of one CSV line split at `sep`, each trimmed of spaces and tabs
// (shared by the cases and the graded answers readers).
std::vector<std::string> split_fields(const std::string& line, char sep = ',');

// The header line as UTF-8 text: a UTF-8 byte-order mark is dropped; UTF-16
// (a BOM or NUL bytes) is refused by name (InputError FILE:LINE), not
// reported as a missing column. Shared by the cases and answers readers.
void check_header_encoding(const std::string& path, long lineno, std::string& line);
// The first non-blank line of `in` as header fields (encoding checked,
// a column named twice refused); lineno counts the lines read. Empty if the
// file holds no header: the caller says what it expected.
std::vector<std::string> read_csv_header(std::istream& in, const std::string& path, long& lineno);
// True if the whole field is one number (decimal or hex float) that does not
// overflow; underflow to a subnormal is accepted.
bool parse_double(const std::string& s, double& out);

}  // namespace ra::audit
