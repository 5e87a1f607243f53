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
#include <limits>

namespace ra::oracle {

std::string_view verdict_name(Verdict v) {
  switch (v) {
    case Verdict::hit: return "hit";
    case Verdict::miss: return "miss";
    case Verdict::boundary: return "boundary";
    case Verdict::coplanar: return "coplanar";
    case Verdict::degenerate: return "degenerate";
  }
  return "?";
}

bool parse_verdict(std::string_view s, Verdict& out) {
  for (Verdict v : {Verdict::hit, Verdict::miss, Verdict::boundary, Verdict::coplanar,
                    Verdict::degenerate})
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
IV icross(const IV& a, const IV& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
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
Filtered filtered_triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                           double lo, Answer& out) {
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
  const int w[3] = {isign(idot(d, icross(ao, bo))), isign(idot(d, icross(bo, co))),
                    isign(idot(d, icross(co, ao)))};
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
double round_ratio(Scratch& s, const Z& num, const Z& den) {
  mpz_set(mpq_numref(s.q), num.v);
  mpz_set(mpq_denref(s.q), den.v);
  mpfr_set_q(s.f53, s.q, MPFR_RNDN);
  return mpfr_get_d(s.f53, MPFR_RNDN);
}

// t = N / D exactly rounded, for a crossing the filter already certified.
double exact_t(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Scratch& s = scratch();
  const int E = common_exponent({r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, a.x, a.y, a.z, b.x, b.y,
                                 b.z, c.x, c.y, c.z});
  set_scaled(s.o, r.o, E), set_scaled(s.d, r.d, E);
  set_scaled(s.a, a, E), set_scaled(s.b, b, E), set_scaled(s.c, c, E);
  sub(s.e1, s.b, s.a), sub(s.e2, s.c, s.a);
  cross(s.n, s.e1, s.e2, s.t0);
  sub(s.ao, s.a, s.o);
  dot(s.D, s.n, s.d, s.t0);
  dot(s.N, s.n, s.ao, s.t0);
  if (s.D.sign() < 0) mpz_neg(s.N.v, s.N.v), mpz_neg(s.D.v, s.D.v);
  return round_ratio(s, s.N, s.D);
}

Answer exact_triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c, double lo) {
  ++g_fallbacks;
  Scratch& s = scratch();
  const int E = common_exponent({r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, a.x, a.y, a.z, b.x, b.y,
                                 b.z, c.x, c.y, c.z});
  set_scaled(s.o, r.o, E), set_scaled(s.d, r.d, E);
  set_scaled(s.a, a, E), set_scaled(s.b, b, E), set_scaled(s.c, c, E);
  sub(s.e1, s.b, s.a), sub(s.e2, s.c, s.a);
  cross(s.n, s.e1, s.e2, s.t0);
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
  if (!(finite3(r.o) && finite3(r.d) && finite3(a) && finite3(b) && finite3(c)) ||
      std::isnan(r.tmin) || std::isnan(r.tmax))
    return make(Verdict::degenerate);
  if (r.d.x == 0 && r.d.y == 0 && r.d.z == 0) return make(Verdict::degenerate);
  const double lo = std::max(r.tmin, 0.0);
  if (lo > r.tmax || std::isinf(lo)) return make(Verdict::miss);
  Answer out;
  switch (filtered_triangle(r, a, b, c, lo, out)) {
    case Filtered::decided: return out;
    case Filtered::crossing: out.t = exact_t(r, a, b, c); return out;
    case Filtered::undecided: break;
  }
  return exact_triangle(r, a, b, c, lo);
}

// ---------------------------------------------------------------- sphere ---
namespace {

// sign(root - x) for root = (-B + s sqrt(disc)) / A, A > 0, disc >= 0: compares
// s sqrt(disc) with Y = x A + B, both scaled by 2^k when x has a fraction.
int cmp_root(Scratch& sc, int s, double x) {
  const Split sx = split(x);
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

bool root_in_window(Scratch& sc, int s, double lo, double hi) {
  if (cmp_root(sc, s, lo) < 0) return false;
  return !std::isfinite(hi) || cmp_root(sc, s, hi) <= 0;
}

// The roots q / A and C / q with q = -(B + sign(B) sqrt(disc)) (no cancellation),
// in MPFR at a precision well above the integers' sizes, then rounded to double.
void sphere_roots(Scratch& sc, double& t_near, double& t_far) {
  const auto bits = std::max({mpz_sizeinbase(sc.sA.v, 2), mpz_sizeinbase(sc.sB.v, 2),
                              mpz_sizeinbase(sc.sC.v, 2), mpz_sizeinbase(sc.disc.v, 2) / 2});
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
  t_near = std::min(r1, r2);
  t_far = std::max(r1, r2);
}

}  // namespace

Answer sphere(const Rayd& r, const Vec3d& center, double radius) {
  if (!(finite3(r.o) && finite3(r.d) && finite3(center) && std::isfinite(radius)) ||
      std::isnan(r.tmin) || std::isnan(r.tmax) || !(radius > 0))
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
  ++g_fallbacks;
  Scratch& sc = scratch();
  const int E = common_exponent({r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, center.x, center.y,
                                 center.z, radius});
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
