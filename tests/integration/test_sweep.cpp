// Sweeps end to end (driver/sweep_runner.hpp, `ibrod sweep`): the points run as real `ibrod run`
// processes; a sweep stopped part-way and started again finishes every point exactly once (finished
// points skipped, the interrupted one resumed from its checkpoint, bitwise as if never stopped); a
// failed point is reported and the others finish; under mpirun the ranks share the points.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "driver/dir_lock.hpp"
#include "driver/sweep_runner.hpp"
#include "helpers.hpp"
#include "run_helpers.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

// 16³, 100 points, 200 Å box: 4 points (ΔLk 1, 2 × Cs 0.05, 0.1) of 1500 steps, checkpoints
// every 100 steps, one thread each so that two can run side by side.
std::string tiny_sweep() {
  ibrod::config::Config c = ibrod::test::small_config(1);
  c.time_t_end_us = 0.15;
  c.output_every_steps = 50;
  c.output_frame_every_steps = 0;
  c.output_checkpoint_every_steps = 100;
  c.run_threads = 1;
  return ibrod::test::small_config_toml(c) +
         "[sweep]\n\"rod.excess_link\" = [1, 2]\n\"solvent.salt_M\" = [0.05, 0.1]\n";
}

driver::SweepOptions options(const fs::path& root, int jobs, std::FILE* log = nullptr) {
  driver::SweepOptions o;
  o.output_root = root;
  o.jobs = jobs;
  o.binary = IBROD_BINARY;
  o.log = log;
  return o;
}

std::string stop_reason(const fs::path& dir) {
  const std::string s = read_file(dir / "summary.json");
  const auto p = s.find("\"stop_reason\": \"");
  return p == std::string::npos ? "" : s.substr(p + 16, s.find('"', p + 16) - p - 16);
}

// steps of the time series, in file order
std::vector<long> steps_of(const fs::path& dir) {
  std::istringstream in(read_file(dir / "timeseries.csv"));
  std::string line;
  std::getline(in, line);  // header
  std::vector<long> steps;
  while (std::getline(in, line)) steps.push_back(std::stol(line));
  return steps;
}

// true once app/main.cpp registers the subcommand (add_sweep_command)
bool sweep_command_wired() {
  const fs::path d = fresh_dir("sweep_wired");
  const Exit e = run_ibrod({"sweep", (d / "none.toml").string()}, d / "log");
  fs::remove_all(d);
  return e.output.find("sweep: cannot read file") != std::string::npos;
}

}  // namespace

TEST(SweepRun, InterruptedPartWayAndStartedAgainFinishesEveryPointExactlyOnce) {
  const fs::path d = fresh_dir("sweep_resume");
  std::ofstream(d / "sweep.toml") << tiny_sweep();
  const driver::Sweep sw = driver::load_sweep(d / "sweep.toml");
  ASSERT_EQ(sw.points.size(), 4u);
  const fs::path root = d / "out";
  auto dir = [&](int i) { return root / sw.points[std::size_t(i)].name; };

  // 1. the sweep in a child process, one point at a time; SIGTERM once point 0 is finished and
  //    point 1 has written a checkpoint after its start
  const pid_t pid = ::fork();
  if (pid == 0) {
    const driver::SweepReport r = driver::run_sweep(sw, options(root, 1));
    ::_exit(r.signal ? 100 : r.failed);
  }
  const auto t0 = std::chrono::steady_clock::now();
  bool caught = false;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120)) {
    if (stop_reason(dir(0)) == "end_time" && steps_of(dir(1)).size() >= 4) {
      ::kill(pid, SIGTERM);
      caught = true;
      break;
    }
    int st = 0;
    if (::waitpid(pid, &st, WNOHANG) == pid) break;
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  int st = 0;
  ::waitpid(pid, &st, 0);
  ASSERT_TRUE(caught) << "the sweep ended before it could be interrupted";
  EXPECT_EQ(WEXITSTATUS(st), 100);
  EXPECT_EQ(driver::point_state(dir(0)), driver::PointState::finished);
  const bool point1_interrupted = driver::point_state(dir(1)) == driver::PointState::interrupted;
  EXPECT_TRUE(point1_interrupted) << "point 1 finished before the signal reached it";
  EXPECT_EQ(driver::point_state(dir(2)), driver::PointState::fresh);  // never started
  EXPECT_EQ(driver::point_state(dir(3)), driver::PointState::fresh);

  // 2. started again (two at a time): point 0 skipped, point 1 resumed, points 2 and 3 run
  const driver::SweepReport r = driver::run_sweep(sw, options(root, 2));
  EXPECT_EQ(r.points, 4);
  EXPECT_EQ(r.skipped, 1);
  EXPECT_EQ(r.resumed, point1_interrupted ? 1 : 0);
  EXPECT_EQ(r.fresh + r.resumed, 3);
  EXPECT_EQ(r.completed, 3);
  EXPECT_EQ(r.failed, 0);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(stop_reason(dir(i)), "end_time") << i;
    // every output step once, in order, up to the end
    std::vector<long> want;
    for (long s = 0; s <= 1500; s += 50) want.push_back(s);
    EXPECT_EQ(steps_of(dir(i)), want) << i;
  }
  EXPECT_THAT(read_file(dir(1) / "summary.json"), HasSubstr("\"resumes\": 1"));
  // the resumed point is bitwise the uninterrupted run of its config
  const Exit e = run_ibrod({"run", (root / "configs" / (sw.points[1].name + ".toml")).string(),
                            "-o", (d / "direct").string()},
                           d / "direct.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_EQ(read_file(dir(1) / "final_state.csv"), read_file(d / "direct" / "final_state.csv"));
  EXPECT_EQ(read_file(dir(1) / "timeseries.csv"), read_file(d / "direct" / "timeseries.csv"));

  // 3. a third time: nothing to do
  const driver::SweepReport again = driver::run_sweep(sw, options(root, 2));
  EXPECT_EQ(again.skipped, 4);
  EXPECT_EQ(again.fresh + again.resumed + again.failed, 0);
  EXPECT_THAT(read_file(root / "points.csv"), HasSubstr("1,dlk=1_salt_M=0.1,1,0.1\n"));
  fs::remove_all(d);
}

TEST(SweepRun, AFailedPointIsReportedAndTheOthersFinish) {
  const fs::path d = fresh_dir("sweep_fail");
  // Δt = 2 ns blows up (SafeFailure in test_restart.cpp); Δt = 0.1 ns does not
  std::ofstream(d / "sweep.toml")
      << "[grid]\nn = 16\nbox_A = 200\n[rod]\nbase_pairs = 100\nexcess_link = 2\n[time]\n"
         "t_end_us = 0.2\n[output]\nevery_steps = 100\n[run]\nthreads = 1\nfftw_measure = false\n"
         "[sweep]\n\"time.dt_ns\" = [2.0, 0.1]\n";
  const driver::Sweep sw = driver::load_sweep(d / "sweep.toml");
  ASSERT_EQ(sw.points[0].name, "dt_ns=2");
  const driver::SweepReport r = driver::run_sweep(sw, options(d / "out", 2));
  EXPECT_EQ(r.failed, 1);
  EXPECT_EQ(r.failed_names, std::vector<std::string>{"dt_ns=2"});
  EXPECT_EQ(r.completed, 1);
  EXPECT_EQ(stop_reason(d / "out" / "dt_ns=0.1"), "end_time");
  EXPECT_THAT(read_file(d / "out" / "logs" / "dt_ns=2.log"), HasSubstr("blow-up"));
  // again: the blown-up point is reported, not re-run; the finished one skipped
  const driver::SweepReport again = driver::run_sweep(sw, options(d / "out", 2));
  EXPECT_EQ(again.failed, 1);
  EXPECT_EQ(again.skipped, 1);
  EXPECT_EQ(again.fresh + again.resumed, 0);
  fs::remove_all(d);
}

TEST(SweepRun, APointDirectoryOfAnotherConfigurationIsNotTouched) {
  const fs::path d = fresh_dir("sweep_stale");
  std::ofstream(d / "sweep.toml")
      << "[grid]\nn = 16\nbox_A = 200\n[rod]\nbase_pairs = 100\n[time]\nt_end_us = 0.01\n"
         "[run]\nthreads = 1\nfftw_measure = false\n[sweep]\n\"rod.excess_link\" = [3]\n";
  ASSERT_EQ(
      driver::run_sweep(driver::load_sweep(d / "sweep.toml"), options(d / "out", 1)).completed, 1);
  // the same point name with another base value (t_end): refused, left as it is
  std::ofstream(d / "sweep.toml")
      << "[grid]\nn = 16\nbox_A = 200\n[rod]\nbase_pairs = 100\n[time]\nt_end_us = 0.02\n"
         "[run]\nthreads = 1\nfftw_measure = false\n[sweep]\n\"rod.excess_link\" = [3]\n";
  const std::string before = read_file(d / "out" / "dlk=3" / "summary.json");
  const driver::SweepReport r =
      driver::run_sweep(driver::load_sweep(d / "sweep.toml"), options(d / "out", 1));
  EXPECT_EQ(r.failed, 1);
  EXPECT_EQ(read_file(d / "out" / "dlk=3" / "summary.json"), before);
  fs::remove_all(d);
}

TEST(SweepCommand, RunsEveryPointAndRejectsABadFileNamingTheKey) {
  if (!sweep_command_wired()) GTEST_SKIP() << "`ibrod sweep` is not wired into app/main.cpp yet";
  const fs::path d = fresh_dir("sweep_cmd");
  // `output_dir` is a top-level key: it comes before the first section
  std::ofstream(d / "sweep.toml") << "output_dir = \"" << (d / "out").string() << "\"\n"
                                  << tiny_sweep();
  Exit e = run_ibrod({"sweep", (d / "sweep.toml").string(), "-j", "2"}, d / "log");
  ASSERT_EQ(e.code, 0) << e.output;
  for (const char* n :
       {"dlk=1_salt_M=0.05", "dlk=1_salt_M=0.1", "dlk=2_salt_M=0.05", "dlk=2_salt_M=0.1"})
    EXPECT_EQ(stop_reason(d / "out" / n), "end_time") << n;
  e = run_ibrod({"sweep", (d / "sweep.toml").string()}, d / "log2");
  EXPECT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("4 finished, 0 to run"));
  e = run_ibrod({"sweep", (d / "sweep.toml").string(), "--list"}, d / "log3");
  EXPECT_THAT(e.output, HasSubstr("dlk=2_salt_M=0.1"));
  EXPECT_THAT(e.output, HasSubstr("finished"));

  std::ofstream(d / "bad.toml") << "[sweep]\n\"rod.excess_lnk\" = [1, 2]\n";
  e = run_ibrod({"sweep", (d / "bad.toml").string()}, d / "log4");
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("rod.excess_lnk"));

  // a failing point: non-zero exit at the end, the failed point named
  std::ofstream(d / "fail.toml")
      << "output_dir = \"" << (d / "fail").string() << "\"\n"
      << "[grid]\nn = 16\nbox_A = 200\n[rod]\nbase_pairs = 100\nexcess_link = 2\n[time]\n"
         "t_end_us = 0.2\n[run]\nthreads = 1\nfftw_measure = false\n[sweep]\n\"time.dt_ns\" = "
         "[2.0, 0.1]\n";
  e = run_ibrod({"sweep", (d / "fail.toml").string(), "-j", "2"}, d / "log5");
  EXPECT_NE(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("point dt_ns=2 failed"));
  EXPECT_EQ(stop_reason(d / "fail" / "dt_ns=0.1"), "end_time");
  fs::remove_all(d);
}

TEST(SweepCommand, UnderMpirunTheRanksShareThePoints) {
  if (!sweep_command_wired()) GTEST_SKIP() << "`ibrod sweep` is not wired into app/main.cpp yet";
#ifndef IBROD_MPI
  GTEST_SKIP() << "built without MPI";
#else
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  const fs::path d = fresh_dir("sweep_mpi");
  std::ofstream(d / "sweep.toml") << "output_dir = \"" << (d / "out").string() << "\"\n"
                                  << tiny_sweep();
  // 2 local ranks (as root mpirun needs --allow-run-as-root; --oversubscribe: 2 cores or fewer)
  const int rc = std::system(("mpirun --allow-run-as-root --oversubscribe -np 2 " +
                              std::string(IBROD_BINARY) + " sweep " + (d / "sweep.toml").string() +
                              " > " + (d / "mpi.log").string() + " 2>&1")
                                 .c_str());
  const std::string log = read_file(d / "mpi.log");
  ASSERT_EQ(rc, 0) << log;
  EXPECT_THAT(log, HasSubstr("sweep[0]: 2 points (rank 0 of 2)"));
  EXPECT_THAT(log, HasSubstr("sweep[1]: 2 points (rank 1 of 2)"));
  EXPECT_THAT(log, HasSubstr("all ranks: 4 points, 4 finished now"));
  for (const char* n :
       {"dlk=1_salt_M=0.05", "dlk=1_salt_M=0.1", "dlk=2_salt_M=0.05", "dlk=2_salt_M=0.1"})
    EXPECT_EQ(stop_reason(d / "out" / n), "end_time") << n;
  fs::remove_all(d);
#endif
}

TEST(SweepRun, APointWrittenByAnotherProcessIsNotStartedAndNotCountedFinished) {
  // the orphaned run of a killed sweep still writes point 0 (here: this process holds its lock);
  // the rerun sweep must not start a second writer there, nor call the point finished
  const fs::path d = fresh_dir("sweep_locked");
  std::ofstream(d / "sweep.toml") << tiny_sweep();
  const driver::Sweep sw = driver::load_sweep(d / "sweep.toml");
  const fs::path root = d / "out";
  const fs::path point0 = root / sw.points[0].name;
  fs::create_directories(point0);
  std::ofstream(point0 / "timeseries.csv") << "step,time_us\n";  // the other writer's file
  {
    const driver::DirLock held(point0);
    EXPECT_EQ(driver::point_state(point0), driver::PointState::running);
    const driver::SweepReport r = driver::run_sweep(sw, options(root, 2));
    EXPECT_EQ(r.running, 1);
    EXPECT_EQ(r.completed, 3);
    EXPECT_EQ(r.failed, 0);
    EXPECT_EQ(read_file(point0 / "timeseries.csv"), "step,time_us\n");  // untouched
    EXPECT_FALSE(fs::exists(point0 / "summary.json"));
  }
  // once the other writer is gone the point is run like any interrupted or fresh one
  EXPECT_NE(driver::point_state(point0), driver::PointState::running);
  fs::remove_all(d);
}

TEST(SweepRun, PointKRunsThatPointAloneAndListNumbersThem) {
  // a scheduler's job array: `ibrod sweep SWEEP.toml --point K` per task
  const fs::path d = fresh_dir("sweep_point");
  std::ofstream(d / "sweep.toml") << tiny_sweep();
  const driver::Sweep sw = driver::load_sweep(d / "sweep.toml");
  const fs::path root = d / "out";
  const Exit list = run_ibrod({"sweep", (d / "sweep.toml").string(), "-o", root.string(), "--list"},
                              d / "list.log");
  ASSERT_EQ(list.code, 0) << list.output;
  EXPECT_THAT(list.output, ::testing::HasSubstr("   2  " + sw.points[2].name));
  const Exit one = run_ibrod(
      {"sweep", (d / "sweep.toml").string(), "-o", root.string(), "--point", "2"}, d / "one.log");
  ASSERT_EQ(one.code, 0) << one.output;
  for (std::size_t i = 0; i < sw.points.size(); ++i)
    EXPECT_EQ(driver::point_state(root / sw.points[i].name),
              i == 2 ? driver::PointState::finished : driver::PointState::fresh)
        << sw.points[i].name;
  // again: skipped as finished; a point that does not exist is refused
  const Exit again = run_ibrod(
      {"sweep", (d / "sweep.toml").string(), "-o", root.string(), "--point", "2"}, d / "again.log");
  EXPECT_EQ(again.code, 0);
  EXPECT_THAT(again.output, ::testing::HasSubstr("1 finished, 0 to run"));
  const Exit bad = run_ibrod(
      {"sweep", (d / "sweep.toml").string(), "-o", root.string(), "--point", "4"}, d / "bad.log");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_THAT(bad.output, ::testing::HasSubstr("--point 4"));
  fs::remove_all(d);
}
