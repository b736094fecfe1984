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
  if (!(p.error_tolerance >= 0) || !(p.grow_max >= 1))
    throw std::invalid_argument("AdaptiveDt: need error_tolerance >= 0 and grow_max >= 1");
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
  const bool control = p_.error_tolerance > 0;
  // error control: the factor the estimate asks for (err ∝ Δt²)
  double ef = p_.grow_max;
  if (control && o.error > 0)
    ef = std::clamp(0.9 * std::sqrt(p_.error_tolerance / o.error), 0.2, p_.grow_max);
  const bool bad = !o.finite || !o.converged || !(ratio <= 1.0) ||
                   !(o.energy_change <= p_.energy_tolerance) ||
                   (control && !(o.error <= p_.error_tolerance));
  if (bad && !(at_floor && o.finite)) {
    // shrink by `shrink`, or further if the displacement or the error asks for it
    const bool error_only =
        o.finite && o.converged && ratio <= 1.0 && o.energy_change <= p_.energy_tolerance;
    double f = error_only ? std::min(ef, 0.9) : p_.shrink;
    if (std::isfinite(ratio) && ratio > 1.0) f = std::min(f, 0.9 / ratio);
    if (control && o.error > p_.error_tolerance) f = std::min(f, ef);
    const double base = o.dt > 0 && o.dt < dt_ ? o.dt : dt_;
    dt_ = std::max(p_.dt_min, base * f);
    run_ = 0;
    ++rejections_;
    return false;
  }
  ++run_;
  if (control) {
    // Δt follows the error estimate, no faster than the displacement allows
    double f = ef;
    if (std::isfinite(ratio) && ratio > 0) f = std::min(f, std::max(1.0, 0.9 / ratio));
    if (run_ < 2) f = std::min(f, 1.0);  // no growth right after a rejection
    // a step the caller shortened (an output time, t_end) does not hold Δt back unless its own
    // error asks for less
    const bool capped = o.dt > 0 && o.dt < dt_;
    if (!capped)
      dt_ = dt_ * f;
    else if (f < 1)
      dt_ = std::min(dt_, o.dt * f);
    dt_ = std::clamp(dt_, p_.dt_min, p_.dt_max);
    return true;
  }
  if (run_ >= p_.grow_after && ratio < 0.7) {
    dt_ = std::min(p_.dt_max, dt_ * p_.grow);
    run_ = 0;
  }
  return true;
}

}  // namespace ibrod::integrate
