// JUnit XML writer (see junit.h): escaping by hand, so no XML library is
// needed; the tests read the output back with a real parser.
#include "junit.h"

#include <cstdio>

#include "io/atomic_file.h"

namespace ra::junit {

namespace {

// Length of the UTF-8 sequence starting at s[i] (0 when not valid UTF-8),
// and its code point.
std::size_t utf8_at(const std::string& s, std::size_t i, unsigned& cp) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned c = b(i);
  std::size_t n;
  if (c < 0x80) return cp = c, 1;
  if ((c & 0xE0) == 0xC0)
    n = 2, cp = c & 0x1F;
  else if ((c & 0xF0) == 0xE0)
    n = 3, cp = c & 0x0F;
  else if ((c & 0xF8) == 0xF0)
    n = 4, cp = c & 0x07;
  else
    return 0;
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3F);
  }
  // Overlong forms, surrogates and values past U+10FFFF are not UTF-8.
  static const unsigned min_of[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < min_of[n] || (cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF) return 0;
  return n;
}

std::string format_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", s >= 0 ? s : 0.0);
  return buf;
}

}  // namespace

std::string escape(const std::string& s, bool attribute) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    unsigned cp = 0;
    const std::size_t n = utf8_at(s, i, cp);
    if (n == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD for a byte that is not UTF-8
      ++i;
      continue;
    }
    switch (cp) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      // Attribute values would have these normalised to spaces: kept as references.
      case '\t':
        out += attribute ? "&#9;" : "\t";
        break;
      case '\n':
        out += attribute ? "&#10;" : "\n";
        break;
      case '\r':
        out += "&#13;";
        break;
      default:
        // XML 1.0 has no C0 controls but tab and line ends, and no U+FFFE/FFFF.
        if (cp < 0x20 || cp == 0xFFFE || cp == 0xFFFF)
          out += "\xEF\xBF\xBD";
        else
          out.append(s, i, n);
    }
    i += n;
  }
  return out;
}

std::string to_xml(const std::vector<Suite>& suites) {
  std::size_t tests = 0, failures = 0, skipped = 0;
  double seconds = 0;
  for (const Suite& su : suites)
    for (const Case& c : su.cases) {
      ++tests;
      failures += c.status == Case::Status::fail;
      skipped += c.status == Case::Status::skip;
      seconds += c.seconds;
    }
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<testsuites tests=\"" + std::to_string(tests) + "\" failures=\"" + std::to_string(failures) +
       "\" errors=\"0\" skipped=\"" + std::to_string(skipped) + "\" time=\"" + format_seconds(seconds) + "\">\n";
  for (const Suite& su : suites) {
    std::size_t f = 0, sk = 0;
    double t = 0;
    for (const Case& c : su.cases)
      f += c.status == Case::Status::fail, sk += c.status == Case::Status::skip, t += c.seconds;
    x += " <testsuite name=\"" + escape(su.name) + "\" tests=\"" + std::to_string(su.cases.size()) + "\" failures=\"" +
         std::to_string(f) + "\" errors=\"0\" skipped=\"" + std::to_string(sk) + "\" time=\"" + format_seconds(t) +
         "\">\n";
    for (const Case& c : su.cases) {
      x += "  <testcase classname=\"" + escape(c.classname) + "\" name=\"" + escape(c.name) + "\" time=\"" +
           format_seconds(c.seconds) + "\"";
      if (c.status == Case::Status::pass) {
        x += "/>\n";
        continue;
      }
      const char* tag = c.status == Case::Status::fail ? "failure" : "skipped";
      x += ">\n   <" + std::string(tag) + " message=\"" + escape(c.message) + "\"";
      if (c.status == Case::Status::fail) x += " type=\"failure\"";
      if (c.text.empty())
        x += "/>\n";
      else
        x += ">" + escape(c.text, false) + "</" + tag + ">\n";
      x += "  </testcase>\n";
    }
    x += " </testsuite>\n";
  }
  x += "</testsuites>\n";
  return x;
}

void write(const std::filesystem::path& path, const std::vector<Suite>& suites) {
  write_text_atomically(path, to_xml(suites));
}

}  // namespace ra::junit
