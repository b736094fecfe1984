// `mpirun -np K ibrod run` (issue 7): one fluid grid split in x-slabs over K ranks
// (fluid::DistributedFluid), the rod replicated. The K-rank trajectory is the one-process one up
// to round-off; a rank count that does not divide grid.n is a clear input error on every rank;
// checkpoints keep the one-process format, so a run moves between K ranks and one.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "run_helpers.hpp"

using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

// 16³, 200 Å box, 100 points, electrostatics and steric on (the defaults), 100 steps of 0.1 ns,
// one thread per process.
std::string tiny_config() {
  ibrod::config::Config c = ibrod::test::small_config(2);
  c.time_t_end_us = 0.01;
  c.output_every_steps = 10;
  c.output_frame_every_steps = 50;
  c.output_checkpoint_every_steps = 50;
  c.run_threads = 1;
  return ibrod::test::small_config_toml(c);
}

bool mpi_usable() {
#ifndef IBROD_MPI
  return false;
#else
  return std::system("command -v mpirun > /dev/null 2>&1") == 0;
#endif
}

// `mpirun -np ranks ibrod args…` (as root OpenMPI needs --allow-run-as-root; --oversubscribe:
// more ranks than cores), output to log; a hang fails after 300 s. Returns the exit status.
int mpirun(int ranks, const std::string& args, const fs::path& log) {
  const std::string cmd =
      "OMP_WAIT_POLICY=passive timeout 300 mpirun --allow-run-as-root "
      "--oversubscribe -np " +
      std::to_string(ranks) + " " + IBROD_BINARY + " " + args + " > " + log.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

std::vector<std::vector<double>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::strtod(cell.c_str(), nullptr));
    rows.push_back(row);
  }
  return rows;
}

int column(const fs::path& csv, const std::string& name) {
  std::ifstream in(csv);
  std::string header, cell;
  std::getline(in, header);
  std::stringstream ss(header);
  for (int i = 0; std::getline(ss, cell, ','); ++i)
    if (cell == name) return i;
  return -1;
}

// final_state.csv: positions (Å) to 1e-10 of the box, triads (unit vectors) to 1e-10; the fluid
// kinetic energy of every timeseries row to 1e-10 relative.
void expect_same_trajectory(const fs::path& a, const fs::path& b) {
  const auto fa = read_csv(a / "final_state.csv"), fb = read_csv(b / "final_state.csv");
  ASSERT_EQ(fa.size(), 100u);
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t k = 0; k < fa.size(); ++k) {
    ASSERT_EQ(fa[k].size(), 12u);
    ASSERT_EQ(fb[k].size(), 12u);
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(fa[k][d], fb[k][d], 1e-10 * 200.0) << "point " << k << " x" << d;
    for (int d = 3; d < 12; ++d)
      EXPECT_NEAR(fa[k][d], fb[k][d], 1e-10) << "point " << k << " triad entry " << d - 3;
  }
  const int ek = column(a / "timeseries.csv", "E_kinetic_kT");
  ASSERT_GE(ek, 0);
  const auto ta = read_csv(a / "timeseries.csv"), tb = read_csv(b / "timeseries.csv");
  ASSERT_EQ(ta.size(), 11u);  // steps 0, 10, …, 100
  ASSERT_EQ(ta.size(), tb.size());
  for (std::size_t r = 1; r < ta.size(); ++r) {
    EXPECT_EQ(ta[r][0], tb[r][0]);
    ASSERT_GT(ta[r][ek], 0.0);
    EXPECT_NEAR(tb[r][ek], ta[r][ek], 1e-10 * ta[r][ek]) << "step " << ta[r][0];
  }
}

}  // namespace

TEST(MpiRun, TwoRanksShareTheFluidGridAndAgreeWithOneProcess) {
  if (!mpi_usable()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const fs::path d = fresh_dir("mpi_run");
  std::ofstream(d / "tiny.toml") << tiny_config();
  const auto one =
      run_ibrod({"run", (d / "tiny.toml").string(), "-o", (d / "one").string()}, d / "one.log");
  ASSERT_EQ(one.code, 0) << one.output;
  const int rc =
      mpirun(2, "run " + (d / "tiny.toml").string() + " -o " + (d / "two").string(), d / "two.log");
  const std::string log = read_file(d / "two.log");
  ASSERT_EQ(rc, 0) << log;
  // rank 0 alone reports
  EXPECT_EQ(log.find("ibrod: stopped (end_time)"), log.rfind("ibrod: stopped (end_time)")) << log;
  expect_same_trajectory(d / "one", d / "two");
  // the same outputs as a one-process run (rank 0 wrote them)
  for (const char* f : {"config.toml", "summary.json", "trajectory.h5md", "checkpoint.bin",
                        "fftw.wisdom", "rod.pvd"})
    EXPECT_TRUE(fs::exists(d / "two" / f)) << f;
  fs::remove_all(d);
}

TEST(MpiRun, ARankCountThatDoesNotDivideTheGridIsAnInputErrorOnEveryRank) {
  if (!mpi_usable()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const fs::path d = fresh_dir("mpi_run_k3");
  std::ofstream(d / "tiny.toml") << tiny_config();
  const int rc =
      mpirun(3, "run " + (d / "tiny.toml").string() + " -o " + (d / "out").string(), d / "log");
  const std::string log = read_file(d / "log");
  EXPECT_EQ(rc, 2) << log;
  // every rank stopped with the message (none hung: mpirun returned)
  const std::string msg = "grid.n = 16 cannot be split over 3 MPI ranks";
  int count = 0;
  for (auto p = log.find(msg); p != std::string::npos; p = log.find(msg, p + 1)) ++count;
  EXPECT_EQ(count, 3) << log;
  EXPECT_FALSE(fs::exists(d / "out" / "checkpoint.bin"));
  fs::remove_all(d);
}

TEST(MpiRun, ABadConfigIsExit2OnEveryRank) {
  if (!mpi_usable()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const fs::path d = fresh_dir("mpi_run_bad");
  std::ofstream(d / "tiny.toml") << tiny_config();
  const int rc = mpirun(
      2, "run " + (d / "tiny.toml").string() + " --set time.dt_ns=-1 -o " + (d / "out").string(),
      d / "log");
  EXPECT_EQ(rc, 2) << read_file(d / "log");
  fs::remove_all(d);
}

TEST(MpiRun, CheckpointsMoveBetweenTwoRanksAndOneProcess) {
  if (!mpi_usable()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const fs::path d = fresh_dir("mpi_run_resume");
  std::ofstream(d / "tiny.toml") << tiny_config();
  const std::string cfg = (d / "tiny.toml").string();
  const auto one = run_ibrod({"run", cfg, "-o", (d / "one").string()}, d / "one.log");
  ASSERT_EQ(one.code, 0) << one.output;
  const std::string half = " --set time.t_end_us=0.005";
  const std::string full = " --set time.t_end_us=0.01 --force";

  // 50 steps on 2 ranks, the other 50 in one process
  ASSERT_EQ(mpirun(2, "run " + cfg + half + " -o " + (d / "a").string(), d / "a1.log"), 0)
      << read_file(d / "a1.log");
  const auto a =
      run_ibrod({"run", "--resume", (d / "a").string(), "--set", "time.t_end_us=0.01", "--force"},
                d / "a2.log");
  ASSERT_EQ(a.code, 0) << a.output;
  expect_same_trajectory(d / "one", d / "a");

  // 50 steps in one process, the other 50 on 2 ranks
  const auto b = run_ibrod({"run", cfg, "--set", "time.t_end_us=0.005", "-o", (d / "b").string()},
                           d / "b1.log");
  ASSERT_EQ(b.code, 0) << b.output;
  ASSERT_EQ(mpirun(2, "run --resume " + (d / "b").string() + full, d / "b2.log"), 0)
      << read_file(d / "b2.log");
  expect_same_trajectory(d / "one", d / "b");
  fs::remove_all(d);
}
