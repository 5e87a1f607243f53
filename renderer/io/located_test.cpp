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

// Messages quote bad input: control bytes and bytes that are not UTF-8
// come out as \xNN, so the message stays one printable line.
TEST(Located, ControlAndNonUtf8BytesAreEscaped) {
  EXPECT_EQ(located("f.ply", 9, std::string("malformed PLY value '") + '\0' + "'"),
            "f.ply:9: malformed PLY value '\\x00'");
  EXPECT_EQ(located("a\nb", 0, "x\ry\xff\xfez"), "a\\x0ab: x\\x0dy\\xff\\xfez");
  EXPECT_EQ(located("f", 1, "caf\xc3\xa9 \xe2\x82\xac"), "f:1: caf\xc3\xa9 \xe2\x82\xac");  // UTF-8 kept
}

}  // namespace
}  // namespace ra
