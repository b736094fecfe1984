#pragma once
// Helpers for end-to-end tests of `ibrod run`: start the real binary (as a child process that a
// test can signal or kill), wait for it, read its files.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace ibrod::test {

namespace fs = std::filesystem;

inline fs::path fresh_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("ibrod_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Whether this build runs under AddressSanitizer: it reserves terabytes of shadow memory at
/// start, so a child under an address-space limit (RLIMIT_AS) cannot start at all; the tests that
/// impose one skip it there (the Release build runs them).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif

/// A running `ibrod` with stdout and stderr going to a log file.
struct Child {
  pid_t pid = -1;
  fs::path log;
};

/// Starts IBROD_BINARY with args, stdin from /dev/null. fsize_limit > 0: RLIMIT_FSIZE of the
/// child in bytes (a full disk as the child sees it); as_limit > 0: its RLIMIT_AS (a machine
/// with less memory); niceness > 0: the child's nice value, for a run that a test kills after
/// some rows: on a loaded machine a child at the test's own priority can finish all its rows
/// while the test waits for the CPU, so the kill comes too late (seen once under load 13).
inline Child spawn(const std::vector<std::string>& args, const fs::path& log, long fsize_limit = 0,
                   long as_limit = 0, int niceness = 0) {
  Child c;
  c.log = log;
  c.pid = ::fork();
  if (c.pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    const int null = ::open("/dev/null", O_RDONLY);
    ::dup2(null, 0);
    // Threads that sleep instead of spinning at barriers: on a machine shared with other jobs
    // (a CI runner, parallel ctest) spinning threads slow a 2-thread run down 20-fold. The
    // results do not depend on it.
    ::setenv("OMP_WAIT_POLICY", "passive", 0);
    if (fsize_limit > 0) {
      rlimit r{rlim_t(fsize_limit), rlim_t(fsize_limit)};
      ::setrlimit(RLIMIT_FSIZE, &r);
    }
    if (as_limit > 0) {
      rlimit r{rlim_t(as_limit), rlim_t(as_limit)};
      ::setrlimit(RLIMIT_AS, &r);
    }
    if (niceness > 0) ::setpriority(PRIO_PROCESS, 0, niceness);
    std::vector<char*> argv;
    std::string bin = IBROD_BINARY;
    argv.push_back(bin.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(bin.c_str(), argv.data());
    ::_exit(127);
  }
  return c;
}

struct Exit {
  int code = -1;   ///< exit status, −1 if killed by a signal
  int signal = 0;  ///< the signal that killed it, 0 if it exited
  std::string output;
};

inline Exit wait_for(const Child& c) {
  int st = 0;
  ::waitpid(c.pid, &st, 0);
  Exit e;
  if (WIFEXITED(st)) e.code = WEXITSTATUS(st);
  if (WIFSIGNALED(st)) e.signal = WTERMSIG(st);
  e.output = read_file(c.log);
  return e;
}

/// Runs to completion.
inline Exit run_ibrod(const std::vector<std::string>& args, const fs::path& log,
                      long fsize_limit = 0) {
  return wait_for(spawn(args, log, fsize_limit));
}

/// Complete lines in a file (0 if it does not exist).
inline int lines_in(const fs::path& p) {
  const std::string s = read_file(p);
  return int(std::count(s.begin(), s.end(), '\n'));
}

/// Waits until `file` has at least `lines` lines or the child has exited; true in the first case.
inline bool wait_for_lines(const Child& c, const fs::path& file, int lines,
                           double timeout_s = 120) {
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < timeout_s) {
    if (lines_in(file) >= lines) return true;
    int st = 0;
    if (::waitpid(c.pid, &st, WNOHANG) == c.pid) return false;  // exited (reaped here)
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  return false;
}

}  // namespace ibrod::test
