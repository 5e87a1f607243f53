// Test helper: reads a JUnit XML file with a real XML parser (Python's
// xml.etree, from Debian's python3), so a malformed document fails the test.
#pragma once
#include <array>
#include <cstdio>
#include <string>

namespace ra::test {

struct JUnitRead {
  bool parsed = false;
  // One line per test case: "CLASSNAME|NAME|ok" or "|FAIL: message" or "|SKIP: message".
  std::string cases;
};

inline JUnitRead read_junit(const std::string& path) {
  const std::string script =
      "import sys, xml.etree.ElementTree as E\n"
      "root = E.parse(sys.argv[1]).getroot()\n"
      "assert root.tag == 'testsuites', root.tag\n"
      "for s in root.iter('testsuite'):\n"
      "    cases = s.findall('testcase')\n"
      "    assert int(s.get('tests')) == len(cases)\n"
      "    assert int(s.get('failures')) == sum(c.find('failure') is not None for c in cases)\n"
      "for c in root.iter('testcase'):\n"
      "    f, k = c.find('failure'), c.find('skipped')\n"
      "    v = 'FAIL: ' + f.get('message') if f is not None else ('SKIP: ' + k.get('message') if k is not None else "
      "'ok')\n"
      "    print(c.get('classname') + '|' + c.get('name') + '|' + v.replace('\\n', ' '))\n";
  const std::string cmd = "/usr/bin/python3 -c \"$RA_JUNIT_SCRIPT\" '" + path + "' 2>&1";
  ::setenv("RA_JUNIT_SCRIPT", script.c_str(), 1);
  JUnitRead r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.cases.append(buf.data(), n);
  r.parsed = pclose(p) == 0;
  return r;
}

}  // namespace ra::test
