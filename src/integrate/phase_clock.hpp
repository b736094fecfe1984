#pragma once
// The phase clock of the serial step (StepPhaseTimes; `ibrod bench`): the System's force terms
// and the explicit Stepper's fluid half mark their phases on it. Internal to src/integrate.
#include <chrono>

#include "integrate/system.hpp"

namespace ibrod::integrate {

// Adds the time since the previous mark to phase k (nothing without a StepPhaseTimes).
class PhaseClock {
 public:
  explicit PhaseClock(StepPhaseTimes* t) : t_(t) {
    if (t_) last_ = std::chrono::steady_clock::now();
  }
  void mark(int k) {
    if (!t_) return;
    const auto now = std::chrono::steady_clock::now();
    t_->ms[k] += std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
  }

 private:
  StepPhaseTimes* t_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace ibrod::integrate
