#pragma once
// Philox4x32-10, the counter-based random-number generator of Salmon, Moraes, Dror & Shaw,
// "Parallel random numbers: as easy as 1, 2, 3" (SC 2011), written from the published
// description: four 32-bit counter words and two 32-bit key words are mixed by ten rounds of two
// 32×32→64-bit multiplications; the key is bumped by the Weyl constants between rounds. The
// output is a pure function of (counter, key): a stream needs no state but its counter, so a
// draw keyed by (seed, step, index) is the same in any thread, in any order, after any resume.
// Used by the thermal noise of the fluid (docs/thermal.md).
#include <array>
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

/// Six independent random numbers of mean 0 and variance 1 (uniform on (−√3, √3), to within
/// 2⁻²¹) from one Philox output: the four words' top 21 bits and two 22-bit numbers made of their
/// low 11 bits. The thermal noise needs only mean and variance per mode (docs/thermal.md: every
/// velocity is a sum over many modes, Gaussian by the central limit theorem), and no logarithm or
/// sine keeps it cheap.
inline void unit_variance6(const Philox4x32& w, double z[6]) {
  constexpr double kSqrt12 = 3.4641016151377544;
  constexpr double k21 = 0x1p-21, k22 = 0x1p-22;
  z[0] = kSqrt12 * ((double(w[0] >> 11) + 0.5) * k21 - 0.5);
  z[1] = kSqrt12 * ((double(w[1] >> 11) + 0.5) * k21 - 0.5);
  z[2] = kSqrt12 * ((double(w[2] >> 11) + 0.5) * k21 - 0.5);
  z[3] = kSqrt12 * ((double(w[3] >> 11) + 0.5) * k21 - 0.5);
  z[4] = kSqrt12 * ((double((w[0] & 0x7ffu) | ((w[1] & 0x7ffu) << 11)) + 0.5) * k22 - 0.5);
  z[5] = kSqrt12 * ((double((w[2] & 0x7ffu) | ((w[3] & 0x7ffu) << 11)) + 0.5) * k22 - 0.5);
}

}  // namespace ibrod
