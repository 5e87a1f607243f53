// A SAX front end to nlohmann's DOM parser (raw library messages,
// the line of an overflowing number, duplicate keys accepted silently).
#include <cstring>
#include "json_input.h"

#include <cstddef>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <vector>

#include "../errors.h"
#include "input_file.h"

namespace ra {
namespace {

using json = nlohmann::json;

// Lines end at \n, \r\n or a lone \r (a CR-only file put every error at
// line 1).
long line_at(const std::string& text, std::size_t byte) {
  long line = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i)
    line += text[i] == '\n' || (text[i] == '\r' && (i + 1 == text.size() || text[i + 1] != '\n'));
  return line;
}

// An iterator over the text that records how far the lexer has read, so a
// duplicate key can be placed on its line.
struct CountingIter {
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;
  const char* p;
  const char* base;
  std::size_t* read;
  reference operator*() const { return *p; }
  CountingIter& operator++() {
    ++p;
    *read = std::size_t(p - base);
    return *this;
  }
  CountingIter operator++(int) {
    CountingIter c = *this;
    ++*this;
    return c;
  }
  bool operator==(const CountingIter& o) const { return p == o.p; }
  bool operator!=(const CountingIter& o) const { return p != o.p; }
};

// A JSON pointer's reference token: '~' and '/' escaped (RFC 6901).
std::string pointer_token(const std::string& k) {
  std::string out;
  for (char c : k) out += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return out;
}

// line_at for a reader that moves forward: each call goes on from the
// last instead of from the start (the SAX records a line for every value;
// from the start each time, a 2,000-entry golden manifest took 12.8 s).
class LineCursor {
 public:
  explicit LineCursor(const std::string& text) : text_(text) {}
  long at(std::size_t byte) {
    if (byte < pos_) pos_ = 0, line_ = 1;
    for (; pos_ < byte && pos_ < text_.size(); ++pos_)
      line_ += text_[pos_] == '\n' || (text_[pos_] == '\r' && (pos_ + 1 == text_.size() || text_[pos_ + 1] != '\n'));
    return line_;
  }

 private:
  const std::string& text_;
  std::size_t pos_ = 0;
  long line_ = 1;
};

class Sax {
 public:
  Sax(json& root, const std::string& text, const std::string& file, const std::size_t& read, JsonLines* lines)
      : dom_(root, true), file_(file), read_(read), lines_(lines), cursor_(text) {}
  bool null() { return value(), dom_.null(); }
  bool boolean(bool v) { return value(), dom_.boolean(v); }
  bool number_integer(json::number_integer_t v) { return value(), dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value(), dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const std::string& s) { return value(), dom_.number_float(v, s); }
  bool string(std::string& v) { return value(), dom_.string(v); }
  bool binary(json::binary_t& v) { return value(), dom_.binary(v); }
  bool start_object(std::size_t n) {
    value();
    keys_.emplace_back();
    if (lines_) path_.push_back(frame(false));
    return dom_.start_object(n);
  }
  bool key(std::string& k) {
    if (!keys_.back().insert(k).second)
      throw InputError(located(file_, cursor_.at(read_), "key \"" + k + "\" given twice in one object"));
    if (lines_ && path_.back().tracked) {  // a member's line is its key's
      path_.back().key = pointer_token(k);
      (*lines_)[path_.back().prefix + "/" + path_.back().key] = cursor_.at(read_ ? read_ - 1 : 0);
    }
    return dom_.key(k);
  }
  bool end_object() {
    keys_.pop_back();
    if (lines_) path_.pop_back();
    return dom_.end_object();
  }
  bool start_array(std::size_t n) {
    value();
    // Only when lines are asked for: the pointers of a document nested a
    // million deep would take gigabytes (corpus scene/deep_nesting.json).
    if (lines_) path_.push_back(frame(true));
    return dom_.start_array(n);
  }
  bool end_array() {
    if (lines_) path_.pop_back();
    return dom_.end_array();
  }
  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& e) {
    const long line = cursor_.at(position == 0 ? 0 : position - 1);
    if (e.id == 406)  // number overflow: the lexer stands just after the number
      throw InputError(located(file_, line, "number " + token + " overflows a double"));
    std::string msg = e.what();
    const auto at = msg.find("syntax error");
    if (at != std::string::npos)
      msg = msg.substr(at);
    else if (const auto b = msg.find("] "); b != std::string::npos)
      msg = msg.substr(b + 2);
    throw InputError(located(file_, line, "invalid JSON: " + msg));
  }

 private:
  nlohmann::detail::json_sax_dom_parser<json> dom_;
  std::vector<std::set<std::string>> keys_;
  // Where each value sits, for JsonLines: the containers open around it.
  struct Frame {
    bool array;
    long index;           // arrays: the current element
    std::string prefix;   // the container's own pointer
    std::string key;      // objects: the current member's token
    bool tracked = true;  // false below kMaxLineDepth: no lines recorded
  };
  // Lines are recorded 64 containers deep at most (deeper values take their
  // ancestor's line): pointers of a document nested 100000 deep would
  // otherwise take quadratic time and memory.
  static constexpr std::size_t kMaxLineDepth = 64;
  Frame frame(bool array) const {
    if (path_.size() >= kMaxLineDepth) return {array, -1, "", "", false};
    return {array, -1, path_.empty() ? "" : pointer_now(), "", true};
  }
  std::string pointer_now() const {
    const Frame& f = path_.back();
    return f.prefix + "/" + (f.array ? std::to_string(f.index) : f.key);
  }
  // A value starts: an array element's line is where it starts.
  void value() {
    if (!lines_ || path_.empty() || !path_.back().array || !path_.back().tracked) return;
    ++path_.back().index;
    (*lines_)[pointer_now()] = cursor_.at(read_ ? read_ - 1 : 0);
  }
  const std::string& file_;
  const std::size_t& read_;
  JsonLines* lines_;
  LineCursor cursor_;
  std::vector<Frame> path_;
};

}  // namespace

json parse_json_text(const std::string& text, const std::string& file, JsonLines* lines) {
  // nlohmann reads UTF-8 only: UTF-16 would be "invalid literal; last read: '\xff'".
  if (text.rfind("\xFF\xFE", 0) == 0 || text.rfind("\xFE\xFF", 0) == 0 || text.find('\0') != std::string::npos)
    throw InputError(located(file, line_at(text, text.find('\0') == std::string::npos ? 0 : text.find('\0')),
                             "the file is UTF-16 (or holds NUL bytes): save it as UTF-8"));
  json root;
  std::size_t read = 0;
  Sax sax(root, text, file, read, lines);
  const char* b = text.data();
  CountingIter first{b, b, &read}, last{b + text.size(), b, &read};
  json::sax_parse(first, last, &sax);
  return root;
}

long JsonLines::at(const std::string& pointer) const {
  // The value itself, else the nearest enclosing one that was recorded.
  for (std::string p = pointer;; p.resize(p.rfind('/'))) {
    if (auto it = find(p); it != end()) return it->second;
    if (p.empty() || p.rfind('/') == std::string::npos) return 0;
  }
}

json read_json_file(const std::string& file, JsonLines* lines) {
  check_input_file(file);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(located(file, 0, "cannot open"));
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_json_text(ss.str(), file, lines);
}

std::string json_error_text(const std::exception& e) {
  std::string msg = e.what();
  if (msg.rfind("[json.exception.", 0) == 0)
    if (const auto b = msg.find("] "); b != std::string::npos) msg = msg.substr(b + 2);
  // nlohmann's wording, said as the other messages say it.
  if (msg.rfind("type must be ", 0) == 0) {
    const auto but = msg.find(", but is ");
    if (but != std::string::npos) return "expected a " + msg.substr(13, but - 13) + ", got " + msg.substr(but + 9);
  }
  if (msg.rfind("key '", 0) == 0 && msg.size() > 15 && msg.compare(msg.size() - 11, 11, "' not found") == 0)
    return "needs \"" + msg.substr(5, msg.size() - 16) + "\"";
  return msg;
}

std::string gbench_non_finite_to_null(const std::string& in) {
  std::string out;
  bool str = false;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const char c = in[i];
    if (str) {
      out += c;
      if (c == '\\' && i + 1 < in.size())
        out += in[++i];
      else if (c == '"')
        str = false;
      continue;
    }
    if (c == '"') str = true;
    bool replaced = false;
    for (const char* tok : {"-Infinity", "Infinity", "NaN", "-nan", "nan", "-inf", "inf"}) {
      const std::size_t n = std::strlen(tok);
      if (in.compare(i, n, tok) == 0) {
        out += "null";
        i += n - 1;
        replaced = true;
        break;
      }
    }
    if (!replaced) out += c;
  }
  return out;
}

}  // namespace ra
