// Peskin's 4-point kernel and the checks shared by Coupler and PlaneCoupler (ib/kernel.hpp).
#include "ib/kernel.hpp"

#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace ibrod::ib {

double phi4(double r) {
  // MODEL (2.14). The radicands are 2 − (2|r| − 1)² and 2 − (2|r| − 3)², both in [1, 2] on their
  // branches, so no clamping is needed.
  const double a = std::abs(r);
  if (a <= 1.0) return (3.0 - 2.0 * a + std::sqrt(1.0 + 4.0 * a - 4.0 * a * a)) * 0.125;
  if (a < 2.0) return (5.0 - 2.0 * a - std::sqrt(-7.0 + 12.0 * a - 4.0 * a * a)) * 0.125;
  return 0.0;
}

double delta(const Vec3& x, double c) {
  // MODEL (2.14), Å⁻³
  return phi4(x[0] / c) * phi4(x[1] / c) * phi4(x[2] / c) / (c * c * c);
}

namespace detail {

void check_positions(std::span<const Vec3> X, double h) {
  const double limit = kMaxGridCoordinate * h;
  for (std::size_t k = 0; k < X.size(); ++k) {
    // written so that NaN fails too
    if (!(std::abs(X[k][0]) <= limit && std::abs(X[k][1]) <= limit && std::abs(X[k][2]) <= limit)) {
      throw RunError("ib::Coupler: point " + std::to_string(k) +
                     " has a non-finite or out-of-range position (" + std::to_string(X[k][0]) +
                     ", " + std::to_string(X[k][1]) + ", " + std::to_string(X[k][2]) + ") Å");
    }
  }
}

void check_size(const char* what, std::size_t got, std::size_t want) {
  if (got != want) {
    throw std::invalid_argument(std::string("ib::Coupler: ") + what + " has " +
                                std::to_string(got) + " entries, positions have " +
                                std::to_string(want));
  }
}

}  // namespace detail

}  // namespace ibrod::ib
