#include "polymesh_io.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <unordered_set>

#include "../io/atomic_file.h"
#include "../errors.h"
#include "mesh.h"

namespace ra {
namespace {

// A whitespace tokenizer over a text that tracks line numbers.
struct Tokens {
  const char* p;
  const char* e;
  const std::string& name;
  long line = 1;

  [[noreturn]] void fail(const std::string& msg) const { throw InputError(located(name, line, msg)); }
  // A line ends at \n, \r\n or a lone \r (classic Mac OS): a CR-only file
  // was one line, its errors all at line 1.
  bool eol(const char* q) const { return *q == '\n' || (*q == '\r' && (q + 1 == e || q[1] != '\n')); }
  // Skips spaces (and line ends when `lines`), and '#' comments.
  void skip(bool lines) {
    for (;;) {
      while (p < e && (*p == ' ' || *p == '\t' || (*p == '\r' && !eol(p)) || (lines && eol(p)))) line += eol(p++);
      if (p < e && *p == '#') {
        while (p < e && !eol(p)) ++p;
        continue;
      }
      return;
    }
  }
  bool at_eol() {
    skip(false);
    return p >= e || eol(p);
  }
  void next_line() {
    while (p < e && !eol(p)) ++p;
    if (p < e) ++p, ++line;
  }
  std::string_view word() {
    skip(true);
    const char* b = p;
    while (p < e && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n') ++p;
    return {b, size_t(p - b)};
  }
  // True at the end of the text (after blank lines and comments).
  bool at_end() {
    skip(true);
    return p >= e;
  }
  // The next number on this line (OFF's lines are records).
  template <class T>
  T number_on_line(const char* what) {
    if (at_eol()) fail(std::string("expected ") + what + ", found the end of the line");
    return number<T>(what);
  }
  template <class T>
  T number(const char* what) {
    skip(true);
    T v{};
    const char* b = p;
    if (p < e && *p == '+') ++p;
    auto [q, ec] = std::from_chars(p, e, v);
    if (ec != std::errc() || (q < e && *q != ' ' && *q != '\t' && *q != '\r' && *q != '\n')) {
      const char* te = b;
      while (te < e && te - b < 20 && *te != ' ' && *te != '\t' && *te != '\r' && *te != '\n') ++te;
      fail(std::string("malformed ") + what + " '" + std::string(b, te) + "'");
    }
    p = q;
    return v;
  }
};

void check_faces(PolyMesh& m, const std::string& name) {
  const long n = long(m.positions.size());
  for (size_t f = 0; f + 1 < m.face_start.size(); ++f)
    for (int i = m.face_start[f]; i < m.face_start[f + 1]; ++i)
      if (m.indices[size_t(i)] < 0 || m.indices[size_t(i)] >= n)
        throw InputError(located(name, 0,
                                 "face " + std::to_string(f) + " has vertex index " +
                                     std::to_string(m.indices[size_t(i)]) + " out of range (" + std::to_string(n) +
                                     " vertices)"));
}

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };
struct PlyProp {
  std::string name;
  PlyType type;
  bool list = false;
  PlyType count_type = PlyType::U8;
  long line = 0;  // its header line, for errors about the property itself
};
struct PlyElement {
  std::string name;
  long count;
  std::vector<PlyProp> props;
  long line = 0;  // its header line
};

bool ply_type(std::string_view s, PlyType& t) {
  static const std::pair<const char*, PlyType> names[] = {
      {"char", PlyType::I8},   {"int8", PlyType::I8},     {"uchar", PlyType::U8},   {"uint8", PlyType::U8},
      {"short", PlyType::I16}, {"int16", PlyType::I16},   {"ushort", PlyType::U16}, {"uint16", PlyType::U16},
      {"int", PlyType::I32},   {"int32", PlyType::I32},   {"uint", PlyType::U32},   {"uint32", PlyType::U32},
      {"float", PlyType::F32}, {"float32", PlyType::F32}, {"double", PlyType::F64}, {"float64", PlyType::F64}};
  for (auto& [n, v] : names)
    if (s == n) return t = v, true;
  return false;
}
// ASCII values must fit their declared type (a char of 300 was taken as
// 300): false for a value outside it, or a fraction in an integer type.
bool fits_ply_type(PlyType t, double v) {
  switch (t) {
    case PlyType::I8:
      return v >= -128 && v <= 127 && v == std::floor(v);
    case PlyType::U8:
      return v >= 0 && v <= 255 && v == std::floor(v);
    case PlyType::I16:
      return v >= -32768 && v <= 32767 && v == std::floor(v);
    case PlyType::U16:
      return v >= 0 && v <= 65535 && v == std::floor(v);
    case PlyType::I32:
      return v >= -2147483648.0 && v <= 2147483647.0 && v == std::floor(v);
    case PlyType::U32:
      return v >= 0 && v <= 4294967295.0 && v == std::floor(v);
    case PlyType::F32:
      return !std::isfinite(v) ||
             std::fabs(v) <= 3.4028234663852886e38;  // 1e39 is no float (non-finite: said by the caller)
    default:
      return true;  // double: any number the reader accepted
  }
}

int ply_size(PlyType t) {
  switch (t) {
    case PlyType::I8:
    case PlyType::U8:
      return 1;
    case PlyType::I16:
    case PlyType::U16:
      return 2;
    case PlyType::I32:
    case PlyType::U32:
    case PlyType::F32:
      return 4;
    default:
      return 8;
  }
}

// Reads one binary value.
struct BinReader {
  const unsigned char* p;
  const unsigned char* b;
  const unsigned char* e;
  bool big;
  const std::string& name;
  double get(PlyType t) {
    const int n = ply_size(t);
    if (e - p < n) throw InputError(located(name, 0, "byte " + std::to_string(p - b) + ": file ends inside the data"));
    unsigned char buf[8];
    std::memcpy(buf, p, size_t(n));
    if (big) std::reverse(buf, buf + n);
    p += n;
    switch (t) {
      case PlyType::I8: {
        int8_t v;
        std::memcpy(&v, buf, 1);
        return v;
      }
      case PlyType::U8:
        return buf[0];
      case PlyType::I16: {
        int16_t v;
        std::memcpy(&v, buf, 2);
        return v;
      }
      case PlyType::U16: {
        uint16_t v;
        std::memcpy(&v, buf, 2);
        return v;
      }
      case PlyType::I32: {
        int32_t v;
        std::memcpy(&v, buf, 4);
        return v;
      }
      case PlyType::U32: {
        uint32_t v;
        std::memcpy(&v, buf, 4);
        return v;
      }
      case PlyType::F32: {
        float v;
        std::memcpy(&v, buf, 4);
        return v;
      }
      default: {
        double v;
        std::memcpy(&v, buf, 8);
        return v;
      }
    }
  }
};

// A value as a message shows it (nan, inf, 3.5, 7).
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The fewest bytes one row of `el` takes: each value's size in binary, and
// in ASCII one character and one separator a value.
std::size_t min_row_bytes(const PlyElement& el, int format) {
  std::size_t n = 0;
  for (const auto& pr : el.props) n += format == 0 ? 2 : std::size_t(ply_size(pr.list ? pr.count_type : pr.type));
  return std::max<std::size_t>(n, 1);  // a row without properties is still a line (or a byte)
}

// Every row takes at least a byte: more rows than bytes is refused at the
// header. Fewer, but still more than the data holds, fail where the data
// ends (with its line, or its byte offset in binary).
void check_ply_counts(const std::vector<PlyElement>& elements, std::size_t data_bytes, Tokens& t) {
  std::uint64_t rows = 0;
  for (const auto& el : elements) {
    rows += std::uint64_t(el.count);
    if (rows > data_bytes + 1)  // the last ASCII line may lack its newline
      t.fail("element '" + el.name + "' declares " + std::to_string(el.count) + " rows, more than the " +
             std::to_string(data_bytes) + " bytes after the header can hold");
  }
}

}  // namespace

PolyMesh parse_ply(std::string_view bytes, const std::string& name) {
  Tokens t{bytes.data(), bytes.data() + bytes.size(), name};
  if (t.word() != "ply") t.fail("not a PLY file (no 'ply' magic)");
  std::vector<PlyElement> elements;
  std::unordered_set<std::string> prop_names;  // the current element's
  int format = -1;                             // 0 ascii, 1 little, 2 big
  for (;;) {
    if (t.p >= t.e) t.fail("no end_header");
    const std::string_view k = t.word();
    if (k == "format") {
      if (format >= 0 || !elements.empty())
        t.fail(format >= 0 ? "a second format line" : "format line after an element");
      const auto f = t.word();
      format = f == "ascii" ? 0 : f == "binary_little_endian" ? 1 : f == "binary_big_endian" ? 2 : -1;
      if (format < 0) t.fail("unknown PLY format '" + std::string(f) + "'");
      // Only version 1.0 exists: "2.0" was read as if it were 1.0.
      if (t.at_eol()) t.fail("format line without a version (format " + std::string(f) + " 1.0)");
      const auto version = t.word();
      if (version != "1.0" && version != "1") t.fail("PLY version '" + std::string(version) + "' (only 1.0 is known)");
      t.next_line();
    } else if (k == "comment" || k == "obj_info") {
      t.next_line();
    } else if (k == "element") {
      PlyElement el;
      el.line = t.line;
      el.name = std::string(t.word());
      el.count = t.number<long>("element count");
      if (el.count < 0 || el.count > (1L << 31)) t.fail("element count out of range");
      if (!t.at_eol()) t.fail("unexpected '" + std::string(t.word().substr(0, 40)) + "' after the element count");
      for (const auto& other : elements)  // was read as two elements, the rows concatenated
        if (other.name == el.name)
          t.fail("element '" + el.name + "' given twice (first at line " + std::to_string(other.line) + ")");
      elements.push_back(std::move(el));
      prop_names.clear();
      t.next_line();
    } else if (k == "property") {
      if (elements.empty()) t.fail("property before any element");
      PlyProp pr;
      pr.line = t.line;
      auto ty = t.word();
      if (ty == "list") {
        pr.list = true;
        if (!ply_type(t.word(), pr.count_type)) t.fail("unknown list count type");
        ty = t.word();
      }
      if (!ply_type(ty, pr.type)) t.fail("unknown property type '" + std::string(ty) + "'");
      pr.name = std::string(t.word());
      // Was "vertex element without x, y, z" for x, x, z. A set: comparing with
      // every earlier property took 8.5 s for 80,000 of them.
      if (!prop_names.insert(pr.name).second) t.fail("property '" + pr.name + "' given twice in one element");
      if (pr.list && (pr.count_type == PlyType::F32 || pr.count_type == PlyType::F64))
        t.fail("list count type must be an integer type");
      elements.back().props.push_back(std::move(pr));
      t.next_line();
    } else if (k == "end_header") {
      t.next_line();
      break;
    } else {
      t.fail("unknown PLY header line '" + std::string(k) + "'");
    }
  }
  if (format < 0) t.fail("no format line");
  // Counts are trusted only as far as the bytes after the header can hold
  // them (a count of 2^31 would otherwise reserve gigabytes first).
  check_ply_counts(elements, std::size_t(t.e - t.p), t);
  PolyMesh m;
  m.face_start.push_back(0);
  BinReader br{reinterpret_cast<const unsigned char*>(t.p), reinterpret_cast<const unsigned char*>(bytes.data()),
               reinterpret_cast<const unsigned char*>(bytes.data() + bytes.size()), format == 2, name};
  bool vertices_read = false;  // faces after the vertex element are checked where they are
  for (const auto& el : elements) {
    const bool is_vertex = el.name == "vertex", is_face = el.name == "face";
    int ix = -1, iy = -1, iz = -1, ilist = -1;
    for (size_t i = 0; i < el.props.size(); ++i) {
      const auto& n = el.props[i].name;
      if (n == "x") ix = int(i);
      if (n == "y") iy = int(i);
      if (n == "z") iz = int(i);
      if (el.props[i].list && (n == "vertex_indices" || n == "vertex_index")) {
        if (is_face && ilist >= 0)
          throw InputError(located(name, el.props[i].line, "a second vertex index list in the face element"));
        ilist = int(i);
      }
    }
    // Errors of the header name its line, not the first data line.
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0))
      throw InputError(located(name, el.line, "vertex element without x, y, z"));
    for (int c : {ix, iy, iz})  // a list named x read its count as the coordinate
      if (is_vertex && el.props[size_t(c)].list)
        throw InputError(
            located(name, el.props[size_t(c)].line, "vertex property '" + el.props[size_t(c)].name + "' is a list"));
    if (is_face && ilist < 0)
      throw InputError(located(name, el.line, "face element without a vertex_indices (or vertex_index) list property"));
    // Reserve no more than the data can hold (a count alone is not trusted).
    if (is_vertex) m.positions.reserve(std::min(size_t(el.count), size_t(br.e - br.p) / min_row_bytes(el, format) + 1));
    for (long r = 0; r < el.count; ++r) {
      Vec3d pos;
      for (size_t i = 0; i < el.props.size(); ++i) {
        const auto& pr = el.props[i];
        auto value = [&](PlyType ty, bool checked = true) {  // a list count has its own message
          if (format != 0) return br.get(ty);
          const double v = t.number<double>("PLY value");
          if (checked && !fits_ply_type(ty, v)) t.fail("value " + number_text(v) + " does not fit the property's type");
          return v;
        };
        // Binary data has no lines: its errors name the byte offset.
        auto fail = [&](const std::string& what) {
          if (format == 0) t.fail(what);
          throw InputError(located(name, 0, "byte " + std::to_string(br.p - br.b) + ": " + what));
        };
        if (pr.list) {
          const double c = value(pr.count_type, false);
          if (!(c >= 0 && c <= 1e6) || c != double(long(c)) || !fits_ply_type(pr.count_type, c))
            fail("bad list count " + number_text(c));
          for (long j = 0; j < long(c); ++j) {
            const double v = value(pr.type);
            if (int(i) == ilist) {
              // NaN or a fraction is not an index (int(NaN) would read as -2147483648).
              if (!(v == std::floor(v)))
                fail("face " + std::to_string(r) + " has vertex index " + number_text(v) + ", not an integer");
              if (!(v >= 0 && v < double(m.positions.size() + (vertices_read ? 0 : 2147483647.0))))
                fail("face " + std::to_string(r) + " has vertex index " + number_text(v) + " out of range (" +
                     (vertices_read ? std::to_string(m.positions.size()) + " vertices, from 0)"
                                    : "not a vertex index)"));
              m.indices.push_back(int(v));
            }
          }
          if (int(i) == ilist) {
            if (c < 3) fail("face with fewer than 3 vertices");
            if (vertices_read)
              for (size_t k = m.indices.size() - size_t(c); k < m.indices.size(); ++k)
                if (m.indices[k] < 0 || m.indices[k] >= long(m.positions.size())) {
                  const std::string what = "face " + std::to_string(r) + " has vertex index " +
                                           std::to_string(m.indices[k]) + " out of range (" +
                                           std::to_string(m.positions.size()) + " vertices, from 0)";
                  if (format == 0) t.fail(what);
                  throw InputError(located(name, 0, "byte " + std::to_string(br.p - br.b) + ": " + what));
                }
            m.face_start.push_back(int(m.indices.size()));
          }
        } else {
          const double v = value(pr.type);
          if ((int(i) == ix || int(i) == iy || int(i) == iz) && !std::isfinite(v))
            fail("vertex " + std::to_string(r) + " has coordinate " + number_text(v) + " (not finite)");
          // As the OBJ reader does: the converted file must load.
          if ((int(i) == ix || int(i) == iy || int(i) == iz) && !(std::abs(v) <= 1e30))
            fail("vertex " + std::to_string(r) + " has coordinate " + number_text(v) + " (magnitude above 1e30)");
          if (int(i) == ix) pos.x = v;
          if (int(i) == iy) pos.y = v;
          if (int(i) == iz) pos.z = v;
        }
      }
      if (is_vertex) m.positions.push_back(pos);
      if (format == 0 && !t.at_eol()) t.fail("extra values on a PLY data line");
      if (format == 0) t.next_line();
    }
    vertices_read = vertices_read || is_vertex;
  }
  // Data after the declared rows was ignored (a count too low, or garbage).
  if (format == 0) {
    if (!t.at_end())
      t.fail("data after the " + std::to_string(elements.empty() ? 0 : elements.back().count) +
             " rows the header declares for the last element");
  } else if (br.p != br.e) {
    throw InputError(located(name, 0,
                             "byte " + std::to_string(br.p - br.b) + ": " + std::to_string(br.e - br.p) +
                                 " bytes after the data the header declares"));
  }
  check_faces(m, name);
  return m;
}

// The OFF family's headers: [ST][C][N]OFF (texture coordinates, colours,
// normals). 4OFF and nOFF (other dimensions) are not 3-D meshes.
static bool off_magic(std::string_view m) {
  if (m.size() < 3 || m.substr(m.size() - 3) != "OFF") return false;
  m.remove_suffix(3);
  if (m.rfind("ST", 0) == 0) m.remove_prefix(2);
  if (!m.empty() && m[0] == 'C') m.remove_prefix(1);
  if (!m.empty() && m[0] == 'N') m.remove_prefix(1);
  return m.empty();
}

// What each vertex line carries after x y z, as the magic promises: N a
// normal (3 values), C a colour (RGB or RGBA: 3 or 4), ST a texture
// coordinate (2). A NOFF without its normals was read as a plain OFF.
struct OffExtras {
  int normal = 0, colour = 0, st = 0;
};
static OffExtras off_extras(std::string_view m) {
  OffExtras x;
  if (m.rfind("ST", 0) == 0) x.st = 2, m.remove_prefix(2);
  if (!m.empty() && m[0] == 'C') x.colour = 3, m.remove_prefix(1);
  if (!m.empty() && m[0] == 'N') x.normal = 3;
  return x;
}

// The values after x y z on a vertex line: all numbers, and as many as the
// magic promises (a colour may have 3 or 4). A plain OFF's extra values
// are ignored as before (some files carry unannounced colours).
static void check_off_extras(Tokens& t, const OffExtras& x, std::string_view magic) {
  if (!x.normal && !x.colour && !x.st) {  // "0 0 0 9 9" was read as 0 0 0
    if (!t.at_eol())
      t.fail("unexpected '" + std::string(t.word().substr(0, 40)) +
             "' after x y z (a COFF, NOFF or STOFF magic announces more values)");
    return;
  }
  int n = 0;
  while (!t.at_eol()) {
    t.number<double>("vertex value");
    ++n;
  }
  const int base = x.normal + x.colour + x.st;
  if (n == base || (x.colour && n == base + 1)) return;
  std::string want;
  auto add = [&](const char* s) { want += (want.empty() ? "" : ", ") + std::string(s); };
  if (x.normal) add("a normal (3 values)");
  if (x.colour) add("a colour (3 or 4 values)");
  if (x.st) add("a texture coordinate (2 values)");
  t.fail(std::string(magic) + " vertex needs x y z and " + want + " (" + std::to_string(n) + " values after x y z)");
}

PolyMesh parse_off(std::string_view text, const std::string& name) {
  Tokens t{text.data(), text.data() + text.size(), name};
  const std::string_view magic = t.word();
  if (!off_magic(magic))
    t.fail("not an OFF file (header '" + std::string(magic.substr(0, 20)) +
           "', expected OFF, COFF, NOFF, CNOFF, STOFF ...)");
  {  // "OFF BINARY" was "malformed vertex count 'BINARY'"
    const char* q = t.p;
    while (q < t.e && (*q == ' ' || *q == '\t')) ++q;
    if (t.e - q >= 6 && std::string_view(q, 6) == "BINARY") t.fail("binary OFF is not supported (ASCII OFF only)");
  }
  const long nv = t.number<long>("vertex count"), nf = t.number<long>("face count");
  // The edge count may be missing ("3 1"): a face would otherwise be read as it.
  if (t.at_eol()) t.fail("counts line needs vertices, faces and edges (found 2 numbers)");
  t.number<long>("edge count");
  if (!t.at_eol()) t.fail("counts line holds more than vertices, faces and edges");
  if (nv < 0 || nf < 0 || nv > (1L << 31) || nf > (1L << 31)) t.fail("counts out of range");
  // Each vertex or face takes more than a byte: counts beyond the bytes that
  // follow are refused at once, and no more is reserved than those hold
  // ("0 0 0": 5 bytes a vertex). Truncated data fails at its line.
  const auto left = std::uint64_t(t.e - t.p);
  if (std::uint64_t(nv) + std::uint64_t(nf) > left)
    t.fail(std::to_string(nv) + " vertices and " + std::to_string(nf) + " faces cannot fit in the " +
           std::to_string(left) + " bytes that follow");
  t.next_line();
  PolyMesh m;
  m.positions.reserve(std::min(size_t(nv), size_t(left / 5) + 1));
  const OffExtras extras = off_extras(magic);
  for (long i = 0; i < nv; ++i) {
    // Fewer rows than the counts: said at the line where the file ends, not
    // as "malformed face size ''" past it.
    if (t.at_end())
      t.fail("file ends after " + std::to_string(i) + " of the " + std::to_string(nv) + " vertices the counts declare");
    Vec3d p;
    p.x = t.number_on_line<double>("x coordinate");
    p.y = t.number_on_line<double>("y coordinate");
    p.z = t.number_on_line<double>("z coordinate");
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) t.fail("coordinate not finite");
    if (!(std::abs(p.x) <= 1e30 && std::abs(p.y) <= 1e30 && std::abs(p.z) <= 1e30))
      t.fail("coordinate with a magnitude above 1e30 (the OBJ reader refuses it)");
    check_off_extras(t, extras, magic);
    m.positions.push_back(p);
    t.next_line();
  }
  m.face_start.push_back(0);
  for (long f = 0; f < nf; ++f) {
    if (t.at_end())
      t.fail("file ends after " + std::to_string(f) + " of the " + std::to_string(nf) + " faces the counts declare");
    const long n = t.number<long>("face size");
    if (n < 3 || n > 1000000) t.fail("face with " + std::to_string(n) + " vertices");
    for (long j = 0; j < n; ++j) {
      const int v = t.number_on_line<int>("vertex index");
      if (v < 0 || v >= nv)
        t.fail("vertex index " + std::to_string(v) + " out of range (" + std::to_string(nv) + " vertices, from 0)");
      m.indices.push_back(v);
    }
    // A colour may follow (a colour-map index, RGB or RGBA): numbers only.
    int extra = 0;
    while (!t.at_eol()) t.number<double>("face colour value"), ++extra;
    if (extra == 2 || extra > 4)
      t.fail("face line has " + std::to_string(extra) + " values after its indices (a colour is 1, 3 or 4)");
    m.face_start.push_back(int(m.indices.size()));
    t.next_line();
  }
  if (!t.at_end()) t.fail("data after the " + std::to_string(nf) + " faces the counts declare");
  check_faces(m, name);
  return m;
}

PolyMesh read_ply(const std::filesystem::path& file) {
  return parse_ply(read_file_bytes(file, kMaxObjFileBytes), file.string());
}
PolyMesh read_off(const std::filesystem::path& file) {
  return parse_off(read_file_bytes(file, kMaxObjFileBytes), file.string());
}

std::string to_obj_text(const PolyMesh& m, const std::string& comment) {
  std::string out;
  out.reserve(m.positions.size() * 40 + m.indices.size() * 8);
  if (!comment.empty()) out += "# " + comment + "\n";
  char buf[64];
  for (const auto& p : m.positions) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      auto r = std::to_chars(buf, buf + sizeof buf, p[k]);
      out.append(buf, r.ptr);
    }
    out += '\n';
  }
  for (size_t f = 0; f < m.faces(); ++f) {
    out += 'f';
    for (int i = m.face_start[f]; i < m.face_start[f + 1]; ++i) {
      out += ' ';
      auto r = std::to_chars(buf, buf + sizeof buf, m.indices[size_t(i)] + 1);
      out.append(buf, r.ptr);
    }
    out += '\n';
  }
  return out;
}

void write_obj(const PolyMesh& m, const std::filesystem::path& out, const std::string& comment) {
  write_text_atomically(out, to_obj_text(m, comment));
}

}  // namespace ra
