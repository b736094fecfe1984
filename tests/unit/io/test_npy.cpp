// velocity.npy (io/npy.hpp): the final fluid velocity as a NumPy array.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/npy.hpp"

using namespace ibrod;

namespace {

// The reading side of velocity.npy, as numpy reads it: n and the 3 n³ values (Å/ns).
std::vector<double> read_velocity_npy(const std::filesystem::path& path, int& n) {
  std::ifstream in(path, std::ios::binary);
  char pre[10];
  if (!in.read(pre, 10) || std::memcmp(pre, "\x93NUMPY", 6) != 0)
    throw std::runtime_error("npy: " + path.string() + " is not a .npy file");
  const std::size_t hlen = std::size_t(std::uint8_t(pre[8])) | std::size_t(std::uint8_t(pre[9]))
                                                                   << 8;
  std::string dict(hlen, '\0');
  in.read(dict.data(), std::streamsize(hlen));
  const auto s = dict.find("'shape': (3, ");
  if (!in || dict.find("'<f8'") == std::string::npos || s == std::string::npos)
    throw std::runtime_error("npy: " + path.string() + " is not a (3, n, n, n) float64 array");
  n = std::stoi(dict.substr(s + 13));
  std::vector<double> v(3 * std::size_t(n) * n * n);
  if (!in.read(reinterpret_cast<char*>(v.data()), std::streamsize(v.size() * sizeof(double))))
    throw std::runtime_error("npy: " + path.string() + " is truncated");
  return v;
}

}  // namespace

TEST(VelocityNpy, RoundTripsInAngstromPerNanosecond) {
  const int n = 4;
  std::vector<double> u(3 * 64);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = 1e9 * (double(i) - 20.5);  // Å/s
  const auto path = std::filesystem::temp_directory_path() / "ibrod_test_velocity.npy";
  io::write_velocity_npy(path, n, u.data(), u.data() + 64, u.data() + 128);
  int got_n = 0;
  const auto v = read_velocity_npy(path, got_n);
  EXPECT_EQ(got_n, n);
  ASSERT_EQ(v.size(), u.size());
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_DOUBLE_EQ(v[i], double(i) - 20.5);
  // the data start at a multiple of 64 bytes (NPY 1.0 alignment)
  EXPECT_EQ(std::filesystem::file_size(path) % 64, (u.size() * 8) % 64);
  std::filesystem::remove(path);
}
