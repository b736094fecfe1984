// Nothing of a run is lost and nothing runs silently wrong ([no-data-lost]): one writer per run
// directory (the lock), a run killed before its final files completes on --resume, the simulated
// time is state (continuous across a Δt change), a t_end before the checkpoint is refused, the
// disk-full advice works, a checkpoint that is a directory is refused. Each test starts the real
// binary on the small configuration of helpers.hpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "analysis/analyze.hpp"
#include "config/config.hpp"
#include "driver/dir_lock.hpp"
#include "driver/sweep_runner.hpp"
#include "helpers.hpp"
#include "io/csv.hpp"
#include "io/h5md.hpp"
#include "run_helpers.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

// 600 steps of 0.1 ns (a few seconds), a row every 20, a checkpoint every 50; one thread.
config::Config long_config() {
  config::Config c = small_config(2);
  c.time_t_end_us = 0.06;
  c.output_every_steps = 20;
  c.output_frame_every_steps = 40;
  c.output_checkpoint_every_steps = 50;
  c.run_threads = 1;
  return c;
}

std::vector<double> column(const fs::path& csv, const std::string& name) {
  const io::CsvTable t = io::read_csv_table(csv);
  const auto s = t.column(name);
  return {s.begin(), s.end()};
}

}  // namespace

TEST(OneWriter, ASecondRunOrResumeOnALockedDirectoryIsRefusedNamingTheHolder) {
  const fs::path d = fresh_dir("lock");
  config::Config c = long_config();
  c.time_t_end_us = 5.0;  // far longer than the test: the first run is stopped by SIGTERM
  const fs::path cfg = write_config(d, c, "c.toml");
  const fs::path out = d / "out";
  Child first = spawn({"run", cfg.string(), "-o", out.string()}, d / "first.log");
  ASSERT_TRUE(wait_for_lines(first, out / "timeseries.csv", 3)) << read_file(d / "first.log");
  // while it runs: a resume and a fresh run into the same directory are refused, exit 2
  const Exit resume = run_ibrod({"run", "--resume", out.string()}, d / "resume.log");
  EXPECT_EQ(resume.code, 2) << resume.output;
  EXPECT_THAT(resume.output, HasSubstr("PID " + std::to_string(first.pid)));
  const Exit second =
      run_ibrod({"run", cfg.string(), "-o", out.string(), "--overwrite"}, d / "second.log");
  EXPECT_EQ(second.code, 2) << second.output;
  EXPECT_THAT(second.output, HasSubstr("another ibrod process"));
  // the lock is visible to a sweep as a running point
  EXPECT_EQ(driver::point_state(out), driver::PointState::running);
  ::kill(first.pid, SIGTERM);
  const Exit e = wait_for(first);
  EXPECT_EQ(e.code, 128 + SIGTERM) << e.output;
  // the first run's files are whole (the refused writers touched nothing): rows every 20 steps
  // up to the step it stopped at, the summary says so
  const auto steps = column(out / "timeseries.csv", "step");
  for (std::size_t i = 1; i < steps.size(); ++i) EXPECT_GT(steps[i], steps[i - 1]);
  EXPECT_THAT(read_file(out / "summary.json"), HasSubstr("\"stop_reason\": \"interrupted\""));
  // released with the process: no longer locked, and it continues
  EXPECT_FALSE(driver::dir_lock_holder(out).has_value());
  EXPECT_EQ(driver::point_state(out), driver::PointState::interrupted);
  fs::remove_all(d);
}

TEST(OneWriter, AKilledWritersLockIsNoLock) {
  const fs::path d = fresh_dir("lock_killed");
  const fs::path cfg = write_config(d, long_config(), "c.toml");
  const fs::path out = d / "out";
  Child first = spawn({"run", cfg.string(), "-o", out.string()}, d / "first.log");
  ASSERT_TRUE(wait_for_lines(first, out / "timeseries.csv", 5));
  ::kill(first.pid, SIGKILL);
  wait_for(first);
  EXPECT_TRUE(fs::exists(out / "ibrod.lock"));  // the file stays, the lock went with the process
  const Exit r = run_ibrod({"run", "--resume", out.string()}, d / "resume.log");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_THAT(read_file(out / "summary.json"), HasSubstr("\"stop_reason\": \"end_time\""));
  fs::remove_all(d);
}

TEST(RunsComplete, KilledAfterTheFinalCheckpointResumeWritesTheMissingFinalFiles) {
  const fs::path d = fresh_dir("complete");
  const fs::path cfg = write_config(d, long_config(), "c.toml");
  const fs::path out = d / "out";
  ASSERT_EQ(run_ibrod({"run", cfg.string(), "-o", out.string()}, d / "a.log").code, 0);
  const std::string summary = read_file(out / "summary.json");
  const std::string final_state = read_file(out / "final_state.csv");
  // as if killed after the final checkpoint, before final_state.csv and summary.json
  fs::remove(out / "summary.json");
  fs::remove(out / "final_state.csv");
  EXPECT_EQ(driver::point_state(out), driver::PointState::interrupted);  // a sweep resumes it
  const Exit r = run_ibrod({"run", "--resume", out.string()}, d / "b.log");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("final files are incomplete"));
  EXPECT_EQ(read_file(out / "final_state.csv"), final_state);
  EXPECT_THAT(read_file(out / "summary.json"), HasSubstr("\"stop_reason\": \"end_time\""));
  EXPECT_EQ(driver::point_state(out), driver::PointState::finished);
  EXPECT_EQ(lines_in(out / "timeseries.csv"), 1 + 600 / 20 + 1);
  // and then there is nothing left to do
  const Exit again = run_ibrod({"run", "--resume", out.string()}, d / "c.log");
  EXPECT_EQ(again.code, 0);
  EXPECT_THAT(again.output, HasSubstr("nothing to do"));
  (void)summary;
  fs::remove_all(d);
}

TEST(TimeIsState, AChangedTimeStepOnResumeKeepsTheTimeContinuousAndMonotone) {
  const fs::path d = fresh_dir("time_state");
  config::Config c = long_config();
  c.time_t_end_us = 0.012;  // 120 steps of 0.1 ns
  c.output_every_steps = 10;
  c.output_frame_every_steps = 10;
  c.output_checkpoint_every_steps = 60;
  const fs::path cfg = write_config(d, c, "c.toml");
  const fs::path out = d / "out";
  ASSERT_EQ(run_ibrod({"run", cfg.string(), "-o", out.string()}, d / "a.log").code, 0);
  // continue to 0.016 us with Δt = 0.004 ns (was 0.1): 1000 more steps
  const Exit r = run_ibrod({"run", "--resume", out.string(), "--force", "--set", "time.dt_ns=0.004",
                            "--set", "time.t_end_us=0.016", "--set", "output.every_steps=250",
                            "--set", "output.frame_every_steps=250"},
                           d / "b.log");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto t = column(out / "timeseries.csv", "time_us");
  const auto step = column(out / "timeseries.csv", "step");
  ASSERT_GE(t.size(), 14u);
  for (std::size_t i = 1; i < t.size(); ++i) {
    EXPECT_GT(t[i], t[i - 1]) << "row " << i;
    EXPECT_GT(step[i], step[i - 1]) << "row " << i;
  }
  EXPECT_NEAR(t.back(), 0.016, 1e-9);
  EXPECT_DOUBLE_EQ(step.back(), 1120);  // 120 steps of 0.1 ns, 1000 of 0.004 ns
  // the H5MD frames carry the same continuous time
  const io::H5mdSeries pos = io::read_h5md_series(out / "trajectory.h5md", "position");
  for (std::size_t i = 1; i < pos.time_us.size(); ++i)
    EXPECT_GT(pos.time_us[i], pos.time_us[i - 1]);
  EXPECT_NEAR(pos.time_us.back(), 0.016, 1e-9);
  const std::string summary = read_file(out / "summary.json");
  const auto at = summary.find("\"time_us\": ");
  ASSERT_NE(at, std::string::npos);
  EXPECT_NEAR(std::stod(summary.substr(at + 11)), 0.016, 1e-12);
  fs::remove_all(d);
}

TEST(TimeIsState, AnEndTimeBeforeTheCheckpointIsRefused) {
  const fs::path d = fresh_dir("t_end_back");
  config::Config c = long_config();
  c.time_t_end_us = 0.01;
  const fs::path cfg = write_config(d, c, "c.toml");
  const fs::path out = d / "out";
  ASSERT_EQ(run_ibrod({"run", cfg.string(), "-o", out.string()}, d / "a.log").code, 0);
  const Exit r = run_ibrod(
      {"run", "--resume", out.string(), "--force", "--set", "time.t_end_us=0.005"}, d / "b.log");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("time.t_end_us"));
  EXPECT_THAT(r.output, HasSubstr("cannot go back"));
  EXPECT_EQ(column(out / "timeseries.csv", "step").back(), 100);  // untouched
  fs::remove_all(d);
}

TEST(CheckpointFile, ADirectoryInItsPlaceIsRefusedNamingIt) {
  const fs::path d = fresh_dir("ckpt_dir");
  config::Config c = long_config();
  c.time_t_end_us = 0.005;
  const fs::path cfg = write_config(d, c, "c.toml");
  const fs::path out = d / "out";
  ASSERT_EQ(run_ibrod({"run", cfg.string(), "-o", out.string()}, d / "a.log").code, 0);
  fs::remove(out / "checkpoint.bin");
  fs::create_directory(out / "checkpoint.bin");
  const Exit r = run_ibrod({"run", "--resume", out.string()}, d / "b.log");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("checkpoint.bin"));
  EXPECT_THAT(r.output, HasSubstr("is a directory"));
  fs::remove_all(d);
}

TEST(DiskFull, BeforeTheFirstCheckpointTheAdviceIsOverwriteAndItWorks) {
  const fs::path d = fresh_dir("disk_full_early");
  config::Config c = long_config();
  c.time_t_end_us = 0.005;
  const fs::path cfg = write_config(d, c, "c.toml");
  const fs::path out = d / "out";
  // a file-size limit below the first checkpoint (24 × 16³ B + the rod ≈ 100 KB)
  const Exit full = run_ibrod({"run", cfg.string(), "-o", out.string()}, d / "a.log", 60000);
  ASSERT_NE(full.code, 0) << full.output;
  EXPECT_FALSE(fs::exists(out / "checkpoint.bin"));
  // whatever it advises, that command must work
  if (full.output.find("--resume") != std::string::npos &&
      full.output.find("--overwrite") == std::string::npos)
    FAIL() << "advises --resume without a checkpoint: " << full.output;
  EXPECT_THAT(full.output, HasSubstr("--overwrite"));
  const Exit again =
      run_ibrod({"run", cfg.string(), "-o", out.string(), "--overwrite"}, d / "b.log");
  EXPECT_EQ(again.code, 0) << again.output;
  fs::remove_all(d);
}

TEST(Extension, ALaterEndTimeAloneNeedsNoForceAndEqualsTheUninterruptedLongerRun) {
  const fs::path d = fresh_dir("extend");
  config::Config c = long_config();
  c.time_t_end_us = 0.05;  // 500 steps: not a multiple of the rows (every 20: yes) or frames (40)
  c.output_every_steps = 30;
  const fs::path short_cfg = write_config(d, c, "short.toml");
  c.time_t_end_us = 0.09;
  const fs::path long_cfg = write_config(d, c, "long.toml");
  ASSERT_EQ(run_ibrod({"run", long_cfg.string(), "-o", (d / "ref").string()}, d / "ref.log").code,
            0);
  ASSERT_EQ(run_ibrod({"run", short_cfg.string(), "-o", (d / "ext").string()}, d / "a.log").code,
            0);
  const Exit e = run_ibrod({"run", "--resume", (d / "ext").string(), "--set", "time.t_end_us=0.09"},
                           d / "b.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("extending the run"));
  EXPECT_EQ(read_file(d / "ext" / "timeseries.csv"), read_file(d / "ref" / "timeseries.csv"));
  EXPECT_EQ(read_file(d / "ext" / "final_state.csv"), read_file(d / "ref" / "final_state.csv"));
  const io::H5mdSeries a = io::read_h5md_series(d / "ext" / "trajectory.h5md", "position");
  const io::H5mdSeries b = io::read_h5md_series(d / "ref" / "trajectory.h5md", "position");
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.value, b.value);
  // another change still needs --force
  const Exit other = run_ibrod({"run", "--resume", (d / "ext").string(), "--set",
                                "time.t_end_us=0.1", "--set", "solvent.salt_M=0.05"},
                               d / "c.log");
  EXPECT_EQ(other.code, 2) << other.output;
  EXPECT_THAT(other.output, HasSubstr("--force"));
  fs::remove_all(d);
}
