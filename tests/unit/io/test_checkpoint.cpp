// Checkpoints: an exact round trip, and every kind of damage (truncation, a flipped bit, another
// version, not a checkpoint at all) rejected with a message; a full disk leaves the previous
// checkpoint intact.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/error.hpp"
#include "io/checkpoint.hpp"

using namespace ibrod;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("ibrod_ckpt_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct Fixture {
  io::CheckpointMeta meta;
  rod::RodState rod;
  int grid_n = 6;
  std::vector<double> u;
  Fixture() {
    meta.step = 1234;
    meta.threads = 3;
    meta.config_toml = "[grid]\nn = 6\n";
    meta.initial.link = 2.0000000000000004;
    meta.initial.E_bend_kT = 1.0 / 3.0;
    meta.self_passage_warning = true;
    meta.self_passage_step = 77;
    meta.max_link_drift = 0.125;
    for (int k = 0; k < 5; ++k) {
      rod.X.push_back(Vec3(k + 0.1, std::sqrt(2.0) * k, -1.0 / (k + 1)));
      rod.D.push_back(rotation(Vec3(0.1 * k, 0.2, -0.3)));
    }
    u.resize(3 * std::size_t(grid_n) * grid_n * grid_n);
    for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::sin(double(i)) * 1e7;
  }
  std::array<const double*, 3> velocity() const {
    const std::size_t n3 = std::size_t(grid_n) * grid_n * grid_n;
    return {u.data(), u.data() + n3, u.data() + 2 * n3};
  }
  void write(const fs::path& p) const { io::write_checkpoint(p, meta, rod, grid_n, velocity()); }
};

std::string read_error(const fs::path& p) {
  try {
    io::read_checkpoint(p);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::vector<char> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void put_bytes(const fs::path& p, const std::vector<char>& b) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(b.data(), std::streamsize(b.size()));
}

}  // namespace

TEST(Checkpoint, Crc32OfTheStandardCheckString) {
  // the check value of CRC-32/IEEE (e.g. zlib's crc32)
  EXPECT_EQ(io::crc32("123456789", 9), 0xCBF43926u);
  // continuing a CRC over pieces equals the CRC of the whole
  EXPECT_EQ(io::crc32("6789", 4, io::crc32("12345", 5)), 0xCBF43926u);
}

TEST(Checkpoint, RoundTripIsExact) {
  const fs::path d = scratch("roundtrip");
  const Fixture f;
  f.write(d / "c.bin");
  EXPECT_FALSE(fs::exists(d / "c.bin.tmp"));
  const io::Checkpoint c = io::read_checkpoint(d / "c.bin");
  EXPECT_EQ(c.meta.step, 1234);
  EXPECT_EQ(c.meta.threads, 3);
  EXPECT_EQ(c.meta.config_toml, f.meta.config_toml);
  EXPECT_EQ(c.meta.initial.link, f.meta.initial.link);  // bitwise, through JSON
  EXPECT_EQ(c.meta.initial.E_bend_kT, f.meta.initial.E_bend_kT);
  EXPECT_TRUE(c.meta.self_passage_warning);
  EXPECT_EQ(c.meta.self_passage_step, 77);
  EXPECT_EQ(c.meta.max_link_drift, 0.125);
  ASSERT_EQ(c.rod.size(), 5);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(c.rod.X[k], f.rod.X[k]);
    EXPECT_EQ(c.rod.D[k], f.rod.D[k]);
  }
  EXPECT_EQ(c.grid_n, 6);
  EXPECT_EQ(c.velocity, f.u);
  fs::remove_all(d);
}

// The implicit thermal scheme's held filter (issue 28: a run stopped by a signal at any step
// resumes bitwise): the state it was made at goes through record_state, the JSON and
// snapshot_of exactly; none stays none; a filter of another size than the rods is refused.
TEST(Checkpoint, TheHeldFilterStateRoundTripsExactly) {
  const fs::path d = scratch("held");
  Fixture f;
  sim::Snapshot s;
  s.rod = f.rod;
  s.step = 1234;
  s.time = 3.1e-7;
  s.implicit.next_dt = 1e-9;
  s.implicit.accepted_in_a_row = 4;
  integrate::ImplicitStepper::HeldFilter h;
  h.steps_since_refresh = 17;
  h.at = f.rod;
  for (int k = 0; k < h.at.size(); ++k) {
    h.at.X[k] += Vec3(1.0 / 3.0, -std::sqrt(3.0), 1e-17 * k);
    h.at.D[k] = rotation(Vec3(0.01 * std::sqrt(double(k)), -0.2, 0.1)) * h.at.D[k];
  }
  s.implicit.held = h;
  io::record_state(f.meta, s);
  f.write(d / "c.bin");
  io::Checkpoint c = io::read_checkpoint(d / "c.bin");
  const sim::Snapshot back = io::snapshot_of(std::move(c), 1e-9);
  ASSERT_TRUE(back.implicit.held.has_value());
  EXPECT_EQ(back.implicit.held->steps_since_refresh, 17);
  ASSERT_EQ(back.implicit.held->at.size(), 5);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(back.implicit.held->at.X[k], h.at.X[k]);  // bitwise, through JSON
    EXPECT_EQ(back.implicit.held->at.D[k], h.at.D[k]);
  }
  EXPECT_EQ(back.implicit.next_dt, 1e-9);
  EXPECT_EQ(back.implicit.accepted_in_a_row, 4);
  // none: no key, none back
  s.implicit.held.reset();
  io::record_state(f.meta, s);
  f.write(d / "c.bin");
  EXPECT_FALSE(io::snapshot_of(io::read_checkpoint(d / "c.bin"), 1e-9).implicit.held);
  // a filter of 4 points beside a rod of 5
  h.at.X.pop_back();
  h.at.D.pop_back();
  s.implicit.held = h;
  io::record_state(f.meta, s);
  f.write(d / "c.bin");
  EXPECT_THAT(read_error(d / "c.bin"), HasSubstr("implicit_filter has 4 points, the rods 5"));
  fs::remove_all(d);
}

TEST(Checkpoint, TruncatedFilesAreRejected) {
  const fs::path d = scratch("truncated");
  Fixture().write(d / "c.bin");
  const std::vector<char> full = bytes_of(d / "c.bin");
  for (std::size_t keep : {std::size_t(0), std::size_t(7), std::size_t(20), std::size_t(40),
                           full.size() / 2, full.size() - 1}) {
    put_bytes(d / "t.bin", std::vector<char>(full.begin(), full.begin() + std::ptrdiff_t(keep)));
    const std::string e = read_error(d / "t.bin");
    EXPECT_THAT(e, HasSubstr("t.bin")) << keep;
    EXPECT_TRUE(e.find("truncated") != std::string::npos ||
                e.find("not an ibrod checkpoint") != std::string::npos)
        << keep << ": " << e;
  }
  fs::remove_all(d);
}

TEST(Checkpoint, EveryFlippedPayloadBitIsCaught) {
  const fs::path d = scratch("flip");
  Fixture().write(d / "c.bin");
  const std::vector<char> good = bytes_of(d / "c.bin");
  // a bit in the JSON, in X, in D and in the velocity block
  for (std::size_t at : {std::size_t(40), std::size_t(200), good.size() / 2, good.size() - 3}) {
    std::vector<char> bad = good;
    bad[at] ^= 0x10;
    put_bytes(d / "b.bin", bad);
    EXPECT_THAT(read_error(d / "b.bin"), HasSubstr("corrupt")) << at;
  }
  // appended garbage
  std::vector<char> longer = good;
  longer.push_back('x');
  put_bytes(d / "b.bin", longer);
  EXPECT_THAT(read_error(d / "b.bin"), HasSubstr("corrupt"));
  fs::remove_all(d);
}

TEST(Checkpoint, ForeignFilesAndOtherVersionsAreRejected) {
  const fs::path d = scratch("foreign");
  std::ofstream(d / "x.bin")
      << "[grid]\nn = 16\n# not a checkpoint, but long enough for a header\n";
  EXPECT_THAT(read_error(d / "x.bin"), HasSubstr("not an ibrod checkpoint"));
  EXPECT_THAT(read_error(d / "missing.bin"), HasSubstr("cannot be read"));

  Fixture().write(d / "c.bin");
  std::vector<char> b = bytes_of(d / "c.bin");
  const std::uint32_t v = io::kCheckpointVersion + 1;
  std::memcpy(b.data() + 8, &v, 4);
  put_bytes(d / "v.bin", b);
  EXPECT_THAT(read_error(d / "v.bin"), HasSubstr("version"));
  fs::remove_all(d);
}

TEST(Checkpoint, AFullDiskKeepsThePreviousCheckpoint) {
  const fs::path d = scratch("full");
  Fixture small;
  small.write(d / "c.bin");
  const std::vector<char> before = bytes_of(d / "c.bin");

  // The next checkpoint does not fit: a file-size limit fails its writes (EFBIG) like a full disk.
  Fixture big;
  big.grid_n = 24;
  big.u.assign(3 * 24 * 24 * 24, 1.5);
  rlimit old{};
  getrlimit(RLIMIT_FSIZE, &old);
  auto* old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit lim = old;
  lim.rlim_cur = 64 * 1024;  // the new file needs ~330 kB
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &lim), 0);
  std::string error;
  try {
    big.write(d / "c.bin");
  } catch (const RunError& e) {
    error = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);

  EXPECT_THAT(error, HasSubstr("disk full"));
  EXPECT_THAT(error, HasSubstr("c.bin"));
  EXPECT_FALSE(fs::exists(d / "c.bin.tmp"));  // no half-written file left behind
  EXPECT_EQ(bytes_of(d / "c.bin"), before);   // the previous checkpoint, untouched
  EXPECT_EQ(io::read_checkpoint(d / "c.bin").meta.step, 1234);
  fs::remove_all(d);
}
