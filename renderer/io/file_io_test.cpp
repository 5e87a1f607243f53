// The io room's guarantees (atomic_file.h, input_file.h, json_input.h):
// every writer on a full disk fails with the output named and the good file
// kept; inputs that are FIFOs, devices, directories or symlink loops are
// named as such without blocking; JSON errors at the line of the fault, in
// our words rather than the library's.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>

#include "errors.h"
#include "image.h"
#include "io/atomic_file.h"
#include "io/full_disk.h"
#include "io/input_file.h"
#include "io/json_input.h"

namespace fs = std::filesystem;
using namespace ra;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// An image whose PNG does not compress to nothing (noise-like values).
Image busy_image(int w, int h) {
  Image img(w, h);
  std::uint32_t s = 12345;
  for (auto& v : img.rgb) {
    s = s * 1664525u + 1013904223u;
    v = float(s >> 8) / float(1u << 24);
  }
  return img;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Every image format, on a full disk: an InputError naming the output, the
// good file that was there untouched, no temporary left behind.
TEST(FullDisk, WriteImageFailsAndKeepsTheGoodFile) {
  test::FullDisk disk(16384);
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const Image img = busy_image(200, 200);  // about 120 KB of PNG: more than the room left
  // The good files first (a page each on tmpfs), then the writes that fail.
  for (const char* name : {"out.png", "out16.png", "out.exr"}) std::ofstream(disk.dir() / name) << "good";
  for (const std::string name : {"out.png", "out16.png", "out.exr"}) {
    SCOPED_TRACE(name);
    const fs::path out = disk.dir() / name;
    ASSERT_EQ(slurp(out), "good");
    ImageWriteOptions o;
    o.bits = name == "out16.png" ? 16 : 8;
    const std::string err = error_of([&] { write_image(out, img, o); });
    EXPECT_NE(err.find(out.string()), std::string::npos) << err;
    EXPECT_NE(err.find("cannot write"), std::string::npos) << err;
    EXPECT_EQ(slurp(out), "good");
  }
  for (const auto& e : fs::directory_iterator(disk.dir()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
}

TEST(FullDisk, WriteTextFailsAndKeepsTheGoodFile) {
  test::FullDisk disk;
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const fs::path out = disk.dir() / "out.json";
  std::ofstream(out) << "good";
  const std::string err = error_of([&] { write_text_atomically(out, std::string(100000, 'j')); });
  EXPECT_NE(err.find("No space left on device"), std::string::npos) << err;
  EXPECT_EQ(slurp(out), "good");
}

// The PNG bytes written through our checked path are a PNG OIIO reads back.
TEST(FullDisk, PngWrittenInMemoryReadsBack) {
  const fs::path out = fs::temp_directory_path() / ("rayaudit-png-" + std::to_string(::getpid()) + ".png");
  Image img(3, 2);
  img.at(2, 1)[0] = 1.0f;
  img.at(0, 0)[1] = 0.5f;
  write_image(out, img, {8, false});
  const Image back = read_image(out);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  EXPECT_EQ(back.at(2, 1)[0], 1.0f);
  EXPECT_EQ(back.at(0, 0)[1], 128.0f / 255.0f);
  fs::remove(out);
}

// A name near NAME_MAX (255) still has a temporary that fits. (The name
// holds the process id: suites running at once would share the file.)
TEST(AtomicFile, OutputNameNear255CharactersIsWritten) {
  const fs::path dir = fs::temp_directory_path();
  const std::string pid = std::to_string(::getpid());
  const fs::path out = dir / (pid + std::string(250 - pid.size(), 'n') + ".txt");
  ASSERT_EQ(out.filename().string().size(), 254u);
  write_text_atomically(out, "ok");
  EXPECT_EQ(slurp(out), "ok");
  fs::remove(out);
}

TEST(InputFile, DirectoryFifoDeviceAndLoopAreNamed) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-input-" + std::to_string(::getpid()));
  fs::create_directories(d);
  EXPECT_EQ(input_file_problem(d), "is a directory, not a file");
  ASSERT_EQ(::mkfifo((d / "fifo").c_str(), 0600), 0);
  EXPECT_EQ(input_file_problem(d / "fifo"), "is a FIFO, not a file");
  EXPECT_EQ(input_file_problem("/dev/zero"), "is a device, not a file");
  EXPECT_EQ(input_file_problem(d / "absent"), "no such file");
  fs::create_symlink(d / "loop", d / "loop");
  EXPECT_NE(input_file_problem(d / "loop").find("Too many levels of symbolic links"), std::string::npos);
  std::ofstream(d / "file") << "x";
  EXPECT_EQ(input_file_problem(d / "file"), "");
  fs::remove_all(d);
}

// A FIFO given as an image is refused at once rather than read forever.
TEST(ImageHeader, FifoIsRefusedWithoutBlocking) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-fifo-" + std::to_string(::getpid()));
  fs::create_directories(d);
  ASSERT_EQ(::mkfifo((d / "t.png").c_str(), 0600), 0);
  const std::string err = error_of([&] { read_image(d / "t.png"); });
  EXPECT_EQ(err, (d / "t.png").string() + ": is a FIFO, not a file");
  fs::remove_all(d);
}

TEST(JsonInput, DuplicateKeyIsRefusedAtItsLine) {
  const std::string err = error_of([] { parse_json_text("{\"a\": 1,\n \"b\": {\"c\": 1,\n \"c\": 2}}", "f.json"); });
  EXPECT_EQ(err, "f.json:3: key \"c\" given twice in one object");
  // The same key in two objects is fine.
  EXPECT_EQ(parse_json_text("[{\"a\": 1}, {\"a\": 2}]", "f.json").size(), 2u);
}

TEST(JsonInput, OverflowIsReportedWhereTheNumberIs) {
  // The text "1e400" appears first in a key on line 1; the number is on line 3.
  const std::string err = error_of([] { parse_json_text("{\"1e400\": 0,\n \"x\": 1,\n \"y\": 1e400}", "f.json"); });
  EXPECT_EQ(err, "f.json:3: number 1e400 overflows a double");
}

TEST(JsonInput, LibraryPrefixesAreRemoved) {
  const std::string err = error_of([] { parse_json_text("{\n\"a\" 1}", "f.json"); });
  EXPECT_EQ(err.rfind("f.json:2: invalid JSON: syntax error", 0), 0u) << err;
  EXPECT_EQ(err.find("[json.exception"), std::string::npos) << err;
}

}  // namespace
