// The exact method (renderer/methods/exact.h) graded by the oracle on every
// triangle family, both precisions: no error of any kind. The two share no
// code and no formulation (Plücker signs and t = n.A' / n.d with a double,
// long double and GMP/MPFR cascade against CGAL intervals, double-double and
// scaled integers), so agreement is evidence for both. Prints the share of
// tests each family sends past the double filter (the 1e6-ray figures are in
// renderer/methods/README.md).
#include <gtest/gtest.h>

#include <cstdio>

#include "audit.h"
#include "methods/exact.h"

namespace {

using namespace ra::audit;

TEST(ExactMethodAudit, NoErrorsOnAnyFamilyAndFallbackRates) {
  const ra::Method* m = ra::find_method("exact");
  ASSERT_NE(m, nullptr);
  for (Precision p : {Precision::f32, Precision::f64}) {
    for (const Family& f : families()) {
      if (f.kind != ra::Kind::triangle) continue;
      Options o;
      o.families = {f.name};
      o.rays = 20000;
      o.seed = 29;
      const ra::exact::Fallbacks before = ra::exact::fallbacks();
      const Report r = run({registry_triangle(*m, p)}, {}, o);
      const ra::exact::Fallbacks after = ra::exact::fallbacks();
      const Stats s = r.total(0);
      const double n = double(s.tests);
      std::printf("exact/%s %-12s tests %7llu  stage 2 (long double) %6.3f%%  stage 3 (GMP) %6.3f%%\n",
                  precision_name(p), f.name.c_str(), (unsigned long long)(s.tests),
                  100.0 * double(after.extended - before.extended) / n, 100.0 * double(after.exact - before.exact) / n);
      EXPECT_GT(s.tests, 0u) << f.name;
      EXPECT_EQ(s.false_hits, 0u) << f.name << " " << precision_name(p);
      EXPECT_EQ(s.false_misses, 0u) << f.name << " " << precision_name(p);
      EXPECT_EQ(s.wrong_t, 0u) << f.name << " " << precision_name(p);
      EXPECT_EQ(s.nan_inf, 0u) << f.name << " " << precision_name(p);
      EXPECT_EQ(s.leaks, 0u) << f.name << " " << precision_name(p);
      EXPECT_EQ(s.double_hits, 0u) << f.name << " " << precision_name(p);
      // t correctly rounded: within 1 ulp of the oracle's t, which is the
      // exact t rounded to double (then to float: at most one more rounding).
      EXPECT_LE(s.max_ulps, 1u) << f.name << " " << precision_name(p);
    }
  }
}

}  // namespace
