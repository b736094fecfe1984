#pragma once
// Running the real binary with a time limit (a hang is killed and reported, not waited for) and
// an optional address-space limit (RLIMIT_AS: a machine with less memory, as the child sees it).
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "run_helpers.hpp"

namespace ibrod::test {

struct BoundedExit {
  int code = -1;      ///< exit status, −1 if killed by a signal or timed out
  int signal = 0;     ///< the signal that killed it (not counting our own kill on timeout)
  bool hung = false;  ///< still running after the time limit (then killed)
  std::string output;
};

/// Runs IBROD_BINARY args with stdout + stderr into `log`, stdin from /dev/null; kills it with
/// SIGKILL after timeout_s. as_limit > 0: the child's RLIMIT_AS in bytes.
inline BoundedExit run_bounded(const std::vector<std::string>& args, const fs::path& log,
                               double timeout_s = 20, long as_limit = 0) {
  const pid_t pid = spawn(args, log, 0, as_limit).pid;
  BoundedExit e;
  int st = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (::waitpid(pid, &st, WNOHANG) == 0) {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > timeout_s) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &st, 0);
      e.hung = true;
      e.output = read_file(log);
      return e;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (WIFEXITED(st)) e.code = WEXITSTATUS(st);
  if (WIFSIGNALED(st)) e.signal = WTERMSIG(st);
  e.output = read_file(log);
  return e;
}

}  // namespace ibrod::test
