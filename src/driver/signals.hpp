#pragma once
// SIGINT/SIGTERM for the processes that must stop cleanly, one guard for `ibrod run` and
// `ibrod sweep`: while a SignalGuard lives, the signals set a flag that the owner reads at a safe
// point (the run after each step, the sweep after each wait) instead of killing the process; the
// previous handlers come back when it dies. SIGXFSZ is ignored for the rest of the process, so
// that a file-size limit is a write error with a message, not a kill (HDF5 may still write while
// it shuts down).
#include <csignal>

namespace ibrod::driver {

class SignalGuard {
 public:
  enum class Mode {
    /// a run: system calls restart, and a second signal gets the default action (every file is
    /// consistent at any instant: atomic renames, rows flushed one by one)
    run,
    /// a sweep: a signal interrupts waitpid (EINTR), so that it can pass it on to its runs
    sweep,
  };
  /// catch_stop_signals = false: SIGINT/SIGTERM keep their handlers (pending() stays 0).
  SignalGuard(bool catch_stop_signals, Mode mode);
  ~SignalGuard();
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

  /// The signal received since construction (SIGINT or SIGTERM), 0 if none.
  int pending() const;

 private:
  bool on_;
  struct sigaction old_int_ {
  }, old_term_{};
};

/// "SIGINT", "SIGTERM" or "a signal".
const char* signal_name(int s);

}  // namespace ibrod::driver
