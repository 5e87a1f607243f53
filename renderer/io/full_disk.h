// Test fixture: a tiny tmpfs, nearly filled, so that writes fail with ENOSPC
// as on a full disk. Mounting needs root (CI runs as root); tests
// skip with the reason otherwise.
#pragma once
#include <sys/mount.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace ra::test {

class FullDisk {
 public:
  // A 64 KiB tmpfs with all but about `room` bytes taken by a filler file.
  explicit FullDisk(std::size_t room = 4096) {
    dir_ = std::filesystem::temp_directory_path() / ("rayaudit-fulldisk-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    if (::geteuid() != 0) {
      why_ = "mounting a small tmpfs needs root";
      return;
    }
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") != 0) {
      why_ = "mount -t tmpfs failed (no CAP_SYS_ADMIN in this container?)";
      return;
    }
    mounted_ = true;
    std::ofstream(dir_ / "filler", std::ios::binary) << std::string(64 * 1024 - room - 4096, 'x');
  }
  ~FullDisk() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  FullDisk(const FullDisk&) = delete;
  FullDisk& operator=(const FullDisk&) = delete;
  bool ok() const { return mounted_; }
  const std::string& why_not() const { return why_; }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::string why_;
  bool mounted_ = false;
};

}  // namespace ra::test
