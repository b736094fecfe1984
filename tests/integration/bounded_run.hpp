#pragma once
// Running the real binary with a time limit (a hang is killed and reported, not waited for) and
// an optional address-space limit (RLIMIT_AS: a machine with less memory, as the child sees it).
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

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
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    const int null = ::open("/dev/null", O_RDONLY);
    ::dup2(null, 0);
    ::setenv("OMP_WAIT_POLICY", "passive", 0);
    if (as_limit > 0) {
      rlimit r{rlim_t(as_limit), rlim_t(as_limit)};
      ::setrlimit(RLIMIT_AS, &r);
    }
    std::vector<char*> argv;
    std::string bin = IBROD_BINARY;
    argv.push_back(bin.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(bin.c_str(), argv.data());
    ::_exit(127);
  }
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
