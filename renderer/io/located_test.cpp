// located(): one printable line of bounded length whatever the input quoted
// (a 100 MB path in a scene was a 100 MB line).
#include <gtest/gtest.h>

#include <string>

#include "../errors.h"

namespace ra {
namespace {

TEST(Located, AnOverlongFileOrMessageIsCutFromTheMiddleSayingHowMuch) {
  const std::string file = "dir/" + std::string(100000, 'f') + ".json";
  const std::string msg = "/objects/0/mesh: file not found: " + std::string(1000000, 'a') + "b.obj";
  const std::string s = located(file, 3, msg);
  EXPECT_LT(s.size(), 3300u);
  EXPECT_EQ(s.rfind("dir/fff", 0), 0u) << "starts with the file's head";
  EXPECT_NE(s.find(".json:3: /objects/0/mesh: file not found: aaa"), std::string::npos) << "the file's tail, the line";
  EXPECT_NE(s.find("bytes cut)..."), std::string::npos);
  EXPECT_EQ(s.substr(s.size() - 5), "b.obj") << "the message's tail kept";
  EXPECT_EQ(s.find('\n'), std::string::npos);
  EXPECT_EQ(located("s.json", 0, "short"), "s.json: short") << "short text untouched";
}

}  // namespace
}  // namespace ra
