#include "fluid/spectral.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace ibrod::fluid::detail {

void check_fluid_args(const char* who, const GridSpec& grid, const FluidParams& params,
                      int threads) {
  const std::string w(who);
  if (grid.n < 4 || grid.n % 2 != 0)
    throw std::invalid_argument(w + ": grid n must be even and >= 4, got " +
                                std::to_string(grid.n));
  if (!(grid.L > 0.0)) throw std::invalid_argument(w + ": box edge L must be > 0");
  if (!(params.density > 0.0)) throw std::invalid_argument(w + ": density must be > 0");
  if (!(params.dt > 0.0)) throw std::invalid_argument(w + ": dt must be > 0");
  if (!(params.viscosity >= 0.0)) throw std::invalid_argument(w + ": viscosity must be >= 0");
  if (threads < 0) throw std::invalid_argument(w + ": threads must be >= 0");
  if (!(params.thermal_kT >= 0.0) || !std::isfinite(params.thermal_kT))
    throw std::invalid_argument(w + ": thermal_kT must be finite and >= 0");
}

void make_spectral_symbols(int n, double h, std::vector<double>& grad, std::vector<double>& lap) {
  grad.assign(n, 0.0);
  lap.assign(n, 0.0);
  for (int k = 0; k <= n / 2; ++k) {
    // exact zeros at k = 0, n/2 and exact oddness sin(2π(n−k)/n) = −sin(2πk/n)
    const double g = (k == 0 || k == n / 2) ? 0.0 : std::sin(2.0 * std::numbers::pi * k / n) / h;
    const double s = std::sin(std::numbers::pi * k / n);
    grad[k] = g;
    lap[k] = 4.0 / (h * h) * s * s;
    if (k > 0 && k < n / 2) {
      grad[n - k] = -g;
      lap[n - k] = lap[k];
    }
  }
}

}  // namespace ibrod::fluid::detail
