#include "pov_runner.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <fstream>
#include <sstream>
#include <vector>

#include "io/atomic_file.h"
#include "errors.h"
#include "pov_export.h"

namespace ra {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Removes the working directory unless asked to keep it.
struct WorkDir {
  fs::path path;
  bool keep = false;
  ~WorkDir() {
    std::error_code ec;
    if (!keep && !path.empty()) fs::remove_all(path, ec);
  }
};

// Ctrl-C, a kill or a hang-up while POV-Ray runs (POV-Ray
// went on rendering as an orphan and its working directory, 64-160 MB, was
// left in /tmp). While a Interruptible lives, the signal is noted and the
// child killed at once (only async-signal-safe calls in the handler); when
// it ends, the working directory is removed and the signal raised again
// with its default action, so the exit status still says what happened.
volatile sig_atomic_t g_signal = 0;
volatile pid_t g_child = 0;

void on_signal(int sig) {
  g_signal = sig;
  if (g_child > 0) kill(g_child, SIGKILL);
}

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};

class Interruptible {
 public:
  explicit Interruptible(WorkDir& dir) : dir_(dir) {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // no SA_RESTART: wait4 returns EINTR and looks again
    for (int i = 0; i < 3; ++i) sigaction(kSignals[i], &sa, &old_[i]);
  }
  ~Interruptible() {
    for (int i = 0; i < 3; ++i) sigaction(kSignals[i], &old_[i], nullptr);
    if (const int sig = g_signal) {
      std::error_code ec;
      fs::remove_all(dir_.path, ec);
      signal(sig, SIG_DFL);
      raise(sig);
    }
  }
  Interruptible(const Interruptible&) = delete;
  Interruptible& operator=(const Interruptible&) = delete;

 private:
  WorkDir& dir_;
  struct sigaction old_[3];
};

}  // namespace

ProcessRun run_process(const fs::path& dir, const std::vector<std::string>& argv, const fs::path& out,
                       const fs::path& err) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    // The child dies with us, whatever ends us (even SIGKILL): never an
    // orphan POV-Ray rendering for hours.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(126);
    const int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int in = open("/dev/null", O_RDONLY);
    if (o < 0 || e < 0 || in < 0 || chdir(dir.c_str()) != 0) _exit(126);
    dup2(in, 0);
    dup2(o, 1);
    dup2(e, 2);
    execv(args[0], args.data());
    _exit(127);
  }
  g_child = pid;
  if (g_signal) kill(pid, SIGKILL);  // a signal came between fork and here
  int status = 0;
  rusage ru{};
  ProcessRun run;
  while (wait4(pid, &status, 0, &ru) < 0)
    if (errno != EINTR) {
      g_child = 0;
      return run;
    }
  g_child = 0;
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  run.cpu_s =
      double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

fs::path find_povray() {
  if (const char* env = std::getenv("RAYAUDIT_POVRAY"); env && *env) {
    if (access(env, X_OK) != 0)
      throw InputError(std::string("RAYAUDIT_POVRAY=") + env + " is not an executable program");
    return env;
  }
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    if (d.empty()) continue;
    const fs::path p = fs::path(d) / "povray";
    if (access(p.c_str(), X_OK) == 0) return p;
  }
  throw InputError(
      "POV-Ray is not installed (no `povray` on the PATH): install the Debian package 'povray' "
      "(ci/install-deps.sh does), or set RAYAUDIT_POVRAY to the program");
}

std::string pov_ini(int bits) {
  return "; rayaudit's own settings: one ray per pixel, linear output, fixed render order.\n"
         "Antialias=Off\nDisplay=Off\nPause_When_Done=Off\nVerbose=Off\nOutput_File_Type=N\n"
         "Bits_Per_Color=" +
         std::to_string(bits) + "\nFile_Gamma=1.0\nQuality=9\nWork_Threads=1\nOutput_Alpha=Off\nOutput_To_File=On\n";
}

PovRun render_with_povray(const Scene& scene, const PovRunOptions& options) {
  find_povray();  // say that POV-Ray is missing before anything else
  return run_povray(export_pov(scene), scene.width, scene.height, options);
}

PovRun run_povray(const PovExport& ex, int width, int height, const PovRunOptions& options) {
  if (options.bits != 8 && options.bits != 16) throw InputError("POV-Ray bits per colour must be 8 or 16");
  const fs::path povray = find_povray();

  // A private directory: mkdtemp creates it mode 0700 under a fresh name.
  std::string tmpl = "/tmp/rayaudit-pov-XXXXXX";
  if (!mkdtemp(tmpl.data())) throw InputError("cannot create a working directory under /tmp");
  WorkDir work{tmpl, options.keep_dir};
  const Interruptible interruptible(work);  // declared after work: ends first
  write_text_atomically(work.path / "scene.pov", ex.sdl);
  write_text_atomically(work.path / "rayaudit.ini", pov_ini(options.bits));
  for (const auto& img : ex.images) copy_pov_image(img.source, work.path / img.name);

  const std::vector<std::string> argv = {povray.string(),
                                         "rayaudit.ini",
                                         "+Iscene.pov",
                                         "+Oout.png",
                                         "+W" + std::to_string(width),
                                         "+H" + std::to_string(height),
                                         "+WT1"};
  const int code = run_process(work.path, argv, work.path / "povray.out", work.path / "povray.err").code;
  PovRun run;
  run.log = read_text(work.path / "povray.err");
  if (code != 0 || !fs::exists(work.path / "out.png")) {
    work.keep = options.keep_on_failure;
    throw CheckFailed("POV-Ray failed (" + (code < 0 ? std::string("killed") : "exit " + std::to_string(code)) +
                      ") on the exported scene" +
                      (work.keep ? "; its files are kept in " + work.path.string() : std::string()) +
                      "\n--- POV-Ray's stderr ---\n" + run.log);
  }
  run.image = read_image(work.path / "out.png");
  if (options.keep_dir) run.dir = work.path;
  return run;
}

}  // namespace ra
