#pragma once
// One writer per run directory: an advisory lock (flock) on DIR/ibrod.lock, held for the life of
// the process that writes the directory (`ibrod run`, `--resume`) and released by the kernel when
// that process ends, however it ends (exit, crash, kill -9). The lock file holds the holder's PID,
// so that a second writer is refused with a message that names it; a lock file left by a process
// that has died is no lock (flock is not held), and is simply taken over. The lock file is opened
// without following links, and only a file that is ibrod's (a regular file with one name, empty
// or holding a PID) is ever truncated: anything else there is refused (ConfigError), not written.
#include <sys/types.h>
#include <filesystem>
#include <optional>
#include <string>

namespace ibrod::driver {

class DirLock {
 public:
  /// Takes the lock of the run directory `dir` (which must exist), without waiting. Throws
  /// ConfigError naming the holder's PID if another process holds it, or if DIR/ibrod.lock is a
  /// link or a file not ibrod's; RunError if the lock file cannot be created.
  explicit DirLock(const std::filesystem::path& dir);
  ~DirLock();
  DirLock(const DirLock&) = delete;
  DirLock& operator=(const DirLock&) = delete;

 private:
  int fd_ = -1;
};

/// The PID of the process that holds the lock of run directory `dir`, if one does (a lock file
/// without a live holder, or none, is no lock). Does not take the lock.
std::optional<pid_t> dir_lock_holder(const std::filesystem::path& dir);

}  // namespace ibrod::driver
