// --explain against the real POV-Ray 3.7 on issue 18's Cornell box: the
// 255-level pixel on the light quad's edge is decided by POV's own mesh2
// inside test, which our default tracer does not use.
#include "pov_explain.h"

#include <gtest/gtest.h>

#include "errors.h"
#include "image_compare.h"
#include "pov_runner.h"
#include "golden.h"

namespace ra {
namespace {

TEST(PovExplain, CornellBoxEdgePixelIsPovsMeshInsideTest) {
  try {
    find_povray();
  } catch (const InputError&) {
    GTEST_SKIP() << "POV-Ray is not installed (Debian package povray)";
  }
  const auto file = std::filesystem::path(RAYAUDIT_SOURCE_DIR) / "scenes" / "corpus" / "cornell-box.json";
  if (!missing_cache_inputs(file).empty()) GTEST_SKIP() << "the corpus cache is empty (ci/fetch-corpus.sh)";
  Scene scene = load_scene(file);
  RenderOptions opt;
  opt.progress = false;
  const Image ours = render(scene, opt);
  const Image pov = render_with_povray(scene).image;
  const ImageComparison c = compare_images(ours, pov, 8);
  bool found = false;
  for (const auto& d : c.differences) found |= d.x == 301 && d.y == 63 && d.levels > 200;
  ASSERT_TRUE(found) << "POV-Ray and we no longer differ at (301, 63): the case is gone";
  // Our tracer with POV's mesh2 test sees what POV-Ray sees there.
  RenderOptions pov_test = opt;
  pov_test.pov_mesh_hit = pov_test.pov_mesh_intersect = true;
  const Color with_pov_test = Tracer(scene, pov_test).pixel(301, 63);
  EXPECT_EQ(quantize(float(with_pov_test.x), 255), quantize(pov.at(301, 63)[0], 255));
  const auto ex = explain_differences(scene, ours, pov, c, opt);
  for (const auto& e : ex) {
    EXPECT_FALSE(e.cause.empty()) << "(" << e.x << ", " << e.y << ") unexplained";
    if (e.x == 301 && e.y == 63) {
      EXPECT_EQ(e.cause.rfind("mesh2 intersection", 0), 0u) << e.cause;
    }
  }
}

}  // namespace
}  // namespace ra
