// PLY (ascii, binary little/big endian) and OFF readers, and the OBJ writer.
#include <gtest/gtest.h>

#include <algorithm>

#include <cstring>

#include "../errors.h"
#include "mesh.h"
#include "polymesh_io.h"

namespace ra {
namespace {

// The unit square z=0 as one quad plus a triangle (0,0,0) (1,0,0) (0,0,1):
// OBJ area 1 + 0.5.
void expect_square(const PolyMesh& m) {
  ASSERT_EQ(m.positions.size(), 5u);
  EXPECT_EQ(m.positions[2], Vec3d(1, 1, 0));
  EXPECT_EQ(m.positions[4], Vec3d(0, 0, 1));
  ASSERT_EQ(m.faces(), 2u);
  EXPECT_EQ(m.face_start, (std::vector<int>{0, 4, 7}));
  EXPECT_EQ(m.indices, (std::vector<int>{0, 1, 2, 3, 0, 1, 4}));
  const Mesh obj = parse_obj(to_obj_text(m, "test"), "c.obj");
  EXPECT_EQ(obj.triangles.size(), 3u);
  EXPECT_DOUBLE_EQ(obj.area(), 1.5);
}

const char* kHeader =
    "element vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n";

TEST(Ply, Ascii) {
  expect_square(parse_ply(std::string("ply\nformat ascii 1.0\ncomment hi\n") + kHeader +
                              "0 0 0 255\n1 0 0 0\n1 1 0 0\n0 1 0 0\n0 0 1 0\n4 0 1 2 3\n3 0 1 4\n",
                          "a.ply"));
}

std::string binary_body(bool big) {
  std::string b;
  auto put = [&](const void* p, size_t n) {
    std::string s(static_cast<const char*>(p), n);
    if (big) std::reverse(s.begin(), s.end());
    b += s;
  };
  const float v[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}};
  for (auto& p : v) {
    for (float c : p) put(&c, 4);
    b += char(7);  // red
  }
  const std::vector<std::vector<int>> faces = {{0, 1, 2, 3}, {0, 1, 4}};
  for (auto& f : faces) {
    b += char(f.size());
    for (int i : f) put(&i, 4);
  }
  return b;
}

TEST(Ply, BinaryLittleAndBigEndian) {
  expect_square(
      parse_ply(std::string("ply\nformat binary_little_endian 1.0\n") + kHeader + binary_body(false), "l.ply"));
  expect_square(parse_ply(std::string("ply\nformat binary_big_endian 1.0\n") + kHeader + binary_body(true), "b.ply"));
}

TEST(Ply, Errors) {
  EXPECT_THROW(parse_ply("plx\n", "x.ply"), InputError);
  const std::string trunc =
      std::string("ply\nformat binary_little_endian 1.0\n") + kHeader + binary_body(false).substr(0, 30);
  try {
    parse_ply(trunc, "t.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.ply: byte"), std::string::npos) << e.what();
  }
  try {
    parse_ply(std::string("ply\nformat ascii 1.0\n") + kHeader +
                  "0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n0 0 1 1\n4 0 1 2 9\n3 0 1 4\n",
              "r.ply");
    FAIL();
  } catch (const InputError& e) {
    // ply, format, 8 header lines, 5 vertices: the face is line 16.
    EXPECT_STREQ(e.what(), "r.ply:16: face 0 has vertex index 9 out of range (5 vertices, from 0)");
  }
  // Binary: no lines, so the byte offset after the face's list.
  std::string body = binary_body(false);
  body[body.size() - 13 - 4] = 9;  // the quad's last index (the triangle takes the last 13 bytes), little endian
  const std::string head = std::string("ply\nformat binary_little_endian 1.0\n") + kHeader;
  try {
    parse_ply(head + body, "b.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.ply: byte "), std::string::npos) << e.what();
    // Offsets count from the start of the file, and the quad ends where the
    // triangle's 13 bytes begin.
    EXPECT_NE(std::string(e.what()).find("b.ply: byte " + std::to_string(head.size() + body.size() - 13) + ": face 0"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("face 0 has vertex index 9 out of range"), std::string::npos) << e.what();
  }
}

TEST(Off, ReadsWithCommentsAndColours) {
  expect_square(
      parse_off("OFF\n# a comment\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n4 0 1 2 3 255 0 0\n3 0 1 4\n", "s.off"));
  expect_square(parse_off("OFF 5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n4 0 1 2 3\n3 0 1 4\n", "s.off"));
}

// The values a magic promises are accepted in each form (a colour of 3 or
// 4), and a CR-only file reads as lines.
TEST(Off, ExtrasTheMagicPromisesAndCrOnlyLineEnds) {
  const std::string v = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n";
  auto with = [&](const std::string& extra) {
    std::string out;
    for (std::size_t b = 0, e; (e = v.find('\n', b)) != std::string::npos; b = e + 1)
      out += v.substr(b, e - b) + extra + "\n";
    return out;
  };
  const std::string faces = "4 0 1 2 3\n3 0 1 4\n";
  expect_square(parse_off("NOFF\n5 2 0\n" + with(" 0 0 1") + faces, "n.off"));
  expect_square(parse_off("COFF\n5 2 0\n" + with(" 1 0 0") + faces, "c.off"));
  expect_square(parse_off("COFF\n5 2 0\n" + with(" 255 0 0 255") + faces, "c.off"));
  expect_square(parse_off("STCNOFF\n5 2 0\n" + with(" 0 0 1 1 0 0 1 0.5 0.5") + faces, "s.off"));
  std::string cr = "OFF\n5 2 0\n" + v + faces;
  std::replace(cr.begin(), cr.end(), '\n', '\r');
  expect_square(parse_off(cr, "cr.off"));
  try {
    parse_off("STOFF\n5 2 0\n" + with(" 0.5") + faces, "st.off");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "st.off:3: STOFF vertex needs x y z and a texture coordinate (2 values) (1 values after x y z)");
  }
}

TEST(Off, Errors) {
  try {
    parse_off("OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 x\n", "e.off");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "e.off:6: malformed z coordinate 'x'");
  }
  // A vertex line one value short is an error at that line, not a misread
  // of the next line's first value as its z.
  try {
    parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1\n3 0 1 2\n", "short.off");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "short.off:5: expected z coordinate, found the end of the line");
  }
  try {
    parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "index.off");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "index.off:6: vertex index 7 out of range (3 vertices, from 0)");
  }
}

}  // namespace
}  // namespace ra
