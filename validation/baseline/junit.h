// JUnit XML for CI systems (GitHub Actions' and GitLab's test reports,
// Jenkins): one <testcase> per judged thing (an audit's subject x family, a
// golden scene, a POV-Ray comparison), failing with the words the command
// prints. The schema followed is the common subset those readers take
// (testsuites > testsuite > testcase > failure | skipped, with message and
// body), as Apache Ant's JUnit task first wrote it.
//
// Guarantee: the document is well-formed XML 1.0 whatever the names hold:
// markup characters are escaped, characters XML 1.0 forbids (C0 controls
// other than tab and line ends) and bytes that are not UTF-8 become U+FFFD.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace ra::junit {

struct Case {
  std::string classname;  // e.g. "audit.moller/float", "golden"
  std::string name;       // e.g. "grazing", a scene's name
  enum class Status { pass, fail, skip } status = Status::pass;
  std::string message;  // one line: the failure or skip reason
  std::string text;     // the body: the table's rows, ids, the replay command
  double seconds = 0;
};

struct Suite {
  std::string name;  // e.g. "rayaudit audit"
  std::vector<Case> cases;
};

// The whole document.
std::string to_xml(const std::vector<Suite>& suites);

// Writes to_xml() through ra::write_text_atomically (an OutputBatch that
// declared `path` defers the rename to its commit).
void write(const std::filesystem::path& path, const std::vector<Suite>& suites);

// `s` as XML attribute text, or character data when !attribute (line ends
// kept as they are); exposed for the tests.
std::string escape(const std::string& s, bool attribute = true);

}  // namespace ra::junit
