// Writes a scene as POV-Ray 3.7 SDL that renders the same image as our
// tracer (../shared/POVRAY.md gives every rule followed here). It reads the
// one scene model (renderer/scene/scene.h): there is no second description.
//
// SDL can read and write files (#fopen, #write, #include, #read), so no text
// from a scene ever reaches the SDL: image files are referred to by names we
// generate (`<prefix>tex<N>.png`), the scene's own file name appears only in
// a comment made of safe characters, and every string written goes through
// pov_string_literal(), which refuses anything outside a small safe set.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <rayaudit/scene/scene.h>

namespace ra {

// An image the SDL refers to: copy `source` to `name` beside the .pov (with
// copy_pov_image, which also drops alpha: POV would take it as transparency).
struct PovImageFile {
  std::filesystem::path source;
  std::string name;
};

struct PovExport {
  std::string sdl;
  std::vector<PovImageFile> images;
};

// Why POV-Ray cannot express the scene (the documents' own bump variants),
// or nullopt when it can.
std::optional<std::string> pov_inexpressible(const Scene& scene);

// The SDL for `scene` at its width/height. Image names are `prefix` +
// "tex<N>.png"; prefix must match [A-Za-z0-9_.-]*. Throws InputError when
// the scene is not expressible (pov_inexpressible) or a number is not finite.
PovExport export_pov(const Scene& scene, const std::string& image_prefix = "");

// `"text"` as a POV string literal. Only [A-Za-z0-9 _.,+=@%/-] pass, so the
// result can neither end the string early nor start an escape; anything else
// is refused with InputError. (POV 3.7 does decode \" and \\ in strings, but
// refusing is simpler to trust than escaping.)
std::string pov_string_literal(std::string_view text);

// Copies an image for POV's image_map / bump_map as an RGB PNG without
// alpha, keeping 8-bit sources 8-bit and writing anything else as 16-bit.
void copy_pov_image(const std::filesystem::path& source, const std::filesystem::path& dest);

// POV's `angle` is the horizontal field of view; ours is vertical.
double horizontal_fov_degrees(double vfov_degrees, double aspect);

}  // namespace ra
