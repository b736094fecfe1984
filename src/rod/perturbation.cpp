#include "rod/perturbation.hpp"

#include <algorithm>
#include <random>

namespace ibrod::rod {

std::vector<double> draw_perturbation(const RandomPerturbation& r) {
  std::vector<double> eps;
  if (r.modes <= 0) return eps;
  std::mt19937_64 engine(r.seed);
  eps.reserve(std::size_t(r.modes));
  for (int m = 1; m <= r.modes; ++m) {
    // u uniform on [0, 1) with 53 random bits; ε = A (2u − 1) uniform on [−A, A)
    const double u = double(engine() >> 11) * 0x1.0p-53;
    eps.push_back(r.amplitude * (2.0 * u - 1.0));
  }
  return eps;
}

std::vector<double> combined_perturbation(const std::vector<double>& deterministic,
                                          const RandomPerturbation& r) {
  const std::vector<double> drawn = draw_perturbation(r);
  std::vector<double> eps(std::max(deterministic.size(), drawn.size()), 0.0);
  for (std::size_t m = 0; m < deterministic.size(); ++m) eps[m] += deterministic[m];
  for (std::size_t m = 0; m < drawn.size(); ++m) eps[m] += drawn[m];
  return eps;
}

}  // namespace ibrod::rod
