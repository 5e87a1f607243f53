// The registry lists every method once, in the order the CLI and the
// benchmarks rely on, with complete kernels and honest metadata.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../registry.h"

namespace ra {
namespace {

TEST(RegistryMethods, OrderAndKinds) {
  std::vector<std::string> names;
  for (const auto& m : methods()) names.push_back(m.name);
  const std::vector<std::string> expected{
      "angles",  "cramer", "areas", "triple",      "sameside",          "moller", "watertight",
      "baldwin", "exact",  "kraus", "codeproject", "codeproject-fixed", "stable", "plane"};
  EXPECT_EQ(names, expected);
  EXPECT_EQ(method_names(Kind::sphere), "kraus, codeproject, codeproject-fixed, stable");
  EXPECT_EQ(default_method(Kind::triangle).name, "moller");
  EXPECT_EQ(default_method(Kind::sphere).name, "stable");
}

TEST(RegistryMethods, KernelsAndMetadataComplete) {
  for (const auto& m : methods()) {
    SCOPED_TRACE(m.name);
    EXPECT_FALSE(m.source.empty());
    EXPECT_FALSE(m.description.empty());
    EXPECT_EQ(m.wrong_on_purpose, m.name == "codeproject");
    if (m.kind == Kind::triangle) {
      EXPECT_TRUE(m.tri_f.hit && m.tri_f.any && m.tri_f.prepare && m.tri_f.hit_pre && m.tri_f.any_pre);
      EXPECT_TRUE(m.tri_d.hit && m.tri_d.any && m.tri_d.prepare && m.tri_d.hit_pre && m.tri_d.any_pre);
      EXPECT_GT(m.tri_f.pre_bytes, 0u);
      EXPECT_GT(m.tri_d.pre_bytes, 0u);
    } else if (m.kind == Kind::sphere) {
      EXPECT_TRUE(m.sph_f.hit && m.sph_f.any && m.sph_d.hit && m.sph_d.any);
    } else {
      EXPECT_TRUE(m.pln_f.hit && m.pln_f.any && m.pln_d.hit && m.pln_d.any);
    }
  }
}

// Only baldwin and exact store more than the vertices: baldwin its 3x4
// transform, exact its vertices with the normal and its permanents.
TEST(RegistryMethods, PrecomputeBytes) {
  for (const auto& m : methods()) {
    SCOPED_TRACE(m.name);
    if (m.name == "baldwin") {
      EXPECT_EQ(m.precompute_bytes_float, 12 * sizeof(float));
      EXPECT_EQ(m.precompute_bytes_double, 12 * sizeof(double));
      EXPECT_EQ(m.tri_f.pre_bytes, m.precompute_bytes_float);
      EXPECT_EQ(m.tri_d.pre_bytes, m.precompute_bytes_double);
    } else if (m.name == "exact") {
      EXPECT_GT(m.precompute_bytes_float, 9 * sizeof(float));
      EXPECT_GT(m.precompute_bytes_double, 9 * sizeof(double));
      EXPECT_EQ(m.tri_f.pre_bytes, m.precompute_bytes_float);
      EXPECT_EQ(m.tri_d.pre_bytes, m.precompute_bytes_double);
    } else {
      EXPECT_EQ(m.precompute_bytes_float, 0u);
      EXPECT_EQ(m.precompute_bytes_double, 0u);
    }
  }
}

}  // namespace
}  // namespace ra
