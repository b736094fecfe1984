#include "driver/signals.hpp"

namespace ibrod::driver {

namespace {
volatile std::sig_atomic_t g_signal = 0;
void on_stop_signal(int s) { g_signal = s; }
}  // namespace

SignalGuard::SignalGuard(bool catch_stop_signals, Mode mode) : on_(catch_stop_signals) {
  g_signal = 0;
  struct sigaction sa {};
  sigemptyset(&sa.sa_mask);
  sa.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &sa, nullptr);
  if (!on_) return;
  sa.sa_handler = on_stop_signal;
  sa.sa_flags = mode == Mode::run ? SA_RESETHAND | SA_RESTART : 0;
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

SignalGuard::~SignalGuard() {
  if (!on_) return;
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

int SignalGuard::pending() const { return on_ ? int(g_signal) : 0; }

const char* signal_name(int s) {
  return s == SIGINT ? "SIGINT" : s == SIGTERM ? "SIGTERM" : "a signal";
}

}  // namespace ibrod::driver
