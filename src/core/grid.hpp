#pragma once
// The periodic Cartesian grid shared by the fluid and the immersed-boundary coupling.
// Points x_ijk = (i, j, k) h, h = L / n, i, j, k in [0, n). Arrays are row-major with z fastest:
// index(i, j, k) = (i n + j) n + k, which is FFTW's layout for an n x n x n real array.
#include <cstddef>

namespace ibrod {

struct GridSpec {
  int n = 64;        ///< points per edge
  double L = 725.0;  ///< box edge, Å

  double h() const { return L / n; }  ///< grid spacing, Å
  std::size_t size() const { return std::size_t(n) * n * n; }
  std::size_t index(int i, int j, int k) const { return (std::size_t(i) * n + j) * n + k; }
  /// periodic wrap of an integer index into [0, n)
  int wrap(int i) const {
    int r = i % n;
    return r < 0 ? r + n : r;
  }
};

}  // namespace ibrod
