// velocity.npy (io/npy.hpp): the final fluid velocity as a NumPy array.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.hpp"
#include "io/npy.hpp"

using namespace ibrod;

TEST(VelocityNpy, RoundTripsInAngstromPerNanosecond) {
  const int n = 4;
  std::vector<double> u(3 * 64);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = 1e9 * (double(i) - 20.5);  // Å/s
  const auto path = std::filesystem::temp_directory_path() / "ibrod_test_velocity.npy";
  io::write_velocity_npy(path, n, u.data(), u.data() + 64, u.data() + 128);
  int got_n = 0;
  const auto v = io::read_velocity_npy(path, got_n);
  EXPECT_EQ(got_n, n);
  ASSERT_EQ(v.size(), u.size());
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_DOUBLE_EQ(v[i], double(i) - 20.5);
  // the data start at a multiple of 64 bytes (NPY 1.0 alignment)
  EXPECT_EQ(std::filesystem::file_size(path) % 64, (u.size() * 8) % 64);
  std::filesystem::remove(path);
}
