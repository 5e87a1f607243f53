// Small scanning helpers shared by the OBJ and MTL parsers (fast_obj style:
// each takes a pointer into one buffer and returns the pointer after what it
// read; nothing allocates). A "statement" is one logical line: physical lines
// joined by a `\` right before their end (LF or CRLF), unless the line holds
// a `#` (a comment ends at its line end).
#pragma once
#include <bit>
#include <charconv>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "../errors.h"
#include "mesh.h"

namespace ra::objtext {

// Warnings of one kind: the first ten one line each, the rest counted in
// one line by finish() (50,000 missing mtllib files, undefined
// materials or statements before newmtl printed 50,000 lines).
struct CappedWarnings {
  static constexpr long kShown = 10;
  std::vector<std::string>& out;
  std::string file;
  std::string rest;  // "more material libraries not found"
  long n = 0, first_line = 0;
  void add(long line, std::string message) {
    if (++n <= kShown)
      out.push_back(std::move(message));
    else if (n == kShown + 1)
      first_line = line;
  }
  void finish() {
    if (n > kShown) out.push_back(located(file, first_line, std::to_string(n - kShown) + " " + rest));
    n = 0;
  }
};

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// True if the line break at `nl` (pointing at '\n') is escaped by `\`.
// `begin` is at or before the start of nl's physical line. A comment ends at
// its line end: a physical line holding a `#` anywhere is never continued
// (`v 0 0 0 # note \` must not swallow the next line). The scan back over
// the line runs only when a `\` is right before the line end (rare).
inline bool escaped_newline(const char* begin, const char* nl) {
  const char* q = nl;
  if (q > begin && q[-1] == '\r') --q;
  if (!(q > begin && q[-1] == '\\')) return false;
  for (const char* s = q - 1; s > begin && s[-1] != '\n'; --s)
    if (s[-1] == '#') return false;
  return true;
}

// End of the statement starting at p: the '\n' ending it (or end). Adds to
// `lines` the number of escaped line breaks inside it.
inline const char* statement_end(const char* p, const char* end, long& lines) {
  const char* begin = p;
  for (;;) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', size_t(end - p)));
    if (!nl) return end;
    if (!escaped_newline(begin, nl)) return nl;
    ++lines;
    p = nl + 1;
  }
}

// Skips whitespace and escaped line breaks, up to `end` (a statement end).
inline const char* skip_ws(const char* p, const char* end) {
  for (;;) {
    while (p < end && is_space(*p)) ++p;
    if (p < end && *p == '\\') {
      const char* q = p + 1;
      if (q < end && *q == '\r') ++q;
      if (q < end && *q == '\n') {
        p = q + 1;
        continue;
      }
    }
    return p;
  }
}

// At a value's end: whitespace, the statement's end, a comment or `\` + EOL.
inline bool at_separator(const char* p, const char* end) {
  if (p >= end) return true;
  char c = *p;
  if (is_space(c) || c == '#' || c == '\n') return true;
  if (c == '\\') {
    const char* q = p + 1;
    if (q < end && *q == '\r') ++q;
    return q >= end || *q == '\n';
  }
  return false;
}

// True when the rest of the statement is empty or a comment.
inline bool at_statement_end(const char* p, const char* end) {
  p = skip_ws(p, end);
  return p >= end || *p == '#';
}

// The token starting at p (up to whitespace), for messages, at most 40 chars.
inline std::string token_text(const char* p, const char* end) {
  const char* q = p;
  while (q < end && !is_space(*q) && *q != '\n' && q - p < 40) ++q;
  return std::string(p, q);
}

// Thrown-message helper bound to a file name.
struct Where {
  const std::string* file;
  [[noreturn]] void fail(long line, const std::string& msg) const { throw InputError(located(*file, line, msg)); }
};

inline bool starts_with_ci(const char* p, const char* end, const char* word) {
  for (; *word; ++word, ++p) {
    if (p >= end) return false;
    char c = *p;
    if (c >= 'a' && c <= 'z') c = char(c - 32);
    if (c != *word) return false;
  }
  return true;
}

// Up to 8 ASCII digits at p, 8 bytes of which must be readable (SWAR: one
// load, the run length from a carry-free per-byte compare, the value from
// three multiplies, as in fast_float's parse_eight_digits_unrolled).
// Returns how many digits (0..8) and their value.
[[gnu::always_inline]] inline int eight_digits(const char* p, std::uint64_t& value) {
  std::uint64_t x;
  std::memcpy(&x, p, 8);
  if constexpr (std::endian::native == std::endian::big) x = __builtin_bswap64(x);
  const std::uint64_t t = x ^ 0x3030303030303030ull;  // digits become bytes 0..9
  // A byte > 9 gets its top bit from t + 0x76 (no carry out of a byte <= 9,
  // so the lowest flagged byte is exact) or, if >= 0x80, from t itself.
  const std::uint64_t nd = ((t + 0x7676767676767676ull) | t) & 0x8080808080808080ull;
  const int n = nd ? __builtin_ctzll(nd) >> 3 : 8;
  if (n == 0) {
    value = 0;
    return 0;
  }
  std::uint64_t v = t << (8 * (8 - n));  // leading zeros in the low bytes
  v = v * 10 + (v >> 8);
  v = (((v & 0x000000FF000000FFull) * (100 + (1000000ull << 32))) +
       (((v >> 16) & 0x000000FF000000FFull) * (1 + (10000ull << 32)))) >>
      32;
  value = v;
  return n;
}

// Reads a run of decimal digits at s (advancing it): mant = mant * 10^k +
// digits, digits += k. mant wraps silently past 19 digits: callers reject
// those by the count.
inline void read_digits(const char*& s, const char* end, std::uint64_t& mant, int& digits) {
  static constexpr std::uint64_t kP10[] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000};
  while (end - s >= 8) {
    std::uint64_t v;
    const int n = eight_digits(s, v);
    mant = mant * kP10[n] + v;
    digits += n;
    s += n;
    if (n < 8) return;
  }
  while (s < end && unsigned(*s - '0') < 10) mant = mant * 10 + unsigned(*s++ - '0'), ++digits;
}

// Clinger's fast path: [sign] digits [. digits] [e [sign] digits] with at
// most 19 significant-or-not digits, a mantissa <= 2^53 and a power of ten
// |e| <= 22 is mantissa x 10^e or mantissa / 10^-e, one correctly rounded
// operation on exact values, so the same double from_chars gives. Returns
// false (p unchanged) for anything else (long numbers, large exponents, a
// malformed exponent): the caller then uses from_chars.
inline bool fast_double(const char*& p, const char* end, double& out) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                      1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const char* s = p;
  bool neg = false;
  if (s < end && (*s == '-' || *s == '+')) neg = *s++ == '-';
  std::uint64_t mant = 0;
  int digits = 0, frac = 0;
  std::uint64_t ip, fp;
  int ni, nf;
  if (end - s >= 17 && (ni = eight_digits(s, ip)) < 8 && s[ni] == '.' && (nf = eight_digits(s + ni + 1, fp)) < 8) {
    // the usual short `i.f` (under 8 digits each side): two loads, no loops
    static constexpr std::uint64_t kP10[] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000};
    mant = ip * kP10[nf] + fp;
    digits = ni + nf, frac = nf;
    s += ni + 1 + nf;
  } else {
    read_digits(s, end, mant, digits);
    if (s < end && *s == '.') {
      ++s;
      const int before = digits;
      read_digits(s, end, mant, digits);
      frac = digits - before;
    }
  }
  if (digits == 0 || digits > 19 || mant > (1ull << 53)) return false;
  int e10 = -frac;
  if (s < end && (*s == 'e' || *s == 'E')) {
    ++s;
    bool eneg = false;
    if (s < end && (*s == '-' || *s == '+')) eneg = *s++ == '-';
    const char* d = s;
    int e = 0;
    while (s < end && unsigned(*s - '0') < 10 && s - d < 4) e = e * 10 + (*s++ - '0');
    if (s == d || (s < end && unsigned(*s - '0') < 10)) return false;  // no digits, or more than 4
    e10 += eneg ? -e : e;
  }
  double v;
  if (mant == 0)
    v = 0;
  else if (e10 < 0 && e10 >= -22)
    v = double(mant) / kPow10[-e10];
  else if (e10 >= 0 && e10 <= 22)
    v = double(mant) * kPow10[e10];
  else
    return false;
  out = neg ? -v : v;
  p = s;
  return true;
}

// Parses one number at p (after whitespace): from_chars plus a leading '+'.
// On success returns the pointer after it; errors name the token.
inline const char* parse_double(const char* p, const char* end, double& out, const Where& w, long line) {
  p = skip_ws(p, end);
  const char* tok = p;
  const char* q = p;
  std::errc ec{};
  if (fast_double(q, end, out)) {
    if (q >= end || (*q != '#' && at_separator(q, end))) return q;  // the common case
  } else {
    if (p < end && *p == '+') ++p;
    auto r = std::from_chars(p, end, out, std::chars_format::general);
    q = r.ptr;
    ec = r.ec;
  }
  if (p < end && (*p == '+' || *p == '-') && tok != p) ec = std::errc::invalid_argument;  // "+-1"
  if (q - tok > kMaxNumberChars && ec != std::errc::invalid_argument)
    w.fail(line, "number too long (" + std::to_string(q - tok) + " characters, at most " +
                     std::to_string(kMaxNumberChars) + ")");
  if (ec == std::errc::result_out_of_range) w.fail(line, "number out of range '" + token_text(tok, end) + "'");
  if (ec != std::errc()) {
    if (tok >= end || *tok == '#' || *tok == '\n') w.fail(line, "expected a number, found the end of the line");
    w.fail(line, "malformed number '" + token_text(tok, end) + "'");
  }
  if (q < end && *q == '#' &&
      (starts_with_ci(q + 1, end, "IND") || starts_with_ci(q + 1, end, "INF") || starts_with_ci(q + 1, end, "QNAN") ||
       starts_with_ci(q + 1, end, "SNAN")))
    w.fail(line, "non-finite number '" + token_text(tok, end) + "' (MSVC notation) is not accepted");
  if (!at_separator(q, end)) w.fail(line, "malformed number '" + token_text(tok, end) + "'");
  if (!std::isfinite(out)) w.fail(line, "non-finite number '" + token_text(tok, end) + "' is not accepted");
  return q;
}

// Reads up to `max` numbers into out; returns how many were read. Stops at
// the statement end or a comment; anything else that is not a number is an
// error, as is a (max+1)-th number.
inline int parse_numbers(const char*& p, const char* end, double* out, int max, const Where& w, long line,
                         const char* what) {
  int n = 0;
  for (;;) {
    p = skip_ws(p, end);
    if (p >= end || *p == '#') return n;
    if (n == max) w.fail(line, std::string(what) + ": too many values (at most " + std::to_string(max) + ")");
    p = parse_double(p, end, out[n], w, line);
    ++n;
  }
}

// The rest of the statement as a name: leading/trailing whitespace removed,
// inner whitespace kept, cut at a '#' that follows whitespace (a comment),
// escaped line breaks kept verbatim (rare; names rarely span lines).
inline std::string_view rest_as_name(const char* p, const char* end) {
  p = skip_ws(p, end);
  const char* q = p;
  while (q < end && *q != '\n') {
    if (*q == '#' && (q == p || is_space(q[-1]))) break;
    ++q;
  }
  while (q > p && (is_space(q[-1]) || q[-1] == '\\')) --q;
  return {p, size_t(q - p)};
}

// Checks the encoding of a whole text: UTF-16 BOMs and NUL bytes are errors;
// returns the text without a UTF-8 BOM.
inline std::string_view check_encoding(std::string_view text, const std::string& name) {
  if (text.size() >= 2 && ((unsigned char)text[0] == 0xFE && (unsigned char)text[1] == 0xFF))
    throw InputError(located(name, 1, "UTF-16 (big-endian BOM) is not supported: convert the file to UTF-8"));
  if (text.size() >= 2 && ((unsigned char)text[0] == 0xFF && (unsigned char)text[1] == 0xFE))
    throw InputError(located(name, 1, "UTF-16 (little-endian BOM) is not supported: convert the file to UTF-8"));
  if (text.size() >= 3 && (unsigned char)text[0] == 0xEF && (unsigned char)text[1] == 0xBB &&
      (unsigned char)text[2] == 0xBF)
    text.remove_prefix(3);
  // CR-only line ends (classic Mac OS) are not read as line breaks (a lone CR
  // is whitespace, so the whole file would be one statement): say so rather
  // than report the first symptom ("malformed number 'v'"). Detected on the
  // first line: a CR followed by anything but whitespace before any LF.
  {
    const char* b = text.data();
    const void* lf = std::memchr(b, '\n', text.size());
    const char* lim = lf ? static_cast<const char*>(lf) : b + text.size();
    for (const char* c = b; (c = static_cast<const char*>(std::memchr(c, '\r', size_t(lim - c)))) != nullptr;) {
      ++c;
      if (c < lim && !is_space(*c))
        throw InputError(located(name, 1,
                                 "the file uses CR-only line ends (classic Mac OS), which are not "
                                 "supported: convert them to LF or CRLF"));
    }
  }
  if (const void* z = std::memchr(text.data(), 0, text.size())) {
    const char* zp = static_cast<const char*>(z);
    long line = 1;
    for (const char* c = text.data(); c < zp; ++c) line += (*c == '\n');
    throw InputError(located(name, line, "NUL byte in a text file (UTF-16 without BOM, or binary?)"));
  }
  return text;
}

}  // namespace ra::objtext
