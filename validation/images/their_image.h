// A user's renderer's image of one of our scenes, read to be judged against
// POV-Ray's render (`rayaudit compare SCENE --image THEIRS.png`) or a
// golden (`rayaudit golden check --image THEIRS.png SCENE`). The comparison
// is pixel for pixel at the bit depth of the reference, so an image that
// cannot be compared so is refused before any render, naming the file:
// another format than PNG, another size or bit depth than the reference,
// grey or palette pixels, transparent pixels, or values tagged as other
// than linear (an sRGB or ICC chunk, a gAMA other than 1.0): our renders,
// POV-Ray's (File_Gamma=1.0) and the goldens all store linear values, so a
// gamma-encoded image would differ everywhere for a reason that is no
// renderer's error. An untagged PNG is taken as stored.
#pragma once
#include <filesystem>
#include <string>

#include <rayaudit/image.h>

namespace ra {

struct ImageReference {
  int width = 0, height = 0;
  int bits = 8;        // 8 or 16
  std::string what;    // names the reference in messages: "the scene's render", "golden/a.png"
  std::string remedy;  // said after a size mismatch: how to get an image of the right size
};

// The PNG's pixels as linear RGB (values v / 255 or v / 65535), after the
// checks above; throws InputError "FILE: what is wrong" on any of them.
Image read_their_image(const std::filesystem::path& file, const ImageReference& want);

}  // namespace ra
