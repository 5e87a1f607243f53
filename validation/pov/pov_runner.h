// Runs POV-Ray 3.7 on a scene and returns its image: exports the scene
// (pov_export.h) into a private working directory under /tmp, which Debian's
// /etc/povray/3.7/povray.conf lets POV read and write (and nothing else is
// there), with our own ini so the system one (display on, 800 px) does not
// apply. One thread (+WT1): POV's shadow cache makes a pixel depend on the
// one rendered before it, so the render order must be fixed.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <rayaudit/image.h>
#include <rayaudit/scene/scene.h>

namespace ra {

struct PovRunOptions {
  int bits = 8;                 // Bits_Per_Color: 8 or 16
  bool keep_dir = false;        // keep the working directory (its path is in PovRun::dir)
  bool keep_on_failure = true;  // keep it when POV-Ray fails, to look at
};

struct PovRun {
  Image image;
  std::filesystem::path dir;  // the working directory if kept, else empty
  std::string log;            // POV-Ray's stderr
};

// A finished child process: its exit code (-1 when it did not exit
// normally) and the wall and CPU (user + system) seconds it took.
struct ProcessRun {
  int code = -1;
  double wall_s = 0, cpu_s = 0;
};

// Runs argv (argv[0] a path) in `dir`, stdin from /dev/null, stdout and
// stderr to files. Used for POV-Ray here and by the benchmark's POV-Ray peer.
ProcessRun run_process(const std::filesystem::path& dir, const std::vector<std::string>& argv,
                       const std::filesystem::path& out, const std::filesystem::path& err);

// The povray program: $RAYAUDIT_POVRAY, else `povray` on the PATH. Throws
// InputError saying how to install it when there is none.
std::filesystem::path find_povray();

// The ini we render with (Antialias off, File_Gamma 1.0, one thread...).
std::string pov_ini(int bits);

// Renders the scene at its width x height with POV-Ray. Throws InputError
// when POV-Ray is missing or the scene is not expressible, CheckFailed (with
// POV's stderr, and the working directory kept for a look) when POV fails.
PovRun render_with_povray(const Scene& scene, const PovRunOptions& options = {});

// The same for SDL already written (render_with_povray exports, then calls
// this): the images are copied in under their generated names.
struct PovExport;
PovRun run_povray(const PovExport& sdl, int width, int height, const PovRunOptions& options = {});

}  // namespace ra
