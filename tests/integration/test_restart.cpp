// Long runs people can trust: a run killed (-9) at an arbitrary step and resumed, or stopped by
// SIGTERM and resumed, ends bitwise identical to an uninterrupted one — time series, final
// state, trajectory and ParaView series; damaged or foreign checkpoints are refused with a
// message; a blow-up stops at once with a diagnosis; a full disk is an error that leaves a
// resumable directory.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "helpers.hpp"
#include "io/checkpoint.hpp"
#include "io/h5md.hpp"
#include "run_helpers.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

// the runs these tests kill mid-way run at a lower priority than the test that watches their rows
constexpr int kKilledNice = 10;

// 16³ grid, 100 points, 200 Å box (helpers.hpp), 600 steps of 0.1 ns. FFTW_MEASURE and two
// threads, so that plans and OpenMP reductions are exercised; checkpoints every 50 steps, rows
// every 20, frames every 40 (none of them divides the others).
std::string restart_config() {
  ibrod::config::Config c = ibrod::test::small_config(2);
  c.time_t_end_us = 0.06;
  c.output_every_steps = 20;
  c.output_frame_every_steps = 40;
  c.output_checkpoint_every_steps = 50;
  c.run_threads = 2;
  c.run_fftw_measure = true;
  return ibrod::test::small_config_toml(c);
}

void expect_same_run(const fs::path& a, const fs::path& b) {
  EXPECT_EQ(read_file(a / "timeseries.csv"), read_file(b / "timeseries.csv"));
  EXPECT_EQ(read_file(a / "final_state.csv"), read_file(b / "final_state.csv"));
  EXPECT_EQ(read_file(a / "rod.pvd"), read_file(b / "rod.pvd"));
  for (const char* e : {"position", "d1", "d2", "d3"}) {
    const io::H5mdSeries sa = io::read_h5md_series(a / "trajectory.h5md", e);
    const io::H5mdSeries sb = io::read_h5md_series(b / "trajectory.h5md", e);
    EXPECT_EQ(sa.step, sb.step) << e;
    EXPECT_EQ(sa.time_us, sb.time_us) << e;
    EXPECT_TRUE(sa.value == sb.value) << e << ": frames differ";  // bitwise
  }
  EXPECT_EQ(read_file(a / "vtk" / "rod_000600.vtp"), read_file(b / "vtk" / "rod_000600.vtp"));
}

class Restart : public ::testing::Test {
 protected:
  // The uninterrupted reference run, shared by the tests of this suite.
  static void SetUpTestSuite() {
    root_ = fresh_dir("restart");
    std::ofstream(root_ / "in.toml") << restart_config();
    const Exit e = run_ibrod({"run", (root_ / "in.toml").string(), "-o", (root_ / "A").string()},
                             root_ / "A.log");
    ASSERT_EQ(e.code, 0) << e.output;
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static fs::path root_;
  fs::path ref() const { return root_ / "A"; }
  // A run that shares the reference's FFTW plans (FFTW_MEASURE may choose other plans in
  // another process, and other plans round differently).
  std::vector<std::string> run_args(const std::string& out) const {
    return {"run",           (root_ / "in.toml").string(),    "-o", (root_ / out).string(),
            "--fftw-wisdom", (ref() / "fftw.wisdom").string()};
  }
};
fs::path Restart::root_;

}  // namespace

TEST_F(Restart, KilledTwiceAndResumedIsBitwiseIdentical) {
  const fs::path b = root_ / "B";
  // kill -9 after 9 rows (step ≥ 160: checkpoint 150 or later), resume, kill again after 22 rows
  Child c = spawn(run_args("B"), root_ / "B1.log", 0, 0, kKilledNice);
  ASSERT_TRUE(wait_for_lines(c, b / "timeseries.csv", 1 + 9)) << read_file(root_ / "B1.log");
  ::kill(c.pid, SIGKILL);
  Exit e = wait_for(c);
  ASSERT_EQ(e.signal, SIGKILL) << "the run finished before it could be killed";
  const std::int64_t ck1 = io::read_checkpoint(b / "checkpoint.bin").meta.step;
  EXPECT_EQ(ck1 % 50, 0);

  c = spawn({"run", "--resume", b.string()}, root_ / "B2.log", 0, 0, kKilledNice);
  ASSERT_TRUE(wait_for_lines(c, b / "timeseries.csv", 1 + 22)) << read_file(root_ / "B2.log");
  ::kill(c.pid, SIGKILL);
  e = wait_for(c);
  ASSERT_EQ(e.signal, SIGKILL) << "the run finished before it could be killed";

  e = run_ibrod({"run", "--resume", b.string()}, root_ / "B3.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("resuming"));
  expect_same_run(ref(), b);
  // 31 rows, no gap, no duplicate
  EXPECT_EQ(lines_in(b / "timeseries.csv"), 1 + 31);
  const std::string summary = read_file(b / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"resumes\": 2"));
  EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"end_time\""));
}

TEST_F(Restart, SigtermWritesACheckpointAndTheRunContinuesExactly) {
  const fs::path b = root_ / "T";
  Child c = spawn(run_args("T"), root_ / "T1.log", 0, 0, kKilledNice);
  ASSERT_TRUE(wait_for_lines(c, b / "timeseries.csv", 1 + 12)) << read_file(root_ / "T1.log");
  ::kill(c.pid, SIGTERM);
  Exit e = wait_for(c);
  ASSERT_EQ(e.code, 128 + SIGTERM) << e.output;
  EXPECT_THAT(e.output, HasSubstr("interrupted by SIGTERM"));
  EXPECT_THAT(e.output, HasSubstr("ibrod run --resume " + b.string()));
  // the checkpoint is of the step the signal arrived in, not of the last periodic one
  const io::Checkpoint ck = io::read_checkpoint(b / "checkpoint.bin");
  EXPECT_GE(ck.meta.step, 220);
  EXPECT_THAT(read_file(b / "summary.json"), HasSubstr("\"stop_reason\": \"interrupted\""));

  e = run_ibrod({"run", "--resume", b.string()}, root_ / "T2.log");
  ASSERT_EQ(e.code, 0) << e.output;
  expect_same_run(ref(), b);
}

TEST_F(Restart, DamagedOrForeignCheckpointsAreRefused) {
  const fs::path d = root_ / "D";
  fs::copy(ref(), d, fs::copy_options::recursive);
  const std::string good = read_file(d / "checkpoint.bin");
  auto resume = [&](std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"run", "--resume", d.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_ibrod(args, root_ / "D.log");
  };
  auto put = [&](const std::string& bytes) {
    std::ofstream(d / "checkpoint.bin", std::ios::binary | std::ios::trunc) << bytes;
  };

  // a finished run has nothing to do
  Exit e = resume();
  EXPECT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("nothing to do"));

  put(good.substr(0, good.size() / 3));
  e = resume();
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("truncated"));

  std::string flipped = good;
  flipped[flipped.size() / 2] ^= 0x01;
  put(flipped);
  e = resume();
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("corrupt"));

  // another configuration: refused, unless forced (a later t_end alone is an extension, which
  // needs no --force: test_no_data_lost.cpp); another grid: refused even when forced
  put(good);
  e = resume({"--set", "solvent.salt_M=0.05"});
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("solvent.salt_M: 0.1 → 0.05"));
  EXPECT_THAT(e.output, HasSubstr("--force"));
  e = resume({"--set", "grid.n=32", "--force"});
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("incompatible"));
  e = resume({"--set", "time.t_end_us=0.07", "--force"});
  EXPECT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(read_file(d / "config.toml"), HasSubstr("t_end_us = 0.07"));
  EXPECT_EQ(lines_in(d / "timeseries.csv"), 1 + 36);  // rows 0, 20, …, 700

  // no checkpoint at all
  fs::remove(d / "checkpoint.bin");
  e = resume();
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("checkpoint.bin does not exist"));
}

TEST_F(Restart, AFullDiskStopsWithAMessageAndTheRunCanBeResumed) {
  const fs::path f = root_ / "F";
  // At most 200 kB per file (RLIMIT_FSIZE: writes beyond fail with EFBIG, as on a full disk):
  // the checkpoint (~110 kB) fits, trajectory.h5md (~110 kB + ~10 kB per frame) outgrows it
  // mid-run. (A real disk that fills up is met earlier, by the free-space check before writes.)
  Exit e = run_ibrod(run_args("F"), root_ / "F1.log", 200 * 1024);
  ASSERT_EQ(e.code, 3) << e.output;
  EXPECT_THAT(e.output, HasSubstr("disk full"));
  for (const auto& entry : fs::recursive_directory_iterator(f))
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();
  const io::Checkpoint ck = io::read_checkpoint(f / "checkpoint.bin");  // intact
  EXPECT_GT(ck.meta.step, 0);
  EXPECT_LT(ck.meta.step, 600);

  e = run_ibrod({"run", "--resume", f.string()}, root_ / "F2.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_EQ(read_file(ref() / "timeseries.csv"), read_file(f / "timeseries.csv"));
  EXPECT_EQ(read_file(ref() / "final_state.csv"), read_file(f / "final_state.csv"));
}

TEST(SafeFailure, ATimeStepFarTooLargeStopsWithinOneOutputInterval) {
  const fs::path d = fresh_dir("blowup");
  std::ofstream(d / "in.toml") << "[grid]\nn = 16\nbox_A = 200\n[rod]\nbase_pairs = 100\n"
                                  "[time]\ndt_ns = 2\nt_end_us = 2\n[output]\nevery_steps = 100\n"
                                  "[run]\nfftw_measure = false\n";
  const Exit e =
      run_ibrod({"run", (d / "in.toml").string(), "-o", (d / "out").string()}, d / "log");
  EXPECT_EQ(e.code, 3) << e.output;
  EXPECT_THAT(e.output, HasSubstr("blow-up at step"));
  EXPECT_THAT(e.output, HasSubstr("time step is probably too large"));
  EXPECT_THAT(e.output, HasSubstr("time.dt_ns = 2"));
  EXPECT_THAT(e.output, HasSubstr("last good checkpoint (step 0)"));
  const std::string summary = read_file(d / "out" / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"blow_up\""));
  const std::int64_t step = std::stoll(e.output.substr(e.output.find("blow-up at step ") + 16));
  EXPECT_GE(step, 1);
  EXPECT_LE(step, 100);
  // the checkpoint of the last good state is still there and valid
  EXPECT_EQ(io::read_checkpoint(d / "out" / "checkpoint.bin").meta.step, 0);
  fs::remove_all(d);
}
