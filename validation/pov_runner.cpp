#include "pov_runner.h"

#include <fcntl.h>
#include <cstring>
#include <signal.h>
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


// The child being waited for, and the signal that interrupted the wait: a
// SIGINT/SIGTERM/SIGHUP sent to rayaudit alone (timeout, kill) left POV-Ray
// rendering as an orphan and its working directory in /tmp (HOSTILE2 F30).
// The handler only forwards the signal (kill is async-signal-safe); the
// waiter then throws, so the working directory is removed on the way out.
volatile sig_atomic_t g_child = 0;
volatile sig_atomic_t g_signal = 0;

extern "C" void forward_signal(int sig) {
  g_signal = sig;
  if (g_child > 0) ::kill(pid_t(g_child), sig);
}

// Installs forward_signal for the wait; restores the previous handlers.
struct ForwardSignals {
  static constexpr int kSignals[3] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction old[3];
  explicit ForwardSignals(pid_t child) {
    g_signal = 0;
    g_child = child;
    struct sigaction sa {};
    sa.sa_handler = forward_signal;
    sigemptyset(&sa.sa_mask);
    for (int i = 0; i < 3; ++i) sigaction(kSignals[i], &sa, &old[i]);
  }
  ~ForwardSignals() {
    for (int i = 0; i < 3; ++i) sigaction(kSignals[i], &old[i], nullptr);
    g_child = 0;
  }
};

}  // namespace

ProcessRun run_process(const fs::path& dir, const std::vector<std::string>& argv, const fs::path& out,
                       const fs::path& err) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
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
  int status = 0;
  rusage ru{};
  ProcessRun run;
  {
    const ForwardSignals forward(pid);
    if (g_signal) ::kill(pid, g_signal);  // arrived between fork and here
    while (wait4(pid, &status, 0, &ru) < 0)
      if (errno != EINTR) return run;
  }
  if (g_signal)
    throw InputError(std::string(argv[0]) + ": interrupted by signal " + std::to_string(int(g_signal)) +
                     " (" + strsignal(int(g_signal)) + "); the child was stopped and its files removed");
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  run.cpu_s = double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
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
         std::to_string(bits) +
         "\nFile_Gamma=1.0\nQuality=9\nWork_Threads=1\nOutput_Alpha=Off\nOutput_To_File=On\n";
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
