// The exact oracle (see oracle.h): a CGAL Interval_nt filter decides the easy
// signs; the rest is integer arithmetic in GMP after scaling every input by the same power of two.
//
// Why integers: the doubles o, d, A, B, C are all m * 2^e with integer m, so
// with E the smallest exponent, X * 2^-E is an integer for each of them. Every
// quantity used is a homogeneous polynomial (degree 3 for the triangle's t
// numerator and denominator, 2 or 4 for the sphere), so signs and the ratio
// t = N / D are unchanged by the scaling and are computed without rationals.
// GMP variables are thread-local scratch, so the exact path never allocates
// once warm.
#include "oracle.h"

#include <CGAL/Interval_nt.h>
#include <gmp.h>
#include <mpfr.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace ra::oracle {

std::string_view verdict_name(Verdict v) {
  switch (v) {
    case Verdict::hit:
      return "hit";
    case Verdict::miss:
      return "miss";
    case Verdict::boundary:
      return "boundary";
    case Verdict::coplanar:
      return "coplanar";
    case Verdict::degenerate:
      return "degenerate";
  }
  return "?";
}

bool parse_verdict(std::string_view s, Verdict& out) {
  for (Verdict v : {Verdict::hit, Verdict::miss, Verdict::boundary, Verdict::coplanar, Verdict::degenerate})
    if (verdict_name(v) == s) {
      out = v;
      return true;
    }
  return false;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
thread_local unsigned long long g_fallbacks = 0;

Answer make(Verdict v, double t = kNaN, int zero_edges = 0) {
  Answer a;
  a.verdict = v;
  a.t = t;
  a.t_far = kNaN;
  a.zero_edges = zero_edges;
  return a;
}

bool finite3(const Vec3d& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// ---------------------------------------------------------------- filter ---
using I = CGAL::Interval_nt_advanced;  // needs the rounding mode set by the caller
struct IV {
  I x, y, z;
};
IV iv(const Vec3d& p) { return {I(p.x), I(p.y), I(p.z)}; }
IV isub(const Vec3d& p, const Vec3d& q) { return {I(p.x) - I(q.x), I(p.y) - I(q.y), I(p.z) - I(q.z)}; }
I idot(const IV& a, const IV& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
IV icross(const IV& a, const IV& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
// The sign of an interval, or 2 when it straddles zero.
int isign(const I& v) {
  if (v.inf() > 0) return 1;
  if (v.sup() < 0) return -1;
  if (v.inf() == 0 && v.sup() == 0) return 0;
  return 2;
}

// What the interval filter settled.
enum class Filtered {
  decided,    // `out` is the answer (miss, coplanar, degenerate)
  crossing,   // hit or boundary certain (out.verdict, out.zero_edges): only t is left
  undecided,  // the exact path must redo everything
};

// Decides the verdicts that need no exact t (miss, coplanar, degenerate) when
// the intervals are conclusive, and certifies hits so the exact path computes
// only t.
Filtered filtered_triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c, double lo, Answer& out) {
  constexpr Filtered decided = Filtered::decided;
  CGAL::Protect_FPU_rounding<true> guard;
  const IV n = icross(isub(b, a), isub(c, a));
  const int nx = isign(n.x), ny = isign(n.y), nz = isign(n.z);
  if (nx == 0 && ny == 0 && nz == 0) return out = make(Verdict::degenerate), decided;
  if (!(nx == 1 || nx == -1 || ny == 1 || ny == -1 || nz == 1 || nz == -1)) return Filtered::undecided;
  const IV d = iv(r.d), ao = isub(a, r.o), bo = isub(b, r.o), co = isub(c, r.o);
  const I D = idot(n, d), N = idot(n, ao);
  const int sD = isign(D);
  if (sD == 2) return Filtered::undecided;
  if (sD == 0) {
    const int sN = isign(N);
    if (sN == 2) return Filtered::undecided;
    return out = make(sN == 0 ? Verdict::coplanar : Verdict::miss), decided;
  }
  const int w[3] = {isign(idot(d, icross(ao, bo))), isign(idot(d, icross(bo, co))), isign(idot(d, icross(co, ao)))};
  for (int s : w)
    if (s == -sD) return out = make(Verdict::miss), decided;  // the line passes outside
  for (int s : w)
    if (s == 2) return Filtered::undecided;
  const int below = isign(N - I(lo) * D);
  if (below == 2) return Filtered::undecided;
  if (below * sD < 0) return out = make(Verdict::miss), decided;
  if (std::isfinite(r.tmax)) {
    const int above = isign(I(r.tmax) * D - N);
    if (above == 2) return Filtered::undecided;
    if (above * sD < 0) return out = make(Verdict::miss), decided;
  }
  const int zeros = (w[0] == 0) + (w[1] == 0) + (w[2] == 0);
  out = make(zeros ? Verdict::boundary : Verdict::hit, kNaN, zeros);
  return Filtered::crossing;
}

// ------------------------------------------------------- double-double ---
// A second filter between the intervals and GMP. Every quantity is evaluated
// in double-double (about 106 bits) next to a rigorous bound on its error of
// the form K u^2 P, where P is the polynomial's permanent (the same expression
// over absolute values) and u = 2^-53. A double-double add errs by at most
// 3 u^2 times the sum of its operands' magnitudes, a product of two
// double-doubles by 8 u^2 times the product of theirs and one by a double by
// 3 u^2 (Dekker; Joldes, Muller and Popescu 2017), and the inputs'
// differences are exact (two_sum), so a degree-3 triangle quantity errs by
// less than 24 u^2 P (20 by this count) and a degree-4 sphere quantity by
// less than 64 u^2 P (34); the constants below take 8 times that. Signs are
// certain when the value exceeds its bound, and t is certain when its
// enclosure stays clear of the midpoints between doubles, so rounding to
// nearest is decided exactly.
// Range guard: every input is a multiple of 2^E and below 2^M; with
// deg * E >= -960 and deg * (M + 3) <= 960 no partial result underflows or
// overflows, so the u^2 analysis holds. Anything else goes to GMP.
struct DD {
  double h = 0, l = 0;
};
inline double fma_(double a, double b, double c) {
#ifdef __FMA__
  return __builtin_fma(a, b, c);
#else
  return std::fma(a, b, c);
#endif
}
inline DD two_sum(double a, double b) {
  const double s = a + b, bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}
inline DD two_prod(double a, double b) {
  const double p = a * b;
  return {p, fma_(a, b, -p)};
}
inline DD operator+(DD x, DD y) {
  const DD s = two_sum(x.h, y.h);
  return two_sum(s.h, s.l + (x.l + y.l));
}
inline DD operator-(DD x) { return {-x.h, -x.l}; }
inline DD operator-(DD x, DD y) { return x + (-y); }
inline DD operator*(DD x, DD y) {
  const DD p = two_prod(x.h, y.h);
  return two_sum(p.h, p.l + (x.h * y.l + x.l * y.h));
}
inline DD operator*(DD x, double y) {
  const DD p = two_prod(x.h, y);
  return two_sum(p.h, p.l + x.l * y);
}
struct DV {
  DD x, y, z;
};
inline DV dsub(const Vec3d& p, const Vec3d& q) { return {two_sum(p.x, -q.x), two_sum(p.y, -q.y), two_sum(p.z, -q.z)}; }
inline DV dcross(const DV& a, const DV& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline DD ddot(const DV& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline DD ddot(const DV& a, const DV& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
// Magnitude bounds (permanents), computed in double and slightly inflated.
inline Vec3d vabs(const DV& v) { return {std::abs(v.x.h), std::abs(v.y.h), std::abs(v.z.h)}; }
inline Vec3d vabs(const Vec3d& v) { return {std::abs(v.x), std::abs(v.y), std::abs(v.z)}; }
inline Vec3d pcross(const Vec3d& a, const Vec3d& b) {
  return {a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x};
}
inline double pdot(const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

constexpr double kU2 = 0x1p-106;
constexpr double kTriK = 256 * kU2;       // degree 3 (8 x 24 u^2, rounded up), see above
constexpr double kSphK = 512 * kU2;       // degree 4 (8 x 64 u^2)
constexpr double kInflate = 1 + 0x1p-40;  // covers rounding in the permanents

// sign of v when |v| > err, else 2 (undecided).
inline int dsign(DD v, double err) {
  if (v.h > err) return 1;
  if (v.h < -err) return -1;
  return 2;
}

// Lowest set bit's exponent (x == m 2^e, m odd), and a bound on the exponent
// of |x| (|x| < 2^top); zero is ignored.
inline void range(double x, int& lo, int& hi) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const int ex = int((bits >> 52) & 0x7ff);
  std::uint64_t mant = bits & ((std::uint64_t(1) << 52) - 1);
  if (ex == 0 && mant == 0) return;
  if (ex != 0) mant |= std::uint64_t(1) << 52;
  const int base = (ex == 0 ? 1 : ex) - 1075;
  lo = std::min(lo, base + __builtin_ctzll(mant));
  hi = std::max(hi, ex - 1022);
}
inline bool in_range(std::initializer_list<double> xs, int deg) {
  int lo = 10000, hi = -10000;
  for (double x : xs) range(x, lo, hi);
  if (lo == 10000) return true;  // all zero
  return deg * lo >= -960 && deg * (hi + 3) <= 960;
}

// A signed 256-bit integer in two's complement, only for summing products of
// three int64s exactly (each below 2^189).
struct I256 {
  std::uint64_t w[4] = {0, 0, 0, 0};
  void add_product(std::int64_t a, std::int64_t b, std::int64_t c) {
    using U128 = unsigned __int128;
    const bool neg = ((a < 0) != (b < 0)) != (c < 0);
    auto mag = [](std::int64_t x) { return x < 0 ? std::uint64_t(0) - std::uint64_t(x) : std::uint64_t(x); };
    const U128 ab = U128(mag(a)) * mag(b);
    const U128 p0 = U128(std::uint64_t(ab)) * mag(c);
    const U128 p1 = U128(std::uint64_t(ab >> 64)) * mag(c) + (p0 >> 64);
    std::uint64_t m[4] = {std::uint64_t(p0), std::uint64_t(p1), std::uint64_t(p1 >> 64), 0};
    if (neg) {  // -m = ~m + 1
      unsigned carry = 1;
      for (auto& x : m) {
        x = ~x + carry;
        carry = carry && x == 0;
      }
    }
    unsigned carry = 0;
    for (int i = 0; i < 4; ++i) {
      const U128 sum = U128(w[i]) + m[i] + carry;
      w[i] = std::uint64_t(sum);
      carry = unsigned(sum >> 64);
    }
  }
  int sign() const {
    if (w[3] >> 63) return -1;
    return (w[0] | w[1] | w[2] | w[3]) ? 1 : 0;
  }
};

// The exact sign of (p x q) . d when every double involved (p and q are exact
// differences, high and low parts) is an integer multiple of a common 2^E
// below 2^(E+61): scaled by 2^-E each is an int64 and the determinant a sum
// of 24 products of three, below 2^(3*61+5), summed exactly in 256 bits.
// This settles the edge functions that are exactly zero (a ray aimed at a
// point of an edge, as the audit's edge and vertex families are built on a
// grid), where any filter can only say "too close to call"; else 2.
int grid_det_sign(const DV& p, const DV& q, const Vec3d& d) {
  const double xs[15] = {p.x.h, p.y.h, p.z.h, q.x.h, q.y.h, q.z.h, d.x,  d.y,
                         d.z,   p.x.l, p.y.l, p.z.l, q.x.l, q.y.l, q.z.l};
  int lo = 10000, hi = -10000;
  for (double x : xs) range(x, lo, hi);
  if (lo == 10000) return 0;
  if (hi - lo > 61) return 2;
  std::int64_t v[15];
  for (int i = 0; i < 15; ++i) v[i] = static_cast<std::int64_t>(std::ldexp(xs[i], -lo));  // exact
  // Coordinate k of p is v[k] + v[9 + k], of q v[3 + k] + v[12 + k]; d's is v[6 + k].
  I256 det;
  auto term = [&](int i, int j, int k, bool minus) {  // +- p_i q_j d_k
    for (int pi : {i, 9 + i})
      for (int qj : {3 + j, 12 + j})
        if (v[pi] && v[qj]) det.add_product(minus ? -v[pi] : v[pi], v[qj], v[6 + k]);
  };
  term(1, 2, 0, false), term(2, 1, 0, true);
  term(2, 0, 1, false), term(0, 2, 1, true);
  term(0, 1, 2, false), term(1, 0, 2, true);
  return det.sign();
}

// The double nearest to a value v known only as t (double-double, finite,
// normalised so t.h = round(t.h + t.l)) within absolute error err: true and
// sets out when every value in [t - err, t + err] rounds to the same double.
inline bool certified_round(DD t, double err, double& out) {
  const double h = t.h;
  if (!std::isfinite(h) || !(err >= 0) || std::abs(h) < 0x1p-960 || std::abs(h) > 0x1p960) return false;
  const double up = std::nextafter(h, HUGE_VAL) - h, down = h - std::nextafter(h, -HUGE_VAL);
  // v - h is within t.l +- err; it must stay strictly inside (-down/2, up/2).
  // (the slack on the right covers the rounding of t.l +- err)
  constexpr double kSlack = 1 - 0x1p-40;
  if (t.l + err >= 0.5 * up * kSlack || t.l - err <= -0.5 * down * kSlack) return false;
  out = h;
  return true;
}

// q = n / d in double-double with relative error 8 u^2 + O(u^3) (d.h != 0);
// callers allow 16 u^2.
inline DD ddiv(DD n, DD d) {
  const double q1 = n.h / d.h;
  const DD p = d * q1;
  const DD r = n - p;
  const double q2 = r.h / d.h;
  const DD q = two_sum(q1, q2);
  const DD p2 = d * q.h;
  const DD r2 = n - p2;
  return two_sum(q.h, r2.h / d.h);
}

// t = N / D rounded to nearest, from N and D within eN and eD: the relative
// error of the quotient is at most eN/|N| + eD/|D| + 8 u^2 to first order
// (both ratios are kept below 2^-20 so the second-order terms fit the margin).
bool dd_t(DD N, DD D, double eN, double eD, double& t_out) {
  if (!(std::abs(N.h) > 0x1p20 * eN)) return false;  // t near 0 (or exactly 0)
  if (!(std::abs(D.h) > 0x1p20 * eD)) return false;
  const double rel = (eN / std::abs(N.h) + eD / std::abs(D.h)) * 1.01 + 16 * kU2;
  const DD t = ddiv(N, D);
  return certified_round(t, rel * std::abs(t.h), t_out);
}

// The triangle query decided with double-double when it can be: true and out
// filled (verdict and t exactly as the exact path gives them); false when some
// sign or the rounding of t is too close to call.
// With t_only, the verdict in `out` is already certain (a crossing) and only t
// is computed.
bool dd_triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c, double lo, Answer& out,
                 bool t_only = false) {
  if (!in_range({r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z}, 3))
    return false;
  const DV e1 = dsub(b, a), e2 = dsub(c, a);
  const DV n = dcross(e1, e2);
  const Vec3d pn = pcross(vabs(e1), vabs(e2)) * kInflate;
  if (dsign(n.x, kTriK * pn.x) == 2 && dsign(n.y, kTriK * pn.y) == 2 && dsign(n.z, kTriK * pn.z) == 2)
    return false;  // maybe degenerate
  const DV ao = dsub(a, r.o), bo = dsub(b, r.o), co = dsub(c, r.o);
  const Vec3d ad = vabs(r.d), aao = vabs(ao), abo = vabs(bo), aco = vabs(co);
  const DD D = ddot(n, r.d), N = ddot(n, ao);
  const double eD = kTriK * pdot(pn, ad) * kInflate, eN = kTriK * pdot(pn, aao) * kInflate;
  const int sD = dsign(D, eD);
  if (sD == 2) return false;  // maybe parallel
  if (t_only) return dd_t(N, D, eN, eD, out.t);
  const double ew[3] = {kTriK * pdot(ad, pcross(aao, abo)) * kInflate, kTriK * pdot(ad, pcross(abo, aco)) * kInflate,
                        kTriK * pdot(ad, pcross(aco, aao)) * kInflate};
  // An exact zero: when d == P - o exactly for a vertex P (a ray aimed at a
  // vertex whose subtraction was exact), the two edge functions through P are
  // determinants with two equal rows, so exactly 0.
  bool zero[3] = {false, false, false};
  auto is_d = [&](const DV& po) {
    return po.x.l == 0 && po.y.l == 0 && po.z.l == 0 && po.x.h == r.d.x && po.y.h == r.d.y && po.z.h == r.d.z;
  };
  if (is_d(ao)) zero[0] = zero[2] = true;
  if (is_d(bo)) zero[0] = zero[1] = true;
  if (is_d(co)) zero[1] = zero[2] = true;
  int w[3] = {zero[0] ? 0 : dsign(ddot(dcross(ao, bo), r.d), ew[0]),
              zero[1] ? 0 : dsign(ddot(dcross(bo, co), r.d), ew[1]),
              zero[2] ? 0 : dsign(ddot(dcross(co, ao), r.d), ew[2])};
  const DV* rows[4] = {&ao, &bo, &co, &ao};
  for (int i = 0; i < 3; ++i)
    if (w[i] == 2) w[i] = grid_det_sign(*rows[i], *rows[i + 1], r.d);
  for (int s : w)
    if (s == -sD) return out = make(Verdict::miss), true;
  for (int s : w)
    if (s == 2) return false;  // maybe on an edge
  const int zeros = (w[0] == 0) + (w[1] == 0) + (w[2] == 0);
  // The window: sign(N - x D) for x = lo and x = tmax.
  auto side = [&](double x) {
    if (std::abs(x) > 0x1p200) return 2;
    const DD v = N - D * x;
    const double err = (eN + std::abs(x) * eD) * 1.5 + 0x1p-1000;
    if (!std::isfinite(v.h) || !std::isfinite(err)) return 2;
    return dsign(v, err);
  };
  const int below = side(lo);
  if (below == 2) return false;
  if (below * sD < 0) return out = make(Verdict::miss), true;
  if (std::isfinite(r.tmax)) {
    const int above = side(r.tmax);
    if (above == 2) return false;
    if (above * sD > 0) return out = make(Verdict::miss), true;
  }
  double td;
  if (!dd_t(N, D, eN, eD, td)) return false;
  out = make(zeros ? Verdict::boundary : Verdict::hit, td, zeros);
  return true;
}

// sign(t - x) for a value known as t within err, or 2.
inline int cmp_enclosed(DD t, double err, double x) {
  const DD d = two_sum(t.h, -x) + DD{t.l, 0};
  if (!std::isfinite(d.h)) return 2;
  return dsign(d, err * kInflate + 0x1p-1060);
}

// The sphere query decided with double-double when it can be (see
// dd_triangle); tangent rays, roots on the window's ends and t too close to a
// rounding midpoint are left to the exact path.
bool dd_sphere(const Rayd& r, const Vec3d& center, double radius, double lo, double hi, Answer& out) {
  if (!in_range({r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, center.x, center.y, center.z, radius}, 4)) return false;
  const DV f = dsub(r.o, center);
  const Vec3d af = vabs(f), ad = vabs(r.d);
  const DD A = two_prod(r.d.x, r.d.x) + two_prod(r.d.y, r.d.y) + two_prod(r.d.z, r.d.z);
  const DD B = ddot(f, r.d);
  const DD C = ddot(f, f) - two_prod(radius, radius);
  const double pA = pdot(ad, ad) * kInflate, pB = pdot(af, ad) * kInflate,
               pC = (pdot(af, af) + radius * radius) * kInflate;
  const double eA = kTriK * pA, eB = kTriK * pB, eC = kTriK * pC;
  const DD disc = B * B - A * C;
  const double edisc = kSphK * (pB * pB + pA * pC) * kInflate;
  const int sdisc = dsign(disc, edisc);
  if (sdisc == 2) return false;  // maybe tangent
  if (sdisc < 0) return out = make(Verdict::miss), true;
  // S = sqrt(disc): one Newton step from the double root.
  const double s1 = std::sqrt(disc.h);
  const DD S = two_sum(s1, (disc - two_prod(s1, s1)).h / (2 * s1));
  const double eS = edisc / std::sqrt(disc.h - edisc) * 1.01 + 16 * kU2 * s1;
  // q = -(B + sign(B) S): no cancellation; the roots are q / A and C / q.
  const DD q = B.h < 0 ? S - B : -(B + S);
  const double eq = (eB + eS) * kInflate + 8 * kU2 * (std::abs(B.h) + s1);
  if (!(std::abs(q.h) > 0x1p20 * eq) || !(A.h > 0x1p20 * eA) || !(std::abs(C.h) > 0x1p20 * eC))
    return false;  // a root near 0 (or a bound too loose for the first-order sum)
  const double relq = eq / std::abs(q.h), relA = eA / A.h, relC = eC / std::abs(C.h);
  DD r1 = ddiv(q, A), r2 = ddiv(C, q);
  double e1 = ((relq + relA) * 1.01 + 16 * kU2) * std::abs(r1.h);
  double e2 = ((relC + relq) * 1.01 + 16 * kU2) * std::abs(r2.h);
  if (!std::isfinite(r1.h) || !std::isfinite(r2.h)) return false;
  if (r2.h < r1.h) std::swap(r1, r2), std::swap(e1, e2);
  if (r1.h + e1 >= r2.h - e2) return false;  // enclosures overlap
  auto in_window = [&](DD t, double e) {
    const int a = cmp_enclosed(t, e, lo);
    if (a == 2) return 2;
    if (a < 0) return 0;
    if (!std::isfinite(hi)) return 1;
    const int b = cmp_enclosed(t, e, hi);
    return b == 2 ? 2 : int(b <= 0);
  };
  const int near_in = in_window(r1, e1), far_in = in_window(r2, e2);
  if (near_in == 2 || far_in == 2) return false;
  if (!near_in && !far_in) return out = make(Verdict::miss), true;
  double t_near = kNaN, t_far = kNaN;
  if (near_in && !certified_round(r1, e1, t_near)) return false;
  if (far_in && !certified_round(r2, e2, t_far)) return false;
  out = make(Verdict::hit, near_in ? t_near : t_far);
  if (near_in && far_in) out.t_far = t_far;
  return true;
}

// ----------------------------------------------------------------- exact ---
struct Z {
  mpz_t v;
  Z() { mpz_init2(v, 512); }
  ~Z() { mpz_clear(v); }
  Z(const Z&) = delete;
  Z& operator=(const Z&) = delete;
  int sign() const { return mpz_sgn(v); }
};

// A double as m * 2^e with integer m (|m| < 2^53).
struct Split {
  std::int64_t m = 0;
  int e = 0;
};
Split split(double x) {
  if (x == 0) return {};
  int k;
  const double f = std::frexp(x, &k);
  return {static_cast<std::int64_t>(std::ldexp(f, 53)), k - 53};
}

// Lowest exponent among the (nonzero) inputs: the common scale.
int common_exponent(std::initializer_list<double> xs) {
  int e = std::numeric_limits<int>::max();
  for (double x : xs)
    if (x != 0) e = std::min(e, split(x).e);
  return e == std::numeric_limits<int>::max() ? 0 : e;
}

void set_scaled(Z& z, double x, int E) {
  const Split s = split(x);
  mpz_set_si(z.v, static_cast<long>(s.m));
  if (s.m != 0) mpz_mul_2exp(z.v, z.v, static_cast<mp_bitcnt_t>(s.e - E));
}

struct ZV {
  Z x, y, z;
  Z& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

void set_scaled(ZV& v, const Vec3d& p, int E) {
  set_scaled(v.x, p.x, E);
  set_scaled(v.y, p.y, E);
  set_scaled(v.z, p.z, E);
}
void sub(ZV& r, ZV& a, ZV& b) {
  for (int i = 0; i < 3; ++i) mpz_sub(r[i].v, a[i].v, b[i].v);
}
// r = a x b (r must differ from a and b); tmp is scratch.
void cross(ZV& r, ZV& a, ZV& b, Z& tmp) {
  mpz_mul(r.x.v, a.y.v, b.z.v), mpz_mul(tmp.v, a.z.v, b.y.v), mpz_sub(r.x.v, r.x.v, tmp.v);
  mpz_mul(r.y.v, a.z.v, b.x.v), mpz_mul(tmp.v, a.x.v, b.z.v), mpz_sub(r.y.v, r.y.v, tmp.v);
  mpz_mul(r.z.v, a.x.v, b.y.v), mpz_mul(tmp.v, a.y.v, b.x.v), mpz_sub(r.z.v, r.z.v, tmp.v);
}
void dot(Z& r, ZV& a, ZV& b, Z& tmp) {
  mpz_mul(r.v, a.x.v, b.x.v);
  mpz_mul(tmp.v, a.y.v, b.y.v), mpz_add(r.v, r.v, tmp.v);
  mpz_mul(tmp.v, a.z.v, b.z.v), mpz_add(r.v, r.v, tmp.v);
}

struct Scratch {
  ZV o, d, a, b, c, ao, bo, co, e1, e2, n, w;
  Z N, D, ws[3], t0, t1, t2;
  Z sA, sB, sC, disc;
  mpq_t q;
  mpfr_t f53, big1, big2, big3;
  Scratch() {
    mpq_init(q);
    mpfr_init2(f53, 53);
    mpfr_inits2(256, big1, big2, big3, static_cast<mpfr_ptr>(nullptr));
  }
  ~Scratch() {
    mpq_clear(q);
    mpfr_clears(f53, big1, big2, big3, static_cast<mpfr_ptr>(nullptr));
  }
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// sign(num / den - x) for den > 0 and finite x.
int cmp_ratio(Scratch& s, const Z& num, const Z& den, double x) {
  const Split sx = split(x);
  mpz_mul_si(s.t0.v, den.v, static_cast<long>(sx.m));
  if (sx.e >= 0) {
    mpz_mul_2exp(s.t0.v, s.t0.v, static_cast<mp_bitcnt_t>(sx.e));
    return mpz_cmp(num.v, s.t0.v) > 0 ? 1 : (mpz_cmp(num.v, s.t0.v) < 0 ? -1 : 0);
  }
  mpz_mul_2exp(s.t1.v, num.v, static_cast<mp_bitcnt_t>(-sx.e));
  const int c = mpz_cmp(s.t1.v, s.t0.v);
  return c > 0 ? 1 : (c < 0 ? -1 : 0);
}

// num / den correctly rounded to double (den > 0).
// Rounding to 53 bits and then to a subnormal double would round twice (e.g.
// t = (2^52 + 4/3) 2^-1075 gave 2^-1023 instead of 2^-1023 + 2^-1074), so the
// rounding is done in double's own exponent range, subnormals included
// (MPFR's documented mpfr_subnormalize idiom).
double round_ratio(Scratch& s, const Z& num, const Z& den) {
  mpz_set(mpq_numref(s.q), num.v);
  mpz_set(mpq_denref(s.q), den.v);
  const mpfr_exp_t emin = mpfr_get_emin(), emax = mpfr_get_emax();
  mpfr_set_emin(-1073);
  mpfr_set_emax(1024);
  const int inex = mpfr_set_q(s.f53, s.q, MPFR_RNDN);
  mpfr_subnormalize(s.f53, inex, MPFR_RNDN);
  const double d = mpfr_get_d(s.f53, MPFR_RNDN);
  mpfr_set_emin(emin);
  mpfr_set_emax(emax);
  return d;
}

// The inputs as integers over one common power of two (exact), and the
// triangle's normal n = (b - a) x (c - a) from them, in the thread's scratch.
Scratch& scaled_with_normal(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Scratch& s = scratch();
  const int E =
      common_exponent({r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z});
  set_scaled(s.o, r.o, E), set_scaled(s.d, r.d, E);
  set_scaled(s.a, a, E), set_scaled(s.b, b, E), set_scaled(s.c, c, E);
  sub(s.e1, s.b, s.a), sub(s.e2, s.c, s.a);
  cross(s.n, s.e1, s.e2, s.t0);
  return s;
}

// t = N / D exactly rounded, for a crossing the filter already certified.
double exact_t(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Scratch& s = scaled_with_normal(r, a, b, c);
  sub(s.ao, s.a, s.o);
  dot(s.D, s.n, s.d, s.t0);
  dot(s.N, s.n, s.ao, s.t0);
  if (s.D.sign() < 0) mpz_neg(s.N.v, s.N.v), mpz_neg(s.D.v, s.D.v);
  return round_ratio(s, s.N, s.D);
}

Answer exact_triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c, double lo) {
  ++g_fallbacks;
  Scratch& s = scaled_with_normal(r, a, b, c);
  if (s.n.x.sign() == 0 && s.n.y.sign() == 0 && s.n.z.sign() == 0) return make(Verdict::degenerate);
  sub(s.ao, s.a, s.o), sub(s.bo, s.b, s.o), sub(s.co, s.c, s.o);
  dot(s.D, s.n, s.d, s.t0);
  dot(s.N, s.n, s.ao, s.t0);
  if (s.D.sign() == 0) return make(s.N.sign() == 0 ? Verdict::coplanar : Verdict::miss);
  // Edge functions w = d . ((P - o) x (Q - o)) over the edges AB, BC, CA.
  ZV* ends[3][2] = {{&s.ao, &s.bo}, {&s.bo, &s.co}, {&s.co, &s.ao}};
  const int sD = s.D.sign();
  int zeros = 0;
  for (int i = 0; i < 3; ++i) {
    cross(s.w, *ends[i][0], *ends[i][1], s.t0);
    dot(s.ws[i], s.d, s.w, s.t0);
    const int sw = s.ws[i].sign();
    if (sw == -sD) return make(Verdict::miss);
    zeros += sw == 0;
  }
  if (sD < 0) mpz_neg(s.N.v, s.N.v), mpz_neg(s.D.v, s.D.v);  // now t = N / D with D > 0
  if (cmp_ratio(s, s.N, s.D, lo) < 0) return make(Verdict::miss);
  if (std::isfinite(r.tmax) && cmp_ratio(s, s.N, s.D, r.tmax) > 0) return make(Verdict::miss);
  return make(zeros ? Verdict::boundary : Verdict::hit, round_ratio(s, s.N, s.D), zeros);
}

}  // namespace

Answer triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  if (!(finite3(r.o) && finite3(r.d) && finite3(a) && finite3(b) && finite3(c)) || std::isnan(r.tmin) ||
      std::isnan(r.tmax))
    return make(Verdict::degenerate);
  if (r.d.x == 0 && r.d.y == 0 && r.d.z == 0) return make(Verdict::degenerate);
  const double lo = std::max(r.tmin, 0.0);
  if (lo > r.tmax || std::isinf(lo)) return make(Verdict::miss);
  Answer out;
  switch (filtered_triangle(r, a, b, c, lo, out)) {
    case Filtered::decided:
      return out;
    case Filtered::crossing:
      if (dd_triangle(r, a, b, c, lo, out, /*t_only=*/true)) return out;
      ++g_fallbacks;
      out.t = exact_t(r, a, b, c);
      return out;
    case Filtered::undecided:
      break;
  }
  if (dd_triangle(r, a, b, c, lo, out)) return out;
  return exact_triangle(r, a, b, c, lo);
}

// ---------------------------------------------------------------- sphere ---
namespace {

// sign(root - x) for root = (-B + s sqrt(disc)) / A, A > 0, disc >= 0, and
// x = sx.m 2^sx.e: compares s sqrt(disc) with Y = x A + B, both scaled by 2^k
// when x has a fraction.
int cmp_root(Scratch& sc, int s, Split sx) {
  Z& Y = sc.t0;
  Z& disc = sc.t1;
  mpz_mul_si(Y.v, sc.sA.v, static_cast<long>(sx.m));
  mpz_set(disc.v, sc.disc.v);
  if (sx.e >= 0) {
    mpz_mul_2exp(Y.v, Y.v, static_cast<mp_bitcnt_t>(sx.e));
    mpz_add(Y.v, Y.v, sc.sB.v);
  } else {
    const auto k = static_cast<mp_bitcnt_t>(-sx.e);
    mpz_mul_2exp(sc.t2.v, sc.sB.v, k);
    mpz_add(Y.v, Y.v, sc.t2.v);
    mpz_mul_2exp(disc.v, disc.v, 2 * k);
  }
  const int sy = Y.sign();
  if (s > 0 && sy < 0) return 1;
  if (s < 0 && sy > 0) return -1;
  mpz_mul(sc.t2.v, Y.v, Y.v);
  const int c = mpz_cmp(disc.v, sc.t2.v);  // disc vs Y^2
  const int mag = c > 0 ? 1 : (c < 0 ? -1 : 0);
  return s > 0 ? mag : -mag;
}

int cmp_root(Scratch& sc, int s, double x) { return cmp_root(sc, s, split(x)); }

// (a + b) / 2 exactly, for adjacent finite doubles a < b.
Split midpoint(double a, double b) {
  Split sa = split(a), sb = split(b);
  if (sa.m == 0) sa.e = sb.e;
  if (sb.m == 0) sb.e = sa.e;
  const int e = std::min(sa.e, sb.e);  // the exponents differ by at most 1
  return {sa.m * (std::int64_t(1) << (sa.e - e)) + sb.m * (std::int64_t(1) << (sb.e - e)), e - 1};
}

// The double nearest to root s (ties to even), from a guess t a few ulps off at
// most: t moves by one ulp while the root is beyond a midpoint next to it.
double nearest_root(Scratch& sc, int s, double t) {
  auto odd = [](double x) {
    std::uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    return (bits & 1) != 0;
  };
  for (;;) {
    if (!std::isfinite(t)) return t;
    const double up = std::nextafter(t, HUGE_VAL), down = std::nextafter(t, -HUGE_VAL);
    if (std::isfinite(up)) {
      const int c = cmp_root(sc, s, midpoint(t, up));
      if (c > 0 || (c == 0 && odd(t))) {
        t = up;
        continue;
      }
    }
    if (std::isfinite(down)) {
      const int c = cmp_root(sc, s, midpoint(down, t));
      if (c < 0 || (c == 0 && odd(t))) {
        t = down;
        continue;
      }
    }
    return t;
  }
}

bool root_in_window(Scratch& sc, int s, double lo, double hi) {
  if (cmp_root(sc, s, lo) < 0) return false;
  return !std::isfinite(hi) || cmp_root(sc, s, hi) <= 0;
}

// The roots q / A and C / q with q = -(B + sign(B) sqrt(disc)) (no cancellation),
// in MPFR at a precision well above the integers' sizes, then rounded to double.
// That precision does not make the rounding exact: a root can be closer to a
// midpoint m between doubles than the MPFR error (A m^2 + 2 B m + C is only
// bounded below by the square of m's last bit), and such roots were rounded to
// the wrong side (OracleDD.SphereRootsWithin2ToMinus200OfAMidpoint), so the
// MPFR value is only a guess that nearest_root settles exactly.
void sphere_roots(Scratch& sc, double& t_near, double& t_far) {
  const auto bits = std::max({mpz_sizeinbase(sc.sA.v, 2), mpz_sizeinbase(sc.sB.v, 2), mpz_sizeinbase(sc.sC.v, 2),
                              mpz_sizeinbase(sc.disc.v, 2) / 2});
  const auto prec = static_cast<mpfr_prec_t>(bits + 96);
  mpfr_set_prec(sc.big1, prec), mpfr_set_prec(sc.big2, prec), mpfr_set_prec(sc.big3, prec);
  mpfr_set_z(sc.big1, sc.disc.v, MPFR_RNDN);
  mpfr_sqrt(sc.big1, sc.big1, MPFR_RNDN);
  if (sc.sB.sign() < 0) mpfr_neg(sc.big1, sc.big1, MPFR_RNDN);
  mpfr_add_z(sc.big1, sc.big1, sc.sB.v, MPFR_RNDN);
  mpfr_neg(sc.big1, sc.big1, MPFR_RNDN);  // q
  mpfr_div_z(sc.big2, sc.big1, sc.sA.v, MPFR_RNDN);
  double r1 = mpfr_get_d(sc.big2, MPFR_RNDN), r2 = r1;
  if (!mpfr_zero_p(sc.big1)) {
    mpfr_set_z(sc.big3, sc.sC.v, MPFR_RNDN);
    mpfr_div(sc.big3, sc.big3, sc.big1, MPFR_RNDN);
    r2 = mpfr_get_d(sc.big3, MPFR_RNDN);
  }
  t_near = nearest_root(sc, -1, std::min(r1, r2));  // A > 0: the smaller root is -sqrt
  t_far = nearest_root(sc, 1, std::max(r1, r2));
}

}  // namespace

Answer sphere(const Rayd& r, const Vec3d& center, double radius) {
  if (!(finite3(r.o) && finite3(r.d) && finite3(center) && std::isfinite(radius)) || std::isnan(r.tmin) ||
      std::isnan(r.tmax) || !(radius > 0))
    return make(Verdict::degenerate);
  if (r.d.x == 0 && r.d.y == 0 && r.d.z == 0) return make(Verdict::degenerate);
  const double lo = std::max(r.tmin, 0.0), hi = r.tmax;
  if (lo > hi || std::isinf(lo)) return make(Verdict::miss);
  {
    // Filter: a certainly negative discriminant is a miss.
    CGAL::Protect_FPU_rounding<true> guard;
    const IV f = isub(r.o, center), d = iv(r.d);
    const I A = idot(d, d), B = idot(f, d), C = idot(f, f) - I(radius) * I(radius);
    if ((B * B - A * C).sup() < 0) return make(Verdict::miss);
  }
  {
    Answer out;
    if (dd_sphere(r, center, radius, lo, hi, out)) return out;
  }
  ++g_fallbacks;
  Scratch& sc = scratch();
  const int E = common_exponent({r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, center.x, center.y, center.z, radius});
  set_scaled(sc.o, r.o, E), set_scaled(sc.d, r.d, E), set_scaled(sc.c, center, E);
  set_scaled(sc.N, radius, E);
  sub(sc.ao, sc.o, sc.c);  // f = o - center
  dot(sc.sA, sc.d, sc.d, sc.t0);
  dot(sc.sB, sc.ao, sc.d, sc.t0);
  dot(sc.sC, sc.ao, sc.ao, sc.t0);
  mpz_mul(sc.t0.v, sc.N.v, sc.N.v), mpz_sub(sc.sC.v, sc.sC.v, sc.t0.v);
  mpz_mul(sc.disc.v, sc.sB.v, sc.sB.v), mpz_mul(sc.t0.v, sc.sA.v, sc.sC.v);
  mpz_sub(sc.disc.v, sc.disc.v, sc.t0.v);  // (B^2 - AC), B = f.d is half the usual b
  const int sdisc = sc.disc.sign();
  if (sdisc < 0) return make(Verdict::miss);
  double t_near, t_far;
  sphere_roots(sc, t_near, t_far);
  if (sdisc == 0) {
    if (!root_in_window(sc, 1, lo, hi)) return make(Verdict::miss);
    return make(Verdict::boundary, t_near);
  }
  const bool near_in = root_in_window(sc, -1, lo, hi), far_in = root_in_window(sc, 1, lo, hi);
  if (!near_in && !far_in) return make(Verdict::miss);
  Answer ans = make(Verdict::hit, near_in ? t_near : t_far);
  if (near_in && far_in) ans.t_far = t_far;
  return ans;
}

unsigned long long exact_fallbacks() { return g_fallbacks; }

}  // namespace ra::oracle
