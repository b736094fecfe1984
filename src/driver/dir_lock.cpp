#include "driver/dir_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "io/run_dir.hpp"

namespace ibrod::driver {

namespace {

// The PID written in an open lock file ("" → none).
std::optional<pid_t> read_pid(int fd) {
  char buf[32] = {};
  const ssize_t got = ::pread(fd, buf, sizeof buf - 1, 0);
  if (got <= 0) return std::nullopt;
  char* end = nullptr;
  const long pid = std::strtol(buf, &end, 10);
  if (end == buf || pid <= 0) return std::nullopt;
  return pid_t(pid);
}

}  // namespace

DirLock::DirLock(const std::filesystem::path& dir) {
  const std::filesystem::path path = io::RunDir(dir).lock();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw RunError("output: cannot create the lock file " + path.string() + ": " +
                   std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    const std::optional<pid_t> holder = read_pid(fd_);
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK)
      throw ConfigError("output: " + dir.string() + " is being written by another ibrod process" +
                        (holder ? " (PID " + std::to_string(*holder) + ")" : std::string()) +
                        "; one writer per run directory: wait for it to finish, or stop it "
                        "(then continue with --resume " +
                        dir.string() + ")");
    throw RunError("output: cannot lock " + path.string() + ": " + std::strerror(err));
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
    // the lock is held all the same; only the holder's name in a refusal would be missing
  }
}

DirLock::~DirLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

std::optional<pid_t> dir_lock_holder(const std::filesystem::path& dir) {
  const std::filesystem::path path = io::RunDir(dir).lock();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::optional<pid_t> holder;
  if (::flock(fd, LOCK_SH | LOCK_NB) != 0) {
    holder = read_pid(fd);
    if (!holder) holder = pid_t(0);  // held, PID unknown
  } else {
    ::flock(fd, LOCK_UN);
  }
  ::close(fd);
  return holder;
}

}  // namespace ibrod::driver
