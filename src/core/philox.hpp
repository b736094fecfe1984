#pragma once
// Philox4x32-10, the counter-based random-number generator of Salmon, Moraes, Dror & Shaw,
// "Parallel random numbers: as easy as 1, 2, 3" (SC 2011), written from the published
// description: four 32-bit counter words and two 32-bit key words are mixed by ten rounds of two
// 32×32→64-bit multiplications; the key is bumped by the Weyl constants between rounds. The
// output is a pure function of (counter, key): a stream needs no state but its counter, so a
// draw keyed by (seed, step, index) is the same in any thread, in any order, after any resume.
// Used by the thermal noise of the fluid (docs/thermal.md).
#include <array>
#include <cmath>
#include <cstdint>

namespace ibrod {

using Philox4x32 = std::array<std::uint32_t, 4>;

/// The ten-round Philox4x32 bijection of `ctr` under the key (k0, k1).
inline Philox4x32 philox4x32_10(Philox4x32 ctr, std::uint32_t k0, std::uint32_t k1) {
  constexpr std::uint64_t kM0 = 0xD2511F53u, kM1 = 0xCD9E8D57u;  // multipliers
  constexpr std::uint32_t kW0 = 0x9E3779B9u, kW1 = 0xBB67AE85u;  // Weyl key increments
  for (int round = 0; round < 10; ++round) {
    if (round > 0) {
      k0 += kW0;
      k1 += kW1;
    }
    const std::uint64_t p0 = kM0 * ctr[0];
    const std::uint64_t p1 = kM1 * ctr[2];
    const std::uint32_t hi0 = std::uint32_t(p0 >> 32), lo0 = std::uint32_t(p0);
    const std::uint32_t hi1 = std::uint32_t(p1 >> 32), lo1 = std::uint32_t(p1);
    ctr = {hi1 ^ ctr[1] ^ k0, lo1, hi0 ^ ctr[3] ^ k1, lo0};
  }
  return ctr;
}

/// A uniform number in (0, 1) from 32 random bits (never 0: safe for a logarithm).
inline double uniform_open01(std::uint32_t x) { return (double(x) + 0.5) * 0x1p-32; }

/// Two independent standard normal numbers from two 32-bit words (Box–Muller).
inline void box_muller(std::uint32_t a, std::uint32_t b, double& z0, double& z1) {
  const double r = std::sqrt(-2.0 * std::log(uniform_open01(a)));
  const double t = 6.283185307179586 * uniform_open01(b);
  z0 = r * std::cos(t);
  z1 = r * std::sin(t);
}

}  // namespace ibrod
