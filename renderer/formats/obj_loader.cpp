// Wavefront OBJ reader (the decisions are listed in mesh.h).
//
// Shape: the file is mapped (or read) into one buffer; a flat switch on each
// statement's keyword calls small parse_x helpers over it (fast_obj style);
// nothing is allocated per line. In front of the general statement parser
// sit fast paths for the lines that make up nearly every real file (`v x y
// z`, `f a b c` in its four forms): whole-line SSE2 masks give every token's
// bounds at once, numbers go through an exact Clinger fast path (SWAR digit
// runs, one correctly rounded division), and anything unusual falls through
// to the general path, so results and messages are those of the general
// parser. Measured on the 871k-triangle dragon: `rayaudit bench --filter obj/`.
//
// Serial (one chunk): one pass. Arrays are reserved from quick_count (line
// starts `v `, `vt`, `vn`, `f `, found 16 bytes at a time) and grow by
// push_back if the hint was short; gnormal is computed in blocks of 512
// triangles while they are in cache; big arrays get huge-page advice.
//
// Parallel (ObjOptions::threads), over chunks of whole statements:
//   0. count   every chunk counts its v / vt / vn statements, lines and
//              triangles (corners - 2 per face) and notes its last usemtl,
//              so all arrays are sized once, every chunk writes its values
//              and triangles in place, knows its first line number and
//              starts with the material in force;
//   1. parse   values go straight into their slots; face indices are
//              resolved with the global counts (relative indices and range
//              checks exact in any chunk); gnormal is computed in blocks
//              whose corners are the chunk's own positions, other blocks and
//              polygons (ear clipping needs positions) wait for step 2;
//   2. merge   names (usemtl, g, o) are mapped from chunk-local tables to
//              global ones in file order, runs of group/object/smoothing
//              are joined with the state each chunk inherits, and each chunk
//              finishes its late normals, polygons and material ids.
// Any error in parallel mode re-runs the serial parse, so the message is the
// one of the first error in the file, as in serial mode.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__unix__)
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

#include "mesh.h"
#include "../io/input_file.h"
#include "obj_text.h"
#include "triangulate.h"
#include "../workers.h"

namespace ra {
namespace {

using namespace objtext;

constexpr int kInherit = -2;  // chunk-local state: "whatever the previous chunk left"

enum class Kw { Empty, V, VT, VN, VP, F, L, P, O, G, S, Usemtl, Mtllib, Other };

// Classifies the keyword [p, e).
Kw classify(const char* p, const char* e) {
  const size_t n = size_t(e - p);
  switch (*p) {
    case 'v':
      if (n == 1) return Kw::V;
      if (n == 2) return p[1] == 't' ? Kw::VT : p[1] == 'n' ? Kw::VN : p[1] == 'p' ? Kw::VP : Kw::Other;
      return Kw::Other;
    case 'f':
      return n == 1 ? Kw::F : Kw::Other;
    case 'l':
      return n == 1 ? Kw::L : Kw::Other;
    case 'p':
      return n == 1 ? Kw::P : Kw::Other;
    case 'o':
      return n == 1 ? Kw::O : Kw::Other;
    case 'g':
      return n == 1 ? Kw::G : Kw::Other;
    case 's':
      return n == 1 ? Kw::S : Kw::Other;
    case 'u':
      return n == 6 && std::memcmp(p, "usemtl", 6) == 0 ? Kw::Usemtl : Kw::Other;
    case 'm':
      return n == 6 && std::memcmp(p, "mtllib", 6) == 0 ? Kw::Mtllib : Kw::Other;
    default:
      return Kw::Other;
  }
}

// Skips leading whitespace of a statement and finds its keyword [p, *kend).
// Returns Empty for a blank or comment-only statement.
Kw read_keyword(const char*& p, const char* se, const char** kend) {
  p = skip_ws(p, se);
  if (p >= se || *p == '#') return Kw::Empty;
  const char* k = p;
  while (!at_separator(k, se)) ++k;  // a `\` before the line end is a continuation
  *kend = k;
  return classify(p, k);
}

// Names in first-seen order, with the line of their first use.
struct NameTable {
  std::vector<std::string> names;
  std::vector<long> lines;
  std::unordered_map<std::string, int> index;
  int intern(const std::string& s, long line) {
    auto it = index.find(s);
    if (it != index.end()) return it->second;
    const int id = int(names.size());
    index.emplace(s, id);
    names.push_back(s);
    lines.push_back(line);
    return id;
  }
};

// Distinct unsupported keywords warned one line each; the rest in one line.
constexpr std::size_t kMaxKeywordWarnings = 10;

// A keyword quoted in a warning: at most 40 bytes of it.
std::string short_quote(const std::string& s) {
  return s.size() > 40 ? s.substr(0, 40) + "... (" + std::to_string(s.size()) + " bytes)" : s;
}

struct Unknown {
  std::string keyword;
  long first_line;
  long count;
};

struct Corner {
  int v, t, n;
};

struct Chunk {
  const char* begin = nullptr;
  const char* end = nullptr;
  long first_line = 1;
  // step 0 (parallel only): exact counts, so every chunk writes in place
  long nv = 0, nvt = 0, nvn = 0, nlines = 0, ntris = 0;
  long base_v = 0, base_vt = 0, base_vn = 0, base_tri = 0;
  // step 1 output
  NameTable mats, groups, objects;
  int cur_mat = kInherit, cur_group = kInherit, cur_object = kInherit, cur_smooth = kInherit;
  std::vector<TriangleRun> runs;  // chunk-local: first counts from the chunk's first triangle
  // step 0: the chunk's last `usemtl` name, if any, so that every chunk can
  // start with the material in force (and need no fixing when ids agree)
  bool has_usemtl = false;
  std::string last_usemtl;
  // parallel: blocks [first, last) of triangles with a corner in an earlier
  // chunk, whose gnormal waits for step 2
  std::vector<std::pair<long, long>> late_normals;
  long vp = 0, l = 0, p = 0;
  std::vector<std::pair<long, std::string>> mtllibs;
  std::vector<Unknown> unknown;
  std::unordered_map<std::string, std::size_t> unknown_at;  // keyword -> index: linear in distinct ones
  long mixed = 0, mixed_first_line = 0;
  // parallel: polygons (n > 3) whose n-2 triangle slots are filled in step 2,
  // when every chunk's positions are in place
  struct Deferred {
    long tri, corner;
    int n;
    long line;
  };
  std::vector<Deferred> deferred;
  std::vector<Corner> deferred_corners;
  // polygons whose ear clipping spent its work limit (triangulate.h): how
  // many, and the first one's line and corner count, for one warning
  long limited = 0, limited_first_line = 0;
  int limited_first_n = 0;
  void note_limited(long line, int n) {
    if (limited++ == 0 || line < limited_first_line) limited_first_line = line, limited_first_n = n;
  }
  // step 2 input: chunk-local name ids -> global ones, inherited state
  std::vector<int> mat_map, group_map, object_map;
  int in_mat = -1, in_group = -1, in_object = -1, in_smooth = 0;
  std::exception_ptr error;
};

// Corners of the face statement [kend, se), as parse_f will find them.
long count_corners(const char* p, const char* se) {
  long n = 0;
  for (;;) {
    p = skip_ws(p, se);
    if (p >= se || *p == '#') return n;
    ++n;
    const char* q = p;
    while (!at_separator(q, se)) ++q;
    p = q > p ? q : p + 1;
  }
}

// count_corners for a statement of at most 48 bytes with 64 readable: with
// no tab, `#` or `\\` in it, tokens are the non-blank bytes after a blank.
long count_corners_short(const char* p, const char* se) {
#if defined(__SSE2__)
  std::uint64_t blank = 0, odd = 0;
  for (int i = 0; i < 4; ++i) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * i));
    const __m128i b = _mm_or_si128(_mm_cmpeq_epi8(x, _mm_set1_epi8(' ')), _mm_cmpeq_epi8(x, _mm_set1_epi8('\r')));
    const __m128i o =
        _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi8(x, _mm_set1_epi8('\t')), _mm_cmpeq_epi8(x, _mm_set1_epi8('#'))),
                     _mm_or_si128(_mm_cmpeq_epi8(x, _mm_set1_epi8('\\')), _mm_cmpeq_epi8(x, _mm_set1_epi8('\v'))));
    blank |= std::uint64_t(unsigned(_mm_movemask_epi8(b))) << (16 * i);
    odd |= std::uint64_t(unsigned(_mm_movemask_epi8(_mm_or_si128(o, _mm_cmpeq_epi8(x, _mm_set1_epi8('\f'))))))
           << (16 * i);
  }
  const std::uint64_t in = (std::uint64_t(1) << (se - p)) - 1;
  if (odd & in) return count_corners(p, se);
  // p (the keyword's end) is a blank or se, so every token follows a blank
  return __builtin_popcountll(~blank & (blank << 1) & in);
#else
  return count_corners(p, se);
#endif
}

// Step 0 (parallel only): counts statements, lines and triangles of a chunk.
void count_chunk(Chunk& c) {
  const char* p = c.begin;
  long line = 0;
  while (p < c.end) {
#if defined(__SSE2__)
    // One physical line of under 64 bytes with no tab, `#`, `\\`, VT or FF
    // (so no continuation and no comment) starting `v `, `vt `, `vn ` or
    // `f `: classified and its corners counted from masks.
    if (c.end - p >= 80) {
      std::uint64_t nl = 0, blank = 0, odd = 0;
      for (int i = 0; i < 4; ++i) {
        const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * i));
        auto eq = [&](char ch) { return _mm_cmpeq_epi8(x, _mm_set1_epi8(ch)); };
        nl |= std::uint64_t(unsigned(_mm_movemask_epi8(eq('\n')))) << (16 * i);
        blank |= std::uint64_t(unsigned(_mm_movemask_epi8(_mm_or_si128(eq(' '), eq('\r'))))) << (16 * i);
        const __m128i o =
            _mm_or_si128(_mm_or_si128(eq('\t'), eq('#')), _mm_or_si128(eq('\\'), _mm_or_si128(eq('\v'), eq('\f'))));
        odd |= std::uint64_t(unsigned(_mm_movemask_epi8(o))) << (16 * i);
      }
      if (nl) {
        const int len = __builtin_ctzll(nl);
        const std::uint64_t in = (std::uint64_t(1) << len) - 1;
        if (!(odd & in) && len >= 2) {
          bool known = true;
          if (p[0] == 'v' && (blank & 2)) {
            ++c.nv;
          } else if (p[0] == 'v' && (p[1] == 't' || p[1] == 'n') && (len == 2 || (blank & 4))) {
            ++(p[1] == 't' ? c.nvt : c.nvn);
          } else if (p[0] == 'f' && (blank & 2)) {
            std::uint64_t tok = ~blank & (blank << 1) & in;
            long n = 0;
            for (; tok; tok &= tok - 1) ++n;
            c.ntris += n > 2 ? n - 2 : 0;
          } else {
            known = false;
          }
          if (known) {
            ++line;
            p += len + 1;
            continue;
          }
        }
      }
    }
#endif
    const char* se = statement_end(p, c.end, line);
    const char* kend = nullptr;
    const char* s = p;
    switch (read_keyword(s, se, &kend)) {
      case Kw::V:
        ++c.nv;
        break;
      case Kw::VT:
        ++c.nvt;
        break;
      case Kw::VN:
        ++c.nvn;
        break;
      case Kw::Usemtl:
        c.has_usemtl = true;
        c.last_usemtl = std::string(rest_as_name(kend, se));
        break;
      case Kw::F: {
        const long n = se - kend <= 48 && c.end - kend >= 64 ? count_corners_short(kend, se) : count_corners(kend, se);
        c.ntris += n > 2 ? n - 2 : 0;
        break;
      }
      default:
        break;
    }
    if (se < c.end) ++line;
    p = se + 1;
  }
  c.nlines = line;
}

// Reservation hint for the serial parse: statements `v `, `vt`, `vn`, `f `
// at the start of a physical line (exact unless lines start with blanks or
// continue with `\`; `f` lines are counted, not triangles).
struct Hint {
  size_t v = 0, vt = 0, vn = 0, f = 0;
};
Hint quick_count(const char* s, size_t n) {
  Hint h;
  if (n >= 2 && s[0] == 'v') h.v += s[1] == ' ', h.vt += s[1] == 't', h.vn += s[1] == 'n';
  if (n >= 2 && s[0] == 'f') h.f += s[1] == ' ';
  const auto* u = reinterpret_cast<const unsigned char*>(s);
  const size_t m = n >= 3 ? n - 2 : 0;  // positions i with u[i + 2] readable
  size_t i = 0;
  // Two tallies per line start, branch-free: by its first character, and
  // (only for 'v') by its second. Lines are found 16 bytes at a time.
  size_t first[256] = {}, second[256] = {};
  auto line_at = [&](size_t j) {
    ++first[u[j + 1]];
    second[u[j + 2]] += u[j + 1] == 'v';
  };
#if defined(__SSE2__)
  const __m128i NL = _mm_set1_epi8('\n');
  for (; i + 16 <= m; i += 16) {
    unsigned bits =
        unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(u + i)), NL)));
    for (; bits; bits &= bits - 1) line_at(i + size_t(__builtin_ctz(bits)));
  }
#endif
  for (; i < m; ++i)
    if (u[i] == '\n') line_at(i);
  h.v += second[size_t(' ')] + second[size_t('\t')], h.vt += second[size_t('t')], h.vn += second[size_t('n')];
  h.f += first[size_t('f')];
  return h;
}

// Asks for transparent huge pages on a large, not yet touched buffer: a
// fresh 70 MB triangle array otherwise costs ~17k page faults (4 KiB each),
// which was a third of the parse time. Advice only; errors are ignored.
template <class T>
void advise_huge(const std::vector<T>& v) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const size_t bytes = v.capacity() * sizeof(T);
  if (bytes < (size_t(4) << 20)) return;
  const uintptr_t page = 4096, b = (uintptr_t(v.data()) + page - 1) & ~(page - 1),
                  e = (uintptr_t(v.data()) + bytes) & ~(page - 1);
  if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
#else
  (void)v;
#endif
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// normalize((B-A) x (C-A)), zero when degenerate.
Vec3d face_normal(const std::vector<Vec3d>& pos, const int* v) {
  const Vec3d& A = pos[size_t(v[0])];
  const Vec3d g = cross(pos[size_t(v[1])] - A, pos[size_t(v[2])] - A);
  const double len = length(g);
  return (len > 0 && std::isfinite(len)) ? g / len : Vec3d{0, 0, 0};
}

// face_normal for triangles t[0..n): the same operations in the same order,
// two triangles per SSE2 instruction (one sqrt and three divisions per
// pair instead of two and six), so bit-identical results.
void face_normals(const std::vector<Vec3d>& pos, MeshTriangle* t, size_t n) {
  size_t i = 0;
#if defined(__SSE2__)
  const Vec3d* P = pos.data();
  const __m128d zero = _mm_setzero_pd(), inf = _mm_set1_pd(std::numeric_limits<double>::infinity());
  for (; i + 2 <= n; i += 2) {
    const int *a = t[i].v, *b = t[i + 1].v;
    auto lanes = [&](int k, double Vec3d::*f) { return _mm_set_pd(P[b[k]].*f, P[a[k]].*f); };
    const __m128d ax = lanes(0, &Vec3d::x), ay = lanes(0, &Vec3d::y), az = lanes(0, &Vec3d::z);
    const __m128d ux = _mm_sub_pd(lanes(1, &Vec3d::x), ax), uy = _mm_sub_pd(lanes(1, &Vec3d::y), ay),
                  uz = _mm_sub_pd(lanes(1, &Vec3d::z), az);
    const __m128d wx = _mm_sub_pd(lanes(2, &Vec3d::x), ax), wy = _mm_sub_pd(lanes(2, &Vec3d::y), ay),
                  wz = _mm_sub_pd(lanes(2, &Vec3d::z), az);
    const __m128d gx = _mm_sub_pd(_mm_mul_pd(uy, wz), _mm_mul_pd(uz, wy));
    const __m128d gy = _mm_sub_pd(_mm_mul_pd(uz, wx), _mm_mul_pd(ux, wz));
    const __m128d gz = _mm_sub_pd(_mm_mul_pd(ux, wy), _mm_mul_pd(uy, wx));
    const __m128d len = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(gx, gx), _mm_mul_pd(gy, gy)), _mm_mul_pd(gz, gz)));
    const __m128d ok = _mm_and_pd(_mm_cmpgt_pd(len, zero), _mm_cmplt_pd(len, inf));  // len > 0, finite
    const __m128d nx = _mm_and_pd(ok, _mm_div_pd(gx, len)), ny = _mm_and_pd(ok, _mm_div_pd(gy, len)),
                  nz = _mm_and_pd(ok, _mm_div_pd(gz, len));
    _mm_storel_pd(&t[i].gnormal.x, nx), _mm_storel_pd(&t[i].gnormal.y, ny), _mm_storel_pd(&t[i].gnormal.z, nz);
    _mm_storeh_pd(&t[i + 1].gnormal.x, nx), _mm_storeh_pd(&t[i + 1].gnormal.y, ny),
        _mm_storeh_pd(&t[i + 1].gnormal.z, nz);
  }
#endif
  for (; i < n; ++i) t[i].gnormal = face_normal(pos, t[i].v);
}

// Step 1 for one chunk. Serially (one chunk) the arrays grow by push_back
// and triangles are finished on the spot; in parallel values and triangles
// go to the slots step 0 counted, and gnormal and polygons wait for step 2.
struct ChunkParser {
  Chunk& c;
  Mesh& m;
  Where w;
  bool serial;
  long iv = 0, ivt = 0, ivn = 0;  // statements of each kind seen so far in the chunk
  long itri = 0;                  // triangles written (parallel)
  const char* here = nullptr;     // statement being parsed (serial: capacity estimates)
  const char* stmt = "face";      // the statement whose indices are parsed, for messages
  std::vector<Corner> poly;
  std::vector<Vec3d> pts;
  std::vector<std::array<int, 3>> ears;
  EarClipScratch scratch;
  std::string name;

  ChunkParser(Chunk& c_, Mesh& m_, Where w_, bool serial_) : c(c_), m(m_), w(w_), serial(serial_) {}

  void run() {
    const char* p = c.begin;
    const char* const end = c.end;
    long line = c.first_line;
    while (p < end) {
      here = p;
      // Fast paths for the bulk of real files, `v x y z` and `f a b c` with
      // plain numbers on one line; anything else (or any doubt) returns
      // nullptr and the general statement parser takes the line.
      const char* q = nullptr;
      if (end - p >= kWideReadable && p[1] == ' ' && (p[0] == 'v' || p[0] == 'f')) q = wide_line(p, end);
      if (!q && end - p > 2 && p[1] == ' ') {
        if (p[0] == 'v')
          q = fast_v(p + 2, end);
        else if (p[0] == 'f')
          q = fast_f(p + 2, end);
      }
      if (q) {
        ++line;
        p = q;
        continue;
      }
      long extra = 0;
      const char* se = statement_end(p, end, extra);
      statement(p, se, line);
      line += extra + 1;
      p = se + 1;
    }
  }

  // The widest fast path: one `v x y z` or `f a b c` line that fits in 64
  // bytes, with single spaces. Its spaces and line end are found at once
  // (SSE2 compares over 64 bytes), so the next line's start and every
  // token's start are known before any value is parsed: the values no longer
  // wait on each other (a chain of dependent loads, one token after the
  // next, was the main cost of the byte-by-byte parse). Each token must be
  // consumed exactly; anything else returns nullptr for the slower paths.
  static constexpr long kWideReadable = 64 + 16;  // the masks and eight_digits read ahead
  const char* wide_line(const char* p, const char* end) {
#if defined(__SSE2__)
    (void)end;
    const __m128i SP = _mm_set1_epi8(' '), NL = _mm_set1_epi8('\n');
    std::uint64_t sp = 0, nl = 0;
    for (int i = 0; i < 4; ++i) {
      const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * i));
      sp |= std::uint64_t(unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(x, SP)))) << (16 * i);
      nl |= std::uint64_t(unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(x, NL)))) << (16 * i);
    }
    if (!nl) return nullptr;
    const int len = __builtin_ctzll(nl);  // p[len] == '\n'
    sp &= (std::uint64_t(1) << len) - 1;
    // exactly three spaces: p[1], then two more
    if ((sp & 3) != 2) return nullptr;
    const std::uint64_t r1 = sp & (sp - 1), r2 = r1 & (r1 - 1);
    if (!r1 || !r2 || (r2 & (r2 - 1))) return nullptr;
    const int s1 = __builtin_ctzll(r1), s2 = __builtin_ctzll(r2);
    const int last = p[len - 1] == '\r' ? len - 1 : len;            // end of the third token
    if (s1 == 2 || s2 == s1 + 1 || last <= s2 + 1) return nullptr;  // an empty token
    if (p[0] == 'v') {
      double x[3];
      const char *a = p + 2, *b = p + s1 + 1, *c = p + s2 + 1;
      if (!wide_double(a, p + s1, end, x[0]) || !wide_double(b, p + s2, end, x[1]) ||
          !wide_double(c, p + last, end, x[2]))
        return nullptr;
      put_position({x[0], x[1], x[2]});
    } else {
      Corner k[3];
      const long nv = c.base_v + iv, nvt = c.base_vt + ivt, nvn = c.base_vn + ivn;
      if (!wide_corner(p + 2, p + s1, nv, nvt, nvn, k[0]) || !wide_corner(p + s1 + 1, p + s2, nv, nvt, nvn, k[1]) ||
          !wide_corner(p + s2 + 1, p + last, nv, nvt, nvn, k[2]))
        return nullptr;
      if ((k[0].t < 0) != (k[1].t < 0) || (k[0].t < 0) != (k[2].t < 0) || (k[0].n < 0) != (k[1].n < 0) ||
          (k[0].n < 0) != (k[2].n < 0))
        return nullptr;  // mixed forms: the general path warns
      emit(k[0], k[1], k[2]);
    }
    return p + len + 1;
#else
    (void)p, (void)end;
    return nullptr;
#endif
  }
  // The number filling exactly [b, e) (8 bytes past each digit run
  // readable): `[-]i.f` or `[-]i` with fewer than 8 digits each side
  // inline, at most 14 digits so the mantissa is exact and one division
  // (by 1 for integers) rounds it correctly; anything else via fast_double.
  [[gnu::always_inline]] static bool wide_double(const char* b, const char* e, const char* end, double& out) {
    static constexpr double kPow10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7};
    static constexpr std::uint64_t kP10[] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000};
    const char* s = b;
    const bool neg = *s == '-';
    s += neg;
    std::uint64_t ip, fp = 0;
    const int ni = eight_digits(s, ip);
    int nf = 0;
    if (ni < 8 && s[ni] == '.') {
      nf = eight_digits(s + ni + 1, fp);
      if (nf == 8 || s + ni + 1 + nf != e || ni + nf == 0) return generic_double(b, e, end, out);
    } else if (ni == 0 || ni == 8 || s + ni != e) {
      return generic_double(b, e, end, out);
    }
    const double v = double(ip * kP10[nf] + fp) / kPow10[nf];
    out = neg ? -v : v;
    return true;
  }
  static bool generic_double(const char* b, const char* e, const char* end, double& out) {
    return fast_double(b, end, out) && b == e;
  }
  // One index of at most 7 digits at b (8 bytes readable), 1-based or
  // negative, checked against count; b moves past it.
  [[gnu::always_inline]] static bool wide_index(const char*& b, long count, int& out) {
    const bool neg = *b == '-';
    b += neg;
    std::uint64_t v;
    const int n = eight_digits(b, v);
    if (n == 0 || n == 8) return false;
    b += n;
    if (v == 0 || long(v) > count) return false;
    out = int(neg ? count - long(v) : long(v) - 1);
    return true;
  }
  // v, v/t, v//n or v/t/n filling exactly [b, e).
  [[gnu::always_inline]] static bool wide_corner(const char* b, const char* e, long nv, long nvt, long nvn, Corner& k) {
    k.t = k.n = -1;
    if (!wide_index(b, nv, k.v)) return false;
    if (*b == '/') {
      ++b;
      if (*b == '/') {
        ++b;
        if (!wide_index(b, nvn, k.n)) return false;
      } else {
        if (!wide_index(b, nvt, k.t)) return false;
        if (*b == '/' && !wide_index(++b, nvn, k.n)) return false;
      }
    }
    return b == e;
  }

  // After a fast-path statement: blanks and CRs, then the line end.
  static const char* line_end(const char* p, const char* end) {
    while (p < end && (is_blank(*p) || *p == '\r')) ++p;
    if (p < end) {
      if (*p != '\n') return nullptr;
      ++p;
    }
    return p;
  }
  static const char* skip_blanks(const char* p, const char* end) {
    if (p < end && *p == ' ') {  // the usual single space
      ++p;
      if (p >= end || !is_blank(*p)) return p;
    }
    while (p < end && is_blank(*p)) ++p;
    return p;
  }
  static bool value_end(const char* p, const char* end) { return p >= end || is_blank(*p) || *p == '\r' || *p == '\n'; }

  const char* fast_v(const char* p, const char* end) {
    double x[3];
    for (double& d : x) {
      p = skip_blanks(p, end);
      if (!fast_double(p, end, d) || !value_end(p, end)) return nullptr;
    }
    p = line_end(p, end);
    if (p) put_position({x[0], x[1], x[2]});
    return p;
  }

  const char* fast_f(const char* p, const char* end) {
    const long nv = c.base_v + iv;
    int idx[3];
    int k = 0;
    for (;;) {
      p = skip_blanks(p, end);
      if (p >= end || *p == '\n' || *p == '\r') break;
      if (k == 3) return nullptr;
      const bool neg = *p == '-';
      p += neg;
      std::uint64_t u = 0;
      int digits = 0;
      read_digits(p, end, u, digits);
      if (digits == 0 || digits > 10 || !value_end(p, end)) return nullptr;
      const long i = long(u);
      if (i == 0 || i > nv) return nullptr;
      idx[k++] = int(neg ? nv - i : i - 1);
    }
    if (k != 3) return nullptr;
    p = line_end(p, end);
    if (p) emit({idx[0], -1, -1}, {idx[1], -1, -1}, {idx[2], -1, -1});
    return p;
  }

  void statement(const char* p, const char* se, long line) {
    const char* kend = nullptr;
    const Kw kw = read_keyword(p, se, &kend);
    switch (kw) {
      case Kw::Empty:
        return;
      case Kw::V:
        parse_v(kend, se, line);
        return;
      case Kw::VT:
        parse_vt(kend, se, line);
        return;
      case Kw::VN:
        parse_vn(kend, se, line);
        return;
      case Kw::F:
        parse_f(kend, se, line);
        return;
      case Kw::VP:
        ++c.vp;
        return;
      case Kw::L:
        parse_lp(kend, se, line, "line", 2), ++c.l;
        return;
      case Kw::P:
        parse_lp(kend, se, line, "point", 1), ++c.p;
        return;
      case Kw::O:
        c.cur_object = parse_name(c.objects, kend, se, line), tags_changed = true;
        return;
      case Kw::Usemtl:
        c.cur_mat = parse_name(c.mats, kend, se, line);
        return;
      case Kw::G:
        c.cur_group = parse_group(kend, se, line), tags_changed = true;
        return;
      case Kw::S:
        c.cur_smooth = parse_s(kend, se, line), tags_changed = true;
        return;
      case Kw::Mtllib:
        c.mtllibs.emplace_back(line, std::string(rest_as_name(kend, se)));
        return;
      default:
        unknown(p, kend, line);
        return;
    }
  }

  void check_end(const char* p, const char* se, long line, const char* what) {
    if (!at_statement_end(p, se))
      w.fail(line, std::string(what) + ": unexpected '" + token_text(skip_ws(p, se), se) + "'");
  }

  template <class V, class T>
  void put(V& v, long base, long& i, const T& x) {
    if (serial) {
      v.push_back(x);
    } else {
      if (size_t(base + i) >= v.size()) throw std::logic_error("obj_loader: count and parse passes disagree");
      v[size_t(base + i)] = x;
    }
    ++i;
  }
  void put_position(const Vec3d& x) { put(m.positions, c.base_v, iv, x); }

  // v x y z [w] | v x y z r g b
  void parse_v(const char* p, const char* se, long line) {
    double x[7];
    const int n = parse_numbers(p, se, x, 7, w, line, "v");
    if (n != 3 && n != 4 && n != 6)
      w.fail(line, "v needs x y z, x y z w or x y z r g b (" + std::to_string(n) + " values given)");
    // As a scene's numbers (scene.cpp): beyond 1e30 a coordinate's square
    // overflows the kernels' products, and a 1e80 triangle rendered as
    // ambient only, from 1e120 black, with exit 0.
    for (int k = 0; k < 3; ++k)
      if (!(std::abs(x[k]) <= 1e30)) {
        char num[32];
        std::snprintf(num, sizeof num, "%.6g", x[k]);
        w.fail(line, std::string("v: coordinate ") + num +
                         " has a magnitude above 1e30 (its square would overflow "
                         "a double's products)");
      }
    put_position({x[0], x[1], x[2]});
  }
  // vt u [v [w]]
  void parse_vt(const char* p, const char* se, long line) {
    double x[3] = {0, 0, 0};
    const int n = parse_numbers(p, se, x, 3, w, line, "vt");
    if (n < 1) w.fail(line, "vt needs 1 to 3 values (none given)");
    put(m.uvs, c.base_vt, ivt, std::array<double, 2>{x[0], x[1]});
  }
  // vn x y z
  void parse_vn(const char* p, const char* se, long line) {
    double x[3];
    const int n = parse_numbers(p, se, x, 3, w, line, "vn");
    if (n != 3) w.fail(line, "vn needs 3 values (" + std::to_string(n) + " given)");
    put(m.normals, c.base_vn, ivn, Vec3d{x[0], x[1], x[2]});
  }
  // One index of a face corner; count = elements defined so far.
  const char* parse_index(const char* p, const char* se, long count, const char* kind, long line, int& out) {
    const char* tok = p;
    const char* q = p;
    long long i = 0;
    std::errc ec{};
    {  // fast path: up to 18 digits
      bool neg = q < se && *q == '-';
      q += neg;
      const char* d = q;
      while (q < se && unsigned(*q - '0') < 10 && q - d < 18) i = i * 10 + (*q++ - '0');
      if (q == d || (q < se && unsigned(*q - '0') < 10)) {  // no digits, or more than 18
        q = p;
        i = 0;
        if (p < se && *p == '+') ++p;
        auto r = std::from_chars(p, se, i);
        q = r.ptr;
        ec = r.ec;
      } else if (neg) {
        i = -i;
      }
    }
    if (ec == std::errc::result_out_of_range)
      w.fail(line, std::string(kind) + " index out of range '" + token_text(tok, se) + "'");
    if (ec != std::errc() || (p != tok && *p == '-'))
      w.fail(line, std::string("malformed ") + kind + " index '" + token_text(tok, se) + "'");
    if (i == 0) w.fail(line, std::string(kind) + " index 0 (OBJ indices start at 1)");
    if (i > 0) {
      if (i > count) past_the_end(kind, i, count, se, line);
      out = int(i - 1);
    } else {
      // i < -count, not -i > count: -i overflows for i = -2^63 (which
      // then passed and read before the first vertex).
      if (i < -static_cast<long long>(count))
        w.fail(line, std::string("relative ") + kind + " index " + std::to_string(i) +
                         " reaches before the first one (" + std::to_string(count) + " defined before this " + stmt +
                         ")");
      out = int(count + i);
    }
    return q;
  }

  // An index past the elements defined before the face (at line `line`,
  // ending at se): a forward reference (defined later: say at which line) or
  // one the whole file never defines (say how many it has). Cold: scans the
  // rest of the text (serially that is the file's end; in parallel the
  // message is discarded, the serial re-run reports).
  [[noreturn]] void past_the_end(const char* kind, long long i, long count, const char* se, long line) {
    const Kw want = kind[0] == 'v' ? Kw::V : kind[0] == 't' ? Kw::VT : Kw::VN;
    long n = count;
    long ln = line + long(std::count(here, se, '\n')) + 1;  // line of the next statement
    const char* p = se + (se < c.end);
    while (p < c.end) {
      long extra = 0;
      const char* e = statement_end(p, c.end, extra);
      const char* s = p;
      const char* kend = nullptr;
      if (read_keyword(s, e, &kend) == want && ++n == i)
        w.fail(line, std::string(kind) + " index " + std::to_string(i) + " is defined later, at line " +
                         std::to_string(ln) + ": forward references are not allowed (" + std::to_string(count) +
                         " defined before this " + stmt + ")");
      ln += extra + 1;
      p = e + 1;
    }
    const char* plural = kind[0] == 'v' ? " vertices" : kind[0] == 't' ? " texture coordinates" : " normals";
    const char* single = kind[0] == 'v' ? " vertex" : kind[0] == 't' ? " texture coordinate" : " normal";
    w.fail(line, std::string(kind) + " index " + std::to_string(i) + " is past the end: the file has only " +
                     std::to_string(n) + (n == 1 ? single : plural));
  }

  // `l v1[/vt1] v2[/vt2] ...` and `p v1 v2 ...`: not rendered, but their
  // indices are checked as a face's are (an index past the end or 0 was
  // skipped silently). `what` names the statement, `min` its fewest vertices.
  void parse_lp(const char* p, const char* se, long line, const char* what, int min) {
    const long nv = c.base_v + iv, nvt = c.base_vt + ivt;
    stmt = what;
    int n = 0, unused = 0;
    for (;;) {
      p = skip_ws(p, se);
      if (p >= se || *p == '#') break;
      p = parse_index(p, se, nv, "vertex", line, unused);
      if (what[0] == 'l' && p < se && *p == '/') p = parse_index(p + 1, se, nvt, "texture", line, unused);
      if (!at_separator(p, se))
        w.fail(line, "malformed " + std::string(what) + " vertex near '" + token_text(p, se) + "'");
      ++n;
    }
    stmt = "face";
    if (n < min)
      w.fail(line, std::string(what) + " statement with " + std::to_string(n) + " vertices (at least " +
                       std::to_string(min) + " needed)");
  }

  void parse_f(const char* p, const char* se, long line) {
    const long nv = c.base_v + iv, nvt = c.base_vt + ivt, nvn = c.base_vn + ivn;
    poly.clear();
    int with_t = 0, with_n = 0;
    for (;;) {
      p = skip_ws(p, se);
      if (p >= se || *p == '#') break;
      if (poly.size() == size_t(kMaxPolygonCorners))
        w.fail(line,
               "face of more than " + std::to_string(kMaxPolygonCorners) + " corners (the limit a polygon; split it)");
      poly.push_back({-1, -1, -1});  // parsed in place (no copy of a temporary)
      Corner& k = poly.back();
      p = parse_index(p, se, nv, "vertex", line, k.v);
      if (p < se && *p == '/') {
        ++p;
        if (p < se && *p == '/') {
          p = parse_index(p + 1, se, nvn, "normal", line, k.n);
        } else {
          p = parse_index(p, se, nvt, "texture", line, k.t);
          if (p < se && *p == '/') p = parse_index(p + 1, se, nvn, "normal", line, k.n);
        }
      }
      if (!at_separator(p, se)) w.fail(line, "malformed face vertex near '" + token_text(p, se) + "'");
      with_t += k.t >= 0;
      with_n += k.n >= 0;
    }
    const int n = int(poly.size());
    if (n < 3) w.fail(line, "face with " + std::to_string(n) + " vertices (at least 3 needed)");
    if ((with_t != 0 && with_t != n) || (with_n != 0 && with_n != n)) {
      if (c.mixed++ == 0) c.mixed_first_line = line;
      for (auto& k : poly) {
        if (with_t != n) k.t = -1;
        if (with_n != n) k.n = -1;
      }
    }
    if (n == 3) {
      emit(poly[0], poly[1], poly[2]);
      return;
    }
    if (!serial) {  // positions of earlier chunks may not be written yet
      c.deferred.push_back({c.base_tri + itri, long(c.deferred_corners.size()), n, line});
      c.deferred_corners.insert(c.deferred_corners.end(), poly.begin(), poly.end());
      for (int i = 2; i < n; ++i) emit(poly[0], poly[0], poly[0]);  // placeholders
      return;
    }
    pts.resize(size_t(n));
    for (int i = 0; i < n; ++i) pts[size_t(i)] = m.positions[size_t(poly[size_t(i)].v)];
    ears.clear();
    if (triangulate_polygon(pts.data(), n, ears, scratch)) c.note_limited(line, n);
    for (auto& e : ears) emit(poly[size_t(e[0])], poly[size_t(e[1])], poly[size_t(e[2])]);
  }

  void emit(const Corner& a, const Corner& b, const Corner& d) {
    MeshTriangle t;
    t.v[0] = a.v, t.v[1] = b.v, t.v[2] = d.v;
    t.t[0] = a.t, t.t[1] = b.t, t.t[2] = d.t;
    t.n[0] = a.n, t.n[1] = b.n, t.n[2] = d.n;
    t.material = c.cur_mat;
    if (tags_changed) open_run();
    if (serial) {
      if (m.triangles.size() == m.triangles.capacity()) grow_triangles();
      m.triangles.push_back(t);
      if (m.triangles.size() - normals_done >= kNormalBlock) finish_normals();
    } else {
      if (itri >= c.ntris) throw std::logic_error("obj_loader: count and parse passes disagree");
      m.triangles[size_t(c.base_tri + itri++)] = t;
      if (size_t(itri) - normals_done >= kNormalBlock) finish_chunk_normals();
    }
  }

  // Parallel: gnormal of the triangles since the last call whose corners
  // are this chunk's own positions (written already); the others wait.
  void finish_chunk_normals() {
    MeshTriangle* t = m.triangles.data() + c.base_tri;
    const unsigned long lo = (unsigned long)c.base_v, n = (unsigned long)iv;
    bool own = true;
    for (size_t i = normals_done; i < size_t(itri); ++i) {
      const int* v = t[i].v;
      own = own && (unsigned long)v[0] - lo < n && (unsigned long)v[1] - lo < n && (unsigned long)v[2] - lo < n;
    }
    if (own) {
      face_normals(m.positions, t + normals_done, size_t(itri) - normals_done);
    } else if (!c.late_normals.empty() && c.late_normals.back().second == c.base_tri + long(normals_done)) {
      c.late_normals.back().second = c.base_tri + itri;
    } else {
      c.late_normals.emplace_back(c.base_tri + long(normals_done), c.base_tri + itri);
    }
    normals_done = size_t(itri);
  }

  // Before the first triangle after g / o / s: a new run if the tags differ.
  bool tags_changed = true;
  void open_run() {
    tags_changed = false;
    const TriangleRun r{serial ? m.triangles.size() : size_t(itri), c.cur_group, c.cur_object, c.cur_smooth};
    if (c.runs.empty() || c.runs.back().group != r.group || c.runs.back().object != r.object ||
        c.runs.back().smoothing != r.smoothing)
      c.runs.push_back(r);
  }

  // Serial: gnormal of the triangles emitted since the last call, in blocks
  // while they are still in cache; a tight loop over independent triangles
  // overlaps the position loads and the sqrt/divisions far better than one
  // triangle at a time between parsing statements.
  static constexpr size_t kNormalBlock = 512;
  size_t normals_done = 0;
  void finish_normals() {
    MeshTriangle* t = m.triangles.data();
    const size_t n = m.triangles.size();
    face_normals(m.positions, t + normals_done, n - normals_done);
    normals_done = n;
  }

  // Serial: the hint was short (polygons, or lines the hint missed): grow to
  // the count extrapolated from the bytes read so far, rather than doubling.
  void grow_triangles() {
    auto& v = m.triangles;
    const double done = double(here - c.begin + 1), total = double(c.end - c.begin);
    // Never more than the rest of the file can hold: every further triangle
    // needs a corner of at least 2 bytes ("1 "). Inside one long face the
    // bytes read so far are few, and the extrapolation alone asked for
    // terabytes (a 2 MB face of 1M corners: std::bad_alloc).
    const size_t most = v.size() + size_t(c.end - here) / 2 + 64;
    const double estimate = double(v.size()) * (total / done) * 1.05 + 64;
    const size_t guess = estimate < double(most) ? size_t(estimate) : most;
    v.reserve(std::max(guess, v.size() + v.size() / 2 + 64));
    advise_huge(v);
  }
  // o / usemtl: the rest of the line; empty means none (-1).
  int parse_name(NameTable& table, const char* p, const char* se, long line) {
    const std::string_view s = rest_as_name(p, se);
    if (s.empty()) return -1;
    name.assign(s);
    return table.intern(name, line);
  }

  // g A B ...: names joined by one space; none means no group (-1).
  int parse_group(const char* p, const char* se, long line) {
    name.clear();
    for (;;) {
      p = skip_ws(p, se);
      if (p >= se || *p == '#') break;
      const char* q = p;
      while (!at_separator(q, se)) ++q;
      if (q == p) ++q;  // a lone '\' that is not a continuation
      if (!name.empty()) name += ' ';
      name.append(p, q);
      p = q;
    }
    if (name.empty()) return -1;
    return c.groups.intern(name, line);
  }

  // s off | s N
  int parse_s(const char* p, const char* se, long line) {
    p = skip_ws(p, se);
    if (se - p >= 3 && std::memcmp(p, "off", 3) == 0 && at_statement_end(p + 3, se)) return 0;
    long long v = 0;
    auto [q, ec] = std::from_chars(p, se, v);
    if (ec != std::errc() || v < 0 || v > 0x7fffffff || !at_statement_end(q, se))
      w.fail(line, "s needs 'off' or a non-negative group number, found '" + token_text(p, se) + "'");
    return int(v);
  }

  void unknown(const char* k, const char* kend, long line) {
    // A map, not a scan of those seen: 100k distinct unknown keywords
    // took over 20 s.
    std::string kw(k, size_t(kend - k));
    const auto [it, fresh] = c.unknown_at.try_emplace(kw, c.unknown.size());
    if (fresh)
      c.unknown.push_back({std::move(kw), line, 1});
    else
      ++c.unknown[it->second].count;
  }
};

// Splits text into n chunks of whole statements.
std::vector<Chunk> split(std::string_view text, int n) {
  std::vector<Chunk> chunks;
  const char* b = text.data();
  const char* e = b + text.size();
  const char* p = b;
  for (int i = 0; i < n && p < e; ++i) {
    const char* target = b + (text.size() * size_t(i + 1)) / size_t(n);
    const char* q = e;
    if (i + 1 < n && target > p) {
      q = target;
      for (;;) {
        const char* nl = static_cast<const char*>(std::memchr(q, '\n', size_t(e - q)));
        if (!nl) {
          q = e;
          break;
        }
        if (!escaped_newline(b, nl)) {
          q = nl + 1;
          break;
        }
        q = nl + 1;
      }
    } else if (i + 1 < n) {
      continue;
    }
    Chunk c;
    c.begin = p;
    c.end = q;
    chunks.push_back(std::move(c));
    p = q;
  }
  if (chunks.empty()) {
    Chunk c;
    c.begin = c.end = b;
    chunks.push_back(std::move(c));
  }
  return chunks;
}

template <class F>
void run_parallel(std::vector<Chunk>& chunks, F&& f) {
  if (chunks.size() == 1) {
    f(chunks[0]);
    return;
  }
  // Chunks are taken from a counter, so fewer threads than chunks (the
  // system refusing some) still parse every chunk.
  std::atomic<size_t> next{0};
  run_workers(int(chunks.size()), [&] {
    for (size_t i; (i = next.fetch_add(1)) < chunks.size();) {
      try {
        f(chunks[i]);
      } catch (...) {
        chunks[i].error = std::current_exception();
      }
    }
  });
}

bool any_error(const std::vector<Chunk>& chunks) {
  for (auto& c : chunks)
    if (c.error) return true;
  return false;
}

std::string slashes(std::string s) {
  std::replace(s.begin(), s.end(), '\\', '/');
  return s;
}

// Reads the `mtllib` libraries and turns the triangles' material indices
// (into `used`, the usemtl names) into indices of m.materials.
void resolve_materials(Mesh& m, const NameTable& used, const std::vector<std::pair<long, std::string>>& mtllibs,
                       const ObjOptions& opt) {
  namespace fs = std::filesystem;
  if (opt.load_materials) {
    const fs::path dir = fs::path(m.path).parent_path();
    std::unordered_set<std::string> loaded;  // a set: 50,000 mtllib lines were a quadratic scan
    std::unordered_map<std::string, int> defined;
    objtext::CappedWarnings missing{m.warnings, m.path, "more material libraries not found or not files"};
    for (auto& [line, raw] : mtllibs) {
      std::vector<std::string> files;
      std::error_code ec;
      if (!raw.empty() && fs::is_regular_file(dir / slashes(raw), ec)) {
        files.push_back(raw);
      } else {
        const char* p = raw.data();
        const char* e = p + raw.size();
        while (p < e) {
          while (p < e && is_space(*p)) ++p;
          const char* q = p;
          while (q < e && !is_space(*q)) ++q;
          if (q > p) files.emplace_back(p, q);
          p = q;
        }
      }
      if (files.empty()) m.warnings.push_back(located(m.path, line, "mtllib without a file name"));
      for (auto& f : files) {
        const fs::path file = dir / slashes(f);
        const std::string key = file.lexically_normal().string();
        if (!loaded.insert(key).second) continue;
        if (const std::string why = input_file_problem(file); !why.empty()) {
          missing.add(line, located(m.path, line,
                                    "material library '" + short_quote(f) + "' " +
                                        (why == "no such file" ? std::string("not found") : why) +
                                        " (its materials get defaults)"));
          continue;
        }
        for (auto& mat : load_mtl(file, m.warnings)) {
          if (defined.count(mat.name)) {
            m.warnings.push_back(located(file.string(), 0, "material '" + mat.name + "' defined twice (first kept)"));
            continue;
          }
          defined.emplace(mat.name, int(m.materials.size()));
          m.materials.push_back(std::move(mat));
        }
      }
    }
    missing.finish();
  }
  objtext::CappedWarnings undefined{m.warnings, m.path, "more materials not defined (default material used)"};
  std::unordered_map<std::string, int> byname;
  for (size_t i = 0; i < m.materials.size(); ++i) byname.emplace(m.materials[i].name, int(i));
  std::vector<int> map(used.names.size());
  bool identity = true;
  for (size_t i = 0; i < used.names.size(); ++i) {
    auto it = byname.find(used.names[i]);
    if (it != byname.end()) {
      map[i] = it->second;
    } else {
      if (opt.load_materials)
        undefined.add(used.lines[i],
                      located(m.path, used.lines[i],
                              "material '" + short_quote(used.names[i]) + "' is not defined (default material used)"));
      MtlMaterial d;
      d.name = used.names[i];
      map[i] = int(m.materials.size());
      byname.emplace(d.name, map[i]);
      m.materials.push_back(std::move(d));
    }
    identity = identity && map[i] == int(i);
  }
  undefined.finish();
  if (!identity)
    for (auto& t : m.triangles)
      if (t.material >= 0) t.material = map[size_t(t.material)];
}

// Step 2 (parallel) for one chunk: triangulates its deferred polygons,
// maps its names and inherited state to global ones, computes gnormal.
void finish_chunk(Chunk& c, Mesh& m, bool first) {
  std::vector<Vec3d> pts;
  std::vector<std::array<int, 3>> ears;
  EarClipScratch scratch;
  for (const auto& d : c.deferred) {
    const Corner* poly = c.deferred_corners.data() + d.corner;
    pts.resize(size_t(d.n));
    for (int i = 0; i < d.n; ++i) pts[size_t(i)] = m.positions[size_t(poly[i].v)];
    ears.clear();
    if (triangulate_polygon(pts.data(), d.n, ears, scratch)) c.note_limited(d.line, d.n);
    for (size_t k = 0; k < ears.size(); ++k) {
      MeshTriangle& t = m.triangles[size_t(d.tri) + k];
      for (int j = 0; j < 3; ++j) {
        const Corner& q = poly[ears[k][size_t(j)]];
        t.v[j] = q.v, t.t[j] = q.t, t.n[j] = q.n;
      }
    }
  }
  for (const auto& d : c.deferred)
    for (int k = 0; k < d.n - 2; ++k) {
      MeshTriangle& t = m.triangles[size_t(d.tri + k)];
      t.gnormal = face_normal(m.positions, t.v);
    }
  for (auto [b, e] : c.late_normals) face_normals(m.positions, m.triangles.data() + b, size_t(e - b));
  // Every chunk started with the material in force, so only local ids that
  // differ from the global ones need rewriting.
  bool identity = true;
  for (size_t i = 0; i < c.mat_map.size(); ++i) identity = identity && c.mat_map[i] == int(i);
  if (first || identity) return;
  MeshTriangle* t = m.triangles.data() + c.base_tri;
  MeshTriangle* const e = t + c.ntris;
  for (; t < e; ++t)
    if (t->material >= 0) t->material = c.mat_map[size_t(t->material)];
}

// Step 2: global name tables, the state each chunk inherits, warnings; in
// parallel also finish_chunk on every chunk.
void merge(Mesh& m, std::vector<Chunk>& chunks, const ObjOptions& opt) {
  NameTable mats, groups, objects;
  int s_mat = -1, s_group = -1, s_object = -1, s_smooth = 0;
  std::vector<Unknown> unknown;
  std::unordered_map<std::string, std::size_t> unknown_at;
  long mixed = 0, mixed_line = 0;
  std::vector<std::pair<long, std::string>> mtllibs;
  for (auto& c : chunks) {
    auto remap = [](NameTable& global, const NameTable& local) {
      std::vector<int> map(local.names.size());
      for (size_t i = 0; i < local.names.size(); ++i) map[i] = global.intern(local.names[i], local.lines[i]);
      return map;
    };
    c.mat_map = remap(mats, c.mats), c.group_map = remap(groups, c.groups), c.object_map = remap(objects, c.objects);
    auto fix = [](int v, const std::vector<int>& map, int inherited) {
      return v == kInherit ? inherited : v < 0 ? v : map[size_t(v)];
    };
    c.in_mat = s_mat, c.in_group = s_group, c.in_object = s_object, c.in_smooth = s_smooth;
    for (const auto& r : c.runs) {
      const TriangleRun g{size_t(c.base_tri) + r.first, fix(r.group, c.group_map, s_group),
                          fix(r.object, c.object_map, s_object), r.smoothing == kInherit ? s_smooth : r.smoothing};
      if (m.runs.empty() || m.runs.back().group != g.group || m.runs.back().object != g.object ||
          m.runs.back().smoothing != g.smoothing)
        m.runs.push_back(g);
    }
    s_mat = fix(c.cur_mat, c.mat_map, s_mat);
    s_group = fix(c.cur_group, c.group_map, s_group);
    s_object = fix(c.cur_object, c.object_map, s_object);
    s_smooth = c.cur_smooth == kInherit ? s_smooth : c.cur_smooth;
    m.skipped.vp += c.vp;
    m.skipped.l += c.l;
    m.skipped.p += c.p;
    mtllibs.insert(mtllibs.end(), c.mtllibs.begin(), c.mtllibs.end());
    for (auto& u : c.unknown) {
      const auto [it, fresh] = unknown_at.try_emplace(u.keyword, unknown.size());
      if (fresh)
        unknown.push_back(u);
      else
        unknown[it->second].count += u.count;
    }
    if (c.mixed && mixed == 0) mixed_line = c.mixed_first_line;
    mixed += c.mixed;
  }
  if (chunks.size() > 1) run_parallel(chunks, [&](Chunk& c) { finish_chunk(c, m, &c == &chunks[0]); });
  long limited = 0, limited_line = 0;
  int limited_n = 0;
  for (const auto& c : chunks) {  // in file order: the warning names the first such polygon
    if (c.limited && !limited) limited_line = c.limited_first_line, limited_n = c.limited_first_n;
    limited += c.limited;
  }
  m.groups = std::move(groups.names);
  m.objects = std::move(objects.names);
  // The first kMaxKeywordWarnings keywords one line each, the rest in one
  // line: 100k distinct ones printed 100k warnings.
  for (std::size_t i = 0; i < unknown.size() && i < kMaxKeywordWarnings; ++i) {
    const Unknown& u = unknown[i];
    m.warnings.push_back(located(m.path, u.first_line,
                                 "unsupported statement '" + short_quote(u.keyword) + "' ignored (" +
                                     std::to_string(u.count) + (u.count == 1 ? " line)" : " lines)")));
  }
  if (unknown.size() > kMaxKeywordWarnings) {
    long lines = 0;
    for (std::size_t i = kMaxKeywordWarnings; i < unknown.size(); ++i) lines += unknown[i].count;
    m.warnings.push_back(located(m.path, unknown[kMaxKeywordWarnings].first_line,
                                 std::to_string(unknown.size() - kMaxKeywordWarnings) +
                                     " more unsupported keywords ignored (" + std::to_string(lines) +
                                     (lines == 1 ? " line)" : " lines)")));
  }
  if (mixed)
    m.warnings.push_back(located(m.path, mixed_line,
                                 "face mixes vertex forms (v, v/vt, v//vn, v/vt/vn); texture or normal indices "
                                 "not on every corner were dropped (" +
                                     std::to_string(mixed) + (mixed == 1 ? " face)" : " faces)")));
  if (limited)
    m.warnings.push_back(located(m.path, limited_line,
                                 "polygon of " + std::to_string(limited_n) +
                                     " corners is too irregular for ear "
                                     "clipping within " +
                                     std::to_string(kEarClipWorkPerCorner) +
                                     " steps a corner: its remaining corners were cut as a fan, whose triangles may "
                                     "overlap (" +
                                     std::to_string(limited) + (limited == 1 ? " polygon)" : " polygons)")));
  resolve_materials(m, mats, mtllibs, opt);
}

Mesh parse_serial(std::string_view text, const std::string& name, const ObjOptions& opt) {
  Mesh m;
  m.path = name;
  std::vector<Chunk> chunks(1);
  Chunk& c = chunks[0];
  c.begin = text.data();
  c.end = text.data() + text.size();
  c.cur_mat = c.cur_group = c.cur_object = -1;
  c.cur_smooth = 0;
  const Hint h = quick_count(text.data(), text.size());
  m.positions.reserve(h.v);
  m.uvs.reserve(h.vt);
  m.normals.reserve(h.vn);
  m.triangles.reserve(h.f);
  advise_huge(m.positions), advise_huge(m.uvs), advise_huge(m.normals), advise_huge(m.triangles);
  ChunkParser cp{c, m, Where{&name}, true};
  cp.run();
  cp.finish_normals();
  merge(m, chunks, opt);
  return m;
}

Mesh parse_parallel(std::string_view text, const std::string& name, const ObjOptions& opt, int nthreads) {
  Mesh m;
  m.path = name;
  std::vector<Chunk> chunks = split(text, nthreads);
  if (chunks.size() == 1) return parse_serial(text, name, opt);
  // The first chunk inherits nothing: its state starts as the file's.
  chunks[0].cur_mat = chunks[0].cur_group = chunks[0].cur_object = -1;
  chunks[0].cur_smooth = 0;
  run_parallel(chunks, count_chunk);
  long v = 0, vt = 0, vn = 0, line = 1, nt = 0;
  for (auto& c : chunks) {
    c.base_v = v, c.base_vt = vt, c.base_vn = vn, c.first_line = line, c.base_tri = nt;
    v += c.nv, vt += c.nvt, vn += c.nvn, line += c.nlines, nt += c.ntris;
  }
  constexpr long kMaxCount = 0x7fffffffL;
  if (v > kMaxCount || vt > kMaxCount || vn > kMaxCount)
    throw InputError(located(name, 0, "more than 2^31-1 vertices, uvs or normals"));
  m.positions.reserve(size_t(v));
  m.uvs.reserve(size_t(vt));
  m.normals.reserve(size_t(vn));
  m.triangles.reserve(size_t(nt));
  advise_huge(m.positions), advise_huge(m.uvs), advise_huge(m.normals), advise_huge(m.triangles);
  m.positions.resize(size_t(v));
  m.uvs.resize(size_t(vt));
  m.normals.resize(size_t(vn));
  m.triangles.resize(size_t(nt));
  bool has_mat = false;
  std::string mat;
  for (auto& c : chunks) {
    c.cur_mat = has_mat && !mat.empty() ? c.mats.intern(mat, c.first_line) : -1;
    if (c.has_usemtl) has_mat = true, mat = c.last_usemtl;
  }
  const Where w{&name};
  run_parallel(chunks, [&](Chunk& c) {
    ChunkParser cp{c, m, w, false};
    cp.run();
    cp.finish_chunk_normals();
    if (cp.itri != c.ntris) throw std::logic_error("obj_loader: count and parse passes disagree");
  });
  if (any_error(chunks)) return parse_serial(text, name, opt);  // the serial message
  merge(m, chunks, opt);
  return m;
}

}  // namespace

Mesh parse_obj(std::string_view text, const std::string& name, const ObjOptions& opt) {
  text = check_encoding(text, name);
  int n = opt.threads;
  if (n <= 0) n = int(std::max(1u, std::thread::hardware_concurrency()));
  if (text.size() < opt.parallel_min_bytes) n = 1;
  return n == 1 ? parse_serial(text, name, opt) : parse_parallel(text, name, opt, n);
}

std::string read_file_bytes(const std::filesystem::path& file, std::uint64_t max_bytes) {
  check_input_file(file);  // a directory, FIFO or device named as such
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(located(file.string(), 0, "cannot read: " + ec.message()));
  if (size > max_bytes)
    throw InputError(
        located(file.string(), 0,
                "file is " + std::to_string(size) + " bytes, more than the limit of " + std::to_string(max_bytes)));
  std::ifstream f(file, std::ios::binary);
  if (!f) throw InputError(located(file.string(), 0, "cannot open"));
  // Read to the end, whatever the size said: /proc files say 0 (and were
  // read as empty), sysfs files 4096 (and were "read failed").
  std::string buf;
  buf.reserve(size_t(size));
  char chunk[65536];
  while (f.read(chunk, sizeof chunk) || f.gcount() > 0) {
    buf.append(chunk, size_t(f.gcount()));
    if (buf.size() > max_bytes)
      throw InputError(
          located(file.string(), 0, "file is more than the limit of " + std::to_string(max_bytes) + " bytes"));
  }
  if (f.bad()) throw InputError(located(file.string(), 0, "read failed: " + std::string(std::strerror(errno))));
  return buf;
}

Mesh load_obj(const std::filesystem::path& file) { return load_obj(file, ObjOptions{}); }

namespace {

// The bytes of a file: mapped read-only when possible (no copy, no zeroed
// heap buffer: the page cache's pages are used as they are), else read.
// Same errors as read_file_bytes.
class FileBytes {
 public:
  FileBytes(const std::filesystem::path& file, std::uint64_t max_bytes) {
    // Noted as an input on the mapped path too: crack-maps --mesh naming one
    // of its own maps was overwritten.
    check_input_file(file);
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
#if defined(__unix__)
    if (!ec && size > 0 && size <= max_bytes) {
      const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
      struct stat st {};
      if (fd >= 0 && ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && std::uint64_t(st.st_size) == size) {
        void* p = ::mmap(nullptr, size_t(size), PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
        if (p != MAP_FAILED) {
          map_ = p;
          size_ = size_t(size);
        }
      }
      if (fd >= 0) ::close(fd);
      if (map_) return;
    }
#endif
    buf_ = read_file_bytes(file, max_bytes);
  }
  ~FileBytes() {
#if defined(__unix__)
    if (map_) ::munmap(map_, size_);
#endif
  }
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  std::string_view view() const { return map_ ? std::string_view(static_cast<const char*>(map_), size_) : buf_; }

 private:
  void* map_ = nullptr;
  size_t size_ = 0;
  std::string buf_;
};

}  // namespace

Mesh load_obj(const std::filesystem::path& file, const ObjOptions& options) {
  const FileBytes bytes(file, kMaxObjFileBytes);
  return parse_obj(bytes.view(), file.string(), options);
}

}  // namespace ra
