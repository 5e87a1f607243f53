// The exact method's stage 3 (exact.h): the whole test in GMP rationals over
// the inputs' exact values, t rounded to nearest by MPFR in T's own exponent
// range (subnormals and overflow included).
#include "exact.h"

#include <gmp.h>
#include <mpfr.h>

#include <atomic>

namespace ra::exact {

namespace {
std::atomic<std::uint64_t> g_extended{0}, g_exact{0};
}  // namespace

Fallbacks fallbacks() { return {g_extended.load(std::memory_order_relaxed), g_exact.load(std::memory_order_relaxed)}; }
void count_extended() { g_extended.fetch_add(1, std::memory_order_relaxed); }
void count_exact() { g_exact.fetch_add(1, std::memory_order_relaxed); }

namespace {

// Thread-local rationals, initialised once (no allocation once warm).
struct Scratch {
  enum { kO = 0, kD = 3, kA = 6, kB = 9, kC = 12, kBC = 15, kCA = 18, kAB = 21, kN = 24 };
  mpq_t q[kN];
  mpq_t U, V, W, det, num, t, x, y;
  mpfr_t rf, rd;
  Scratch() {
    for (auto& v : q) mpq_init(v);
    for (mpq_t* v : {&U, &V, &W, &det, &num, &t, &x, &y}) mpq_init(*v);
    mpfr_init2(rf, 24);
    mpfr_init2(rd, 53);
  }
  ~Scratch() {
    for (auto& v : q) mpq_clear(v);
    for (mpq_t* v : {&U, &V, &W, &det, &num, &t, &x, &y}) mpq_clear(*v);
    mpfr_clear(rf);
    mpfr_clear(rd);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
};

Scratch& scratch() {
  static thread_local Scratch s;
  return s;
}

template <class T>
bool finite3(const Vec3<T>& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// out = p . (q x r) over rationals, using x, y as temporaries.
void triple(mpq_t out, const mpq_t* p, const mpq_t* q, const mpq_t* r, mpq_t x, mpq_t y) {
  mpq_set_ui(out, 0, 1);
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    mpq_mul(x, q[j], r[k]);
    mpq_mul(y, q[k], r[j]);
    mpq_sub(x, x, y);
    mpq_mul(x, x, p[i]);
    mpq_add(out, out, x);
  }
}

// The rational q rounded to nearest T (ties to even), subnormals and
// overflow as IEEE 754 does them.
template <class T>
T round_to(const mpq_t q, Scratch& s) {
  constexpr bool kFloat = sizeof(T) == sizeof(float);
  mpfr_ptr x = kFloat ? s.rf : s.rd;
  const mpfr_exp_t emin = mpfr_get_emin(), emax = mpfr_get_emax();
  // MPFR writes values as m 2^e, 1/2 <= m < 1: T's smallest subnormal is
  // 2^-1074 = 1/2 2^-1073 (float: 2^-149 = 1/2 2^-148), its largest finite
  // value below 2^1024 (2^128); the range mpfr_subnormalize's manual uses.
  mpfr_set_emin(kFloat ? -148 : -1073);
  mpfr_set_emax(kFloat ? 128 : 1024);
  int inex = mpfr_set_q(x, q, MPFR_RNDN);
  inex = mpfr_check_range(x, inex, MPFR_RNDN);
  mpfr_subnormalize(x, inex, MPFR_RNDN);
  const T out = kFloat ? T(mpfr_get_flt(x, MPFR_RNDN)) : T(mpfr_get_d(x, MPFR_RNDN));
  mpfr_set_emin(emin);
  mpfr_set_emax(emax);
  return out;
}

// ------------------------------------------------- double-double stage ---
// Double-word arithmetic (Joldes, Muller, Popescu, "Tight and rigorous error
// bounds for basic building blocks of double-word arithmetic", ACM TOMS 44,
// 2017; u = 2^-53): two_sum and two_prod (with a correctly rounded fma) are
// exact; AccurateDWPlusDW (their Alg. 6) errs by at most 3u^2 relative to
// its exact result, DWTimesDW (Alg. 12, fma) by 5u^2, DWDivDW (Alg. 17) by
// 15u^2 + 56u^3, all as long as nothing underflows or overflows.
struct DW {
  double h = 0, l = 0;
};
inline DW two_sum(double a, double b) {
  const double s = a + b, bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}
inline DW fast_two_sum(double a, double b) {  // |a| >= |b|
  const double s = a + b;
  return {s, b - (s - a)};
}
inline DW two_prod(double a, double b) {
  const double p = a * b;
  return {p, std::fma(a, b, -p)};
}
inline DW add(DW x, DW y) {  // AccurateDWPlusDW
  const DW s = two_sum(x.h, y.h), t = two_sum(x.l, y.l);
  DW v = fast_two_sum(s.h, s.l + t.h);
  return fast_two_sum(v.h, t.l + v.l);
}
inline DW neg(DW x) { return {-x.h, -x.l}; }
inline DW mul(DW x, DW y) {  // DWTimesDW3
  const DW c = two_prod(x.h, y.h);
  const double tl0 = x.l * y.l, tl1 = std::fma(x.h, y.l, tl0), cl2 = std::fma(x.l, y.h, tl1);
  return fast_two_sum(c.h, c.l + cl2);
}
inline DW div(DW x, DW y) {  // DWDivDW2
  const double th = x.h / y.h;
  const DW r = mul(y, DW{th, 0});
  const double ph = x.h - r.h, dl = x.l - r.l, d = ph + dl, tl = d / y.h;
  return fast_two_sum(th, tl);
}

}  // namespace

namespace detail {

// t for double inputs in double-word arithmetic, when the long double
// enclosure could not round it: N = n . A' and D = n . d from exact
// differences (two_sum), n = e1 x e2 with e1, e2 exact.
//   n_i: two products (5u^2 each) and an accurate difference (3u^2 of the
//   result <= the permanent): within 9u^2 Pn_i; N: n_i q_i adds 5u^2 and
//   the two sums 3u^2 each of partial sums <= PN: |N~ - N| <= 20u^2 PN
//   (+ second-order terms), taken as 64u^2 PN; D likewise. Underflow:
//   inputs are <= 2^250 here, so an underflowing rounding (<= 2^-1074)
//   grows through at most two products by 2^251 each: tau = 2^-560.
//   t~ = N~ / D~ (15u^2 + 56u^3, taken as 32u^2): with a, b as in exact.h,
//   |t / t~ - 1| <= 2 (a + b) + 33u^2 < the width w below. When t~.l +- w
//   stays inside half the gaps either side of t~.h, t rounds to t~.h
//   (correctly rounded) and lies on t~.h's side of any other double: the
//   window [tlo, thi] is then decided when t~.h != tlo, thi.
Dist t_double_word(const Ray<double>& r, const Vec3<double>& a, const Vec3<double>& b, const Vec3<double>& c,
                   double& t_out) {
  const double big = 0x1p250;
  for (const Vec3<double>* v : {&r.o, &r.d, &a, &b, &c})
    if (!(std::abs(v->x) <= big && std::abs(v->y) <= big && std::abs(v->z) <= big)) return Dist::undecided;
  DW e1[3], e2[3], q[3], n[3];
  double pn[3];
  for (int i = 0; i < 3; ++i) {
    e1[i] = two_sum(b[i], -a[i]);
    e2[i] = two_sum(c[i], -a[i]);
    q[i] = two_sum(a[i], -r.o[i]);
  }
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    n[i] = add(mul(e1[j], e2[k]), neg(mul(e1[k], e2[j])));
    pn[i] = std::abs(e1[j].h * e2[k].h) + std::abs(e1[k].h * e2[j].h);
  }
  DW N = mul(n[0], q[0]), D = mul(n[0], DW{r.d.x, 0});
  for (int i = 1; i < 3; ++i) {
    N = add(N, mul(n[i], q[i]));
    D = add(D, mul(n[i], DW{r.d[i], 0}));
  }
  constexpr double u2 = 0x1p-106, tau = 0x1p-560;
  // The permanents from the high parts, inflated for the low parts' 2^-52
  // and the products' roundings (1 + 2^-40).
  const double PN = (pn[0] * std::abs(q[0].h) + pn[1] * std::abs(q[1].h) + pn[2] * std::abs(q[2].h)) * (1 + 0x1p-40);
  const double PD = (pn[0] * std::abs(r.d.x) + pn[1] * std::abs(r.d.y) + pn[2] * std::abs(r.d.z)) * (1 + 0x1p-40);
  const double eN = 64 * u2 * PN + tau, eD = 64 * u2 * PD + tau;
  const double aN = std::abs(N.h), aD = std::abs(D.h);
  if (!(aN > 4 * eN && aD > 4 * eD)) return Dist::undecided;
  const DW t = div(N, D);
  if (!std::isfinite(t.h) || std::abs(t.h) < 0x1p-900) return Dist::undecided;
  const double w = std::abs(t.h) * ((2 * (eN / aN + eD / aD) + 64 * u2) * (1 + 0x1p-40));
  const double up = std::nextafter(t.h, INFINITY) - t.h, down = t.h - std::nextafter(t.h, -INFINITY);
  if (!(t.l + w < 0.5 * up * (1 - 0x1p-40) && t.l - w > -0.5 * down * (1 - 0x1p-40))) return Dist::undecided;
  const double tlo = std::max(r.tmin, 0.0);
  if (t.h < tlo || t.h > r.tmax) return Dist::out;
  if (!(t.h > tlo && t.h < r.tmax)) return Dist::undecided;  // on a window end (or a NaN window)
  t_out = t.h;
  return Dist::in;
}

}  // namespace detail

template <class T>
std::optional<TriangleHit<T>> hit_exact(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                        bool cull) {
  if (!finite3(r.o) || !finite3(r.d) || !finite3(a) || !finite3(b) || !finite3(c)) return std::nullopt;
  if (std::isnan(r.tmin) || std::isnan(r.tmax)) return std::nullopt;
  const T tlo = std::max(r.tmin, T(0));
  if (tlo > r.tmax) return std::nullopt;
  Scratch& s = scratch();
  mpq_t* q = s.q;
  const Vec3<T>* in[5] = {&r.o, &r.d, &a, &b, &c};
  for (int v = 0; v < 5; ++v)
    for (int i = 0; i < 3; ++i) mpq_set_d(q[3 * v + i], double((*in[v])[i]));  // exact
  // Translate the vertices to the origin: A' = A - o, etc.
  for (int v = Scratch::kA; v <= Scratch::kC; v += 3)
    for (int i = 0; i < 3; ++i) mpq_sub(q[v + i], q[v + i], q[Scratch::kO + i]);
  const mpq_t* d = q + Scratch::kD;
  const mpq_t *A = q + Scratch::kA, *B = q + Scratch::kB, *C = q + Scratch::kC;
  // U = d . (B' x C'), V = d . (C' x A'), W = d . (A' x B')
  triple(s.U, d, B, C, s.x, s.y);
  triple(s.V, d, C, A, s.x, s.y);
  triple(s.W, d, A, B, s.x, s.y);
  const int su = mpq_sgn(s.U), sv = mpq_sgn(s.V), sw = mpq_sgn(s.W);
  const bool pos = su > 0 || sv > 0 || sw > 0, neg = su < 0 || sv < 0 || sw < 0;
  if (pos == neg) return std::nullopt;   // opposite signs, or all zero (det = 0)
  if (cull && pos) return std::nullopt;  // det = n . d > 0: the back face
  mpq_add(s.det, s.U, s.V);
  mpq_add(s.det, s.det, s.W);
  // N = [A', B', C'] = n . A'; t = N / det.
  triple(s.num, A, B, C, s.x, s.y);
  mpq_div(s.t, s.num, s.det);
  mpq_set_d(s.x, double(tlo));
  if (mpq_cmp(s.t, s.x) < 0) return std::nullopt;
  if (std::isfinite(r.tmax)) {
    mpq_set_d(s.x, double(r.tmax));
    if (mpq_cmp(s.t, s.x) > 0) return std::nullopt;
  }
  TriangleHit<T> h;
  h.t = round_to<T>(s.t, s);
  mpq_div(s.x, s.V, s.det);
  h.b1 = round_to<T>(s.x, s);
  mpq_div(s.x, s.W, s.det);
  h.b2 = round_to<T>(s.x, s);
  return h;
}

template std::optional<TriangleHit<float>> hit_exact(const Ray<float>&, const Vec3<float>&, const Vec3<float>&,
                                                     const Vec3<float>&, bool);
template std::optional<TriangleHit<double>> hit_exact(const Ray<double>&, const Vec3<double>&, const Vec3<double>&,
                                                      const Vec3<double>&, bool);

}  // namespace ra::exact
