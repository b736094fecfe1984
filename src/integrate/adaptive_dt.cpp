#include "integrate/adaptive_dt.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ibrod::integrate {

namespace {
void check(const AdaptiveDtParams& p) {
  if (!(p.dt_max > 0) || !(p.dt_min > 0) || p.dt_min > p.dt_max)
    throw std::invalid_argument("AdaptiveDt: need 0 < dt_min <= dt_max");
  if (!(p.max_displacement > 0) || !(p.max_rotation > 0))
    throw std::invalid_argument("AdaptiveDt: max_displacement and max_rotation must be > 0");
  if (!(p.energy_tolerance >= 0))
    throw std::invalid_argument("AdaptiveDt: energy_tolerance must be >= 0");
  if (!(p.shrink > 0 && p.shrink < 1) || !(p.grow >= 1) || p.grow_after < 1)
    throw std::invalid_argument("AdaptiveDt: need 0 < shrink < 1, grow >= 1, grow_after >= 1");
}
}  // namespace

AdaptiveDt::AdaptiveDt(const AdaptiveDtParams& p) : p_(p), dt_(p.dt_max) { check(p_); }

AdaptiveDt::AdaptiveDt(const AdaptiveDtParams& p, double dt, int accepted_in_a_row)
    : p_(p), dt_(dt), run_(accepted_in_a_row) {
  check(p_);
  if (!(dt > 0)) throw std::invalid_argument("AdaptiveDt: dt must be > 0");
}

bool AdaptiveDt::judge(const StepOutcome& o) {
  const bool at_floor = dt_ <= p_.dt_min;
  const double disp_ratio = o.max_displacement / p_.max_displacement;
  const double rot_ratio = o.max_rotation / p_.max_rotation;
  const double ratio = std::max(disp_ratio, rot_ratio);
  const bool bad =
      !o.finite || !o.converged || !(ratio <= 1.0) || !(o.energy_change <= p_.energy_tolerance);
  if (bad && !(at_floor && o.finite)) {
    // shrink by `shrink`, or further if the displacement asks for it (it scales with Δt)
    double f = p_.shrink;
    if (std::isfinite(ratio) && ratio > 1.0) f = std::min(f, 0.9 / ratio);
    dt_ = std::max(p_.dt_min, dt_ * f);
    run_ = 0;
    ++rejections_;
    return false;
  }
  ++run_;
  if (run_ >= p_.grow_after && ratio < 0.7) {
    dt_ = std::min(p_.dt_max, dt_ * p_.grow);
    run_ = 0;
  }
  return true;
}

}  // namespace ibrod::integrate
