// A user's test of their own intersector: the audit's GoogleTest helper
// checks it against the exact oracle on shared edges, vertices and closed meshes.
#include <gtest/gtest.h>

#include <rayaudit/audit.h>
#include <rayaudit/audit_gtest.h>

#include "textbook_moller.h"

TEST(MyIntersector, IsWatertight) {
  const auto mine = ra::audit::triangle_subject<float>("textbook-moller", my::textbook_moller);
  EXPECT_WATERTIGHT(mine);
}
