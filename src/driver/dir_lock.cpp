#include "driver/dir_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
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
  // never through a link: a symbolic link named ibrod.lock would make ibrod write its PID into
  // whatever file it points to
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
  if (fd_ < 0 && errno == ELOOP)
    throw ConfigError("output: the lock file " + path.string() +
                      " is a symbolic link; ibrod neither follows it nor writes through it: "
                      "remove it (ibrod creates its own lock file there)");
  if (fd_ < 0)
    throw RunError("output: cannot create the lock file " + path.string() + ": " +
                   std::strerror(errno));
  // only a file ibrod owns is truncated: a regular file with no other name, empty or holding a PID
  struct stat st {};
  std::string not_ours;
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode))
    not_ours = "is not a regular file";
  else if (st.st_nlink != 1)
    not_ours = "has other names (hard links)";
  else if (st.st_size > 0 && (st.st_size > 24 || !read_pid(fd_)))
    not_ours = "holds something other than the PID of an ibrod process";
  if (!not_ours.empty()) {
    ::close(fd_);
    fd_ = -1;
    throw ConfigError("output: the lock file " + path.string() + " " + not_ours +
                      "; it is not ibrod's lock, and ibrod does not overwrite it: move it away "
                      "(ibrod creates its own lock file there)");
  }
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
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
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
