// The exact method's stage 3 (exact.h): the whole test in GMP rationals over
// the inputs' exact values, t rounded to nearest by MPFR in T's own exponent
// range (subnormals and overflow included).
#include "exact.h"

#include <gmp.h>
#include <mpfr.h>

namespace ra::exact {

Fallbacks& fallbacks() {
  static thread_local Fallbacks f;
  return f;
}

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

}  // namespace

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
  if (pos == neg) return std::nullopt;  // opposite signs, or all zero (det = 0)
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
