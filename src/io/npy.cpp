#include "io/npy.hpp"

#include <bit>
#include <cstring>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "core/units.hpp"
#include "io/atomic_file.hpp"

namespace ibrod::io {

namespace {

static_assert(std::endian::native == std::endian::little, "the .npy header says '<f8'");

// NPY format 1.0: magic, version, header length (uint16 LE), then a Python dict literal padded
// with spaces and ended by '\n' so that the data starts at a multiple of 64 bytes.
std::string npy_header(int n) {
  const std::string dims = std::to_string(n);
  std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (3, " + dims + ", " + dims +
                     ", " + dims + "), }";
  const std::size_t preamble = 10;
  std::size_t total = preamble + dict.size() + 1;
  total = (total + 63) / 64 * 64;
  dict.resize(total - preamble - 1, ' ');
  dict += '\n';
  std::string h = "\x93NUMPY";
  h += char(1);
  h += char(0);
  const auto len = std::uint16_t(dict.size());
  h += char(len & 0xff);
  h += char(len >> 8);
  return h + dict;
}

}  // namespace

void write_velocity_npy(const std::filesystem::path& path, int n, const double* ux,
                        const double* uy, const double* uz) {
  AtomicFile f(path);
  f.write(npy_header(n));
  const std::size_t n3 = std::size_t(n) * n * n;
  std::vector<double> buf(std::size_t(n) * n);  // one x-plane at a time
  const double to_A_per_ns = units::ns;         // Å/s → Å/ns
  for (const double* u : {ux, uy, uz}) {
    for (std::size_t o = 0; o < n3; o += buf.size()) {
      for (std::size_t q = 0; q < buf.size(); ++q) buf[q] = u[o + q] * to_A_per_ns;
      f.write(buf.data(), buf.size() * sizeof(double));
    }
  }
  f.commit(false);
}

}  // namespace ibrod::io
