// Text read line by line with every kind of line end counted: \n, \r\n and
// a lone \r (classic Mac OS), so messages name the right line.
#pragma once
#include <cstdio>
#include <istream>
#include <string>

namespace ra {

// Like std::getline, but a line also ends at a lone '\r'; the line end is
// not part of `line`. false (and the stream's fail state) at the end of
// the input; a last line without a line end is still a line.
inline bool read_text_line(std::istream& in, std::string& line) {
  line.clear();
  std::streambuf* sb = in.rdbuf();
  if (!in.good() || !sb) return false;
  bool any = false;
  for (;;) {
    const int c = sb->sbumpc();
    if (c == EOF) {
      in.setstate(any ? std::ios::eofbit : std::ios::eofbit | std::ios::failbit);
      return any;
    }
    any = true;
    if (c == '\n') return true;
    if (c == '\r') {
      if (sb->sgetc() == '\n') sb->sbumpc();
      return true;
    }
    line.push_back(char(c));
  }
}

}  // namespace ra
