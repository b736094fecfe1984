// Nothing lost outside the happy path ([no-data-lost-2], issue 26): the lock file is never
// written through a link, --overwrite deletes only what a run wrote, a run whose directory is
// deleted stops honestly, per-link files that are no regular file are refused at once, a changed
// per-link file or another run's checkpoint is not continued silently, a damaged final state is
// not drawn, triads with rows and columns swapped and rods on each other's periodic image are
// refused (by `check` too), a point another sweep started is `running`, and an extension that
// cannot be bitwise says so. Each test starts the real binary on the small configuration of
// helpers.hpp (S in the issue); T3-n names the item of the issue.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bounded_run.hpp"
#include "config/config.hpp"
#include "driver/dir_lock.hpp"
#include "driver/sweep_file.hpp"
#include "driver/sweep_runner.hpp"
#include "helpers.hpp"
#include "run_helpers.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

// 100 steps of 0.1 ns (about a second), a row and a frame every 50; one thread.
config::Config short_config() {
  config::Config c = small_config(2);
  c.time_t_end_us = 0.01;
  c.output_every_steps = 50;
  c.run_threads = 1;
  return c;
}

// A finished run of c in d/name.
fs::path finished_run(const fs::path& d, const config::Config& c, const std::string& name) {
  const fs::path cfg = write_config(d, c, name + ".toml");
  const fs::path out = d / name;
  const Exit e = run_ibrod({"run", cfg.string(), "-o", out.string()}, d / (name + ".log"));
  EXPECT_EQ(e.code, 0) << e.output;
  return out;
}

// Waits for a child at most `seconds`, then kills it (a run that goes on is a failure here).
Exit wait_at_most(const Child& c, double seconds, bool& hung) {
  const auto t0 = std::chrono::steady_clock::now();
  int st = 0;
  hung = false;
  while (::waitpid(c.pid, &st, WNOHANG) == 0) {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > seconds) {
      ::kill(c.pid, SIGKILL);
      ::waitpid(c.pid, &st, 0);
      hung = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  Exit e;
  if (WIFEXITED(st)) e.code = WEXITSTATUS(st);
  if (WIFSIGNALED(st)) e.signal = WTERMSIG(st);
  e.output = read_file(c.log);
  return e;
}

std::string toml_string(const fs::path& p) { return "\"" + p.string() + "\""; }

}  // namespace

// T3-1, T3-2: a FIFO blocked `check` and `run` for ever, /dev/zero was read until memory ran out,
// a directory read as "0 rows": each is refused before it is opened, naming the key.
TEST(PerLinkFiles, AFifoADeviceOrADirectoryIsRefusedAtOnceByCheckAndRun) {
  const fs::path d = fresh_dir("nd2_perlink");
  const fs::path fifo = d / "fifo.csv", dir = d / "dir.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  fs::create_directories(dir);
  const struct {
    fs::path path;
    std::string why;
  } cases[] = {{fifo, "not a regular file"},
               {"/dev/zero", "not a regular file"},
               {dir, "it is a directory"}};
  int i = 0;
  for (const char* key : {"rod.intrinsic_file", "rod.moduli_file"})
    for (const auto& k : cases) {
      const std::string set = std::string(key) + "=" + toml_string(k.path);
      for (const char* cmd : {"check", "run"}) {
        const fs::path out = d / ("out" + std::to_string(i++));
        std::vector<std::string> args{cmd, "--set", set};
        if (std::string(cmd) == "run") args.insert(args.end(), {"-o", out.string()});
        const BoundedExit e = run_bounded(args, d / "log", 20, kAddressSanitizer ? 0 : 1L << 30);
        EXPECT_FALSE(e.hung) << cmd << " " << set;
        EXPECT_EQ(e.code, 2) << cmd << " " << set << "\n" << e.output;
        EXPECT_THAT(e.output, HasSubstr(key)) << cmd << " " << set;
        EXPECT_THAT(e.output, HasSubstr(k.why)) << cmd << " " << set;
        EXPECT_FALSE(fs::exists(out / "config.toml")) << cmd << " " << set;
      }
    }
  fs::remove_all(d);
}

// T3-3: the lock file was opened through a symlink (the PID went into the link's target) and a
// file that was not ibrod's was truncated.
TEST(LockFile, ALinkOrAFileNotIbrodsInItsPlaceIsRefusedAndLeftUntouched) {
  const fs::path d = fresh_dir("nd2_lock");
  const config::Config c = short_config();
  const fs::path out = finished_run(d, c, "out");
  const fs::path victim = d / "v.txt";
  const std::string precious = "precious data\n";
  std::ofstream(victim) << precious;
  const auto resume = [&](const std::string& log) {
    return run_ibrod({"run", "--resume", out.string(), "--set", "time.t_end_us=0.02"}, d / log);
  };
  // a symbolic link: refused (resume and a fresh run with --overwrite), the target unchanged
  fs::remove(out / "ibrod.lock");
  fs::create_symlink(victim, out / "ibrod.lock");
  const Exit r1 = resume("r1.log");
  EXPECT_EQ(r1.code, 2) << r1.output;
  EXPECT_THAT(r1.output, HasSubstr("symbolic link"));
  const Exit r2 = run_ibrod({"run", (d / "out.toml").string(), "-o", out.string(), "--overwrite"},
                            d / "r2.log");
  EXPECT_EQ(r2.code, 2) << r2.output;
  EXPECT_EQ(read_file(victim), precious);
  EXPECT_TRUE(fs::exists(out / "summary.json"));  // --overwrite removed nothing
  // a hard link to the user's file, and a file of the user's under the lock's name: not truncated
  fs::remove(out / "ibrod.lock");
  fs::create_hard_link(victim, out / "ibrod.lock");
  const Exit r3 = resume("r3.log");
  EXPECT_EQ(r3.code, 2) << r3.output;
  EXPECT_EQ(read_file(victim), precious);
  fs::remove(out / "ibrod.lock");
  std::ofstream(out / "ibrod.lock") << precious;
  const Exit r4 = resume("r4.log");
  EXPECT_EQ(r4.code, 2) << r4.output;
  EXPECT_THAT(r4.output, HasSubstr("not ibrod's lock"));
  EXPECT_EQ(read_file(out / "ibrod.lock"), precious);
  // ibrod's own lock file (a PID of a dead process) is taken over as before
  std::ofstream(out / "ibrod.lock", std::ios::trunc) << "999999\n";
  const Exit r5 = resume("r5.log");
  EXPECT_EQ(r5.code, 0) << r5.output;
  fs::remove_all(d);
}

// T3-14: --overwrite deleted a file of the user's inside vtk/.
TEST(Overwrite, DeletesOnlyWhatARunWroteInVtk) {
  const fs::path d = fresh_dir("nd2_overwrite");
  config::Config c = short_config();
  c.time_t_end_us = 0.02;  // frames at steps 0, 50, 100, 150, 200
  const fs::path out = finished_run(d, c, "out");
  ASSERT_TRUE(fs::exists(out / "vtk" / "rod_000200.vtp"));
  std::ofstream(out / "vtk" / "notes.txt") << "mine\n";
  std::ofstream(out / "notes.txt") << "mine too\n";
  c.time_t_end_us = 0.01;  // a shorter run: frames 0, 50, 100
  const fs::path cfg = write_config(d, c, "shorter.toml");
  const Exit e = run_ibrod({"run", cfg.string(), "-o", out.string(), "--overwrite"}, d / "o.log");
  EXPECT_EQ(e.code, 0) << e.output;
  EXPECT_EQ(read_file(out / "vtk" / "notes.txt"), "mine\n");
  EXPECT_EQ(read_file(out / "notes.txt"), "mine too\n");
  EXPECT_TRUE(fs::exists(out / "vtk" / "rod_000100.vtp"));
  EXPECT_FALSE(fs::exists(out / "vtk" / "rod_000200.vtp"));  // the earlier run's frame is gone
  fs::remove_all(d);
}

// T3-15: a run whose directory was deleted wrote on into deleted files and at the end advised a
// --resume that cannot work.
TEST(DeletedDirectory, TheRunStopsWithExit3AndAnHonestMessage) {
  const fs::path d = fresh_dir("nd2_deleted");
  config::Config c = short_config();
  c.time_t_end_us = 5.0;  // far longer than the test
  c.output_every_steps = 20;
  const fs::path cfg = write_config(d, c, "c.toml");
  const fs::path out = d / "out";
  Child run = spawn({"run", cfg.string(), "-o", out.string()}, d / "run.log");
  ASSERT_TRUE(wait_for_lines(run, out / "timeseries.csv", 3)) << read_file(d / "run.log");
  // rm -rf while the run writes (a file may appear meanwhile: try again)
  std::error_code ec;
  for (int i = 0; i < 100 && fs::exists(out, ec); ++i) fs::remove_all(out, ec);
  bool hung = false;
  const Exit e = wait_at_most(run, 60, hung);
  EXPECT_FALSE(hung) << "the run went on writing into a deleted directory";
  EXPECT_EQ(e.code, 3) << e.output;
  EXPECT_THAT(e.output, HasSubstr("was deleted or moved"));
  EXPECT_THAT(e.output, Not(HasSubstr("continue with: ibrod run --resume")));
  fs::remove_all(d);
}

// T3-18: 100 000 [[rods]] tables took more than 150 s (quadratic): bounded.
TEST(SeveralRods, TooManyTablesAreRefusedAtOnce) {
  const fs::path d = fresh_dir("nd2_rods");
  std::string toml = "[rod]\nbase_pairs = 8\nexcess_link = 0\n";
  for (int i = 0; i < 100000; ++i) toml += "[[rods]]\n";
  std::ofstream(d / "many.toml") << toml;
  for (const char* cmd : {"check", "run"}) {
    std::vector<std::string> args{cmd, (d / "many.toml").string()};
    if (std::string(cmd) == "run") args.insert(args.end(), {"-o", (d / "o").string()});
    const BoundedExit e = run_bounded(args, d / "log", 20);
    EXPECT_FALSE(e.hung) << cmd;
    EXPECT_EQ(e.code, 2) << cmd << "\n" << e.output.substr(0, 2000);
    EXPECT_THAT(e.output, HasSubstr("at most 1000")) << cmd;
  }
  fs::remove_all(d);
}

// T3-4: after an edit of rod.moduli_file, --resume used the new values silently.
TEST(Resume, AChangedModuliFileIsAChangedKey) {
  const fs::path d = fresh_dir("nd2_moduli");
  const fs::path moduli = d / "moduli.csv";
  const auto write_moduli = [&](const std::string& first_a1) {
    std::ofstream f(moduli);
    for (int k = 0; k < 100; ++k)
      f << (k == 0 ? first_a1 : "1.3e-19") << ",1.3e-19,1.82e-19,5e-05,5e-05,5e-05\n";
  };
  write_moduli("1.3e-19");
  config::Config c = short_config();
  c.rod_moduli_file = moduli.string();
  const fs::path out = finished_run(d, c, "out");
  EXPECT_THAT(read_file(out / "config.toml"), HasSubstr("# input rod.moduli_file"));
  // unchanged: a later end time alone extends the run, no --force
  const Exit ext =
      run_ibrod({"run", "--resume", out.string(), "--set", "time.t_end_us=0.015"}, d / "ext.log");
  EXPECT_EQ(ext.code, 0) << ext.output;
  // changed: refused, listed like a key; with --force continued, listed in the warning
  write_moduli("1.5e-19");
  const Exit r =
      run_ibrod({"run", "--resume", out.string(), "--set", "time.t_end_us=0.02"}, d / "r.log");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("rod.moduli_file"));
  EXPECT_THAT(r.output, HasSubstr("CRC-32"));
  EXPECT_THAT(r.output, HasSubstr("--force"));
  const Exit f = run_ibrod(
      {"run", "--resume", out.string(), "--force", "--set", "time.t_end_us=0.02"}, d / "f.log");
  EXPECT_EQ(f.code, 0) << f.output;
  EXPECT_THAT(f.output, HasSubstr("changed configuration (--force): "));
  EXPECT_THAT(f.output, HasSubstr("rod.moduli_file"));
  fs::remove_all(d);
}

// T3-5: `ibrod render` drew a truncated final_state.csv as a 2-point blob, exit 0.
TEST(Render, ATruncatedFinalStateIsRefused) {
  const fs::path d = fresh_dir("nd2_render");
  const fs::path out = finished_run(d, short_config(), "out");
  const std::string whole = read_file(out / "final_state.csv");
  std::size_t cut = 0;
  for (int lines = 0; lines < 3; ++lines) cut = whole.find('\n', cut) + 1;  // header + 2 rows
  for (const std::string& part : {whole.substr(0, cut), whole.substr(0, whole.size() / 2)}) {
    std::ofstream(out / "final_state.csv", std::ios::trunc) << part;
    const Exit e = run_ibrod({"render", out.string(), "--size", "64x64", "--force"}, d / "r.log");
    EXPECT_EQ(e.code, 2) << e.output;
    EXPECT_THAT(e.output, HasSubstr("truncated or damaged"));
  }
  fs::remove_all(d);
}

// T3-11, T3-19: triads with rows and columns swapped passed rod.initial_shape (the run blew up
// at step 1, blaming Δt), and `ibrod check` did not read rod.initial_shape at all.
TEST(InitialShape, SwappedTriadsOrAWrongShapeAreRefusedByCheckAndRun) {
  const fs::path d = fresh_dir("nd2_shape");
  const fs::path out = finished_run(d, short_config(), "out");
  // the final state with each triad transposed (still orthonormal and right-handed)
  std::istringstream in(read_file(out / "final_state.csv"));
  std::string line;
  std::getline(in, line);
  std::ofstream swapped(d / "swapped.csv"), few(d / "few.csv");
  swapped << line << "\n";
  few << line << "\n";
  for (int row = 0; std::getline(in, line); ++row) {
    std::vector<std::string> v;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) v.push_back(f);
    ASSERT_EQ(v.size(), 12u);
    swapped << v[0] << "," << v[1] << "," << v[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) swapped << "," << v[3 + 3 * j + i];
    swapped << "\n";
    if (row < 50) few << line << "\n";
  }
  swapped.close();
  few.close();
  const struct {
    fs::path file;
    std::string says;
  } cases[] = {{d / "swapped.csv", "off the rod's tangent"}, {d / "few.csv", "50 positions"}};
  for (const auto& k : cases)
    for (const char* cmd : {"check", "run"}) {
      std::vector<std::string> args{cmd, write_config(d, short_config(), "c.toml").string(),
                                    "--set", "rod.initial_shape=" + toml_string(k.file)};
      if (std::string(cmd) == "run") args.insert(args.end(), {"-o", (d / "o").string()});
      const Exit e = run_ibrod(args, d / "log");
      EXPECT_EQ(e.code, 2) << cmd << " " << k.file << "\n" << e.output;
      EXPECT_THAT(e.output, HasSubstr("rod.initial_shape")) << cmd;
      EXPECT_THAT(e.output, HasSubstr(k.says)) << cmd;
      EXPECT_FALSE(fs::exists(d / "o" / "config.toml"));
    }
  fs::remove_all(d);
}

// T3-12: two rods on each other's periodic image ran through each other; T3-13: an overlap of
// initial shapes was refused with exit 1 (after config.toml was written) and passed by `check`.
TEST(SeveralRods, OverlapsAcrossTheBoxOrOfInitialShapesAreInputErrorsForCheckAndRun) {
  const fs::path d = fresh_dir("nd2_overlap");
  const fs::path one = finished_run(d, short_config(), "one");
  config::Config image = short_config();
  image.rods = {{{"excess_link", "2"}}, {{"offset_A", "[200.0, 0.0, 0.0]"}}};  // box 200 Å
  config::Config shapes = short_config();
  const std::string shape = toml_string(one / "final_state.csv");
  shapes.rods = {{{"initial_shape", shape}}, {{"initial_shape", shape}}};
  for (const auto& [c, name] : {std::pair{image, "image"}, std::pair{shapes, "shapes"}}) {
    const fs::path cfg = write_config(d, c, std::string(name) + ".toml");
    for (const char* cmd : {"check", "run"}) {
      std::vector<std::string> args{cmd, cfg.string()};
      const fs::path out = d / (std::string(name) + "_out");
      if (std::string(cmd) == "run") args.insert(args.end(), {"-o", out.string()});
      const Exit e = run_ibrod(args, d / "log");
      EXPECT_EQ(e.code, 2) << cmd << " " << name << "\n" << e.output;
      EXPECT_THAT(e.output, HasSubstr("overlap")) << cmd << " " << name;
      EXPECT_FALSE(fs::exists(out / "config.toml")) << name;
    }
  }
  const Exit e = run_ibrod({"check", (d / "image.toml").string()}, d / "log");
  EXPECT_THAT(e.output, HasSubstr("in the periodic box"));
  fs::remove_all(d);
}

// T3-16: a resume after timeseries.csv was deleted, or with another run's checkpoint, went on
// silently.
TEST(Resume, AMissingTimeSeriesIsSaidAndAnotherRunsCheckpointIsRefused) {
  const fs::path d = fresh_dir("nd2_other");
  const fs::path a = finished_run(d, short_config(), "a");
  const fs::path b = finished_run(d, short_config(), "b");  // the same configuration
  fs::remove(a / "timeseries.csv");
  const Exit r =
      run_ibrod({"run", "--resume", a.string(), "--set", "time.t_end_us=0.015"}, d / "r.log");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("timeseries.csv is missing"));
  // b's checkpoint copied into a: refused, even with --force; a's own files are left as they were
  fs::copy_file(b / "checkpoint.bin", a / "checkpoint.bin", fs::copy_options::overwrite_existing);
  const std::string summary = read_file(a / "summary.json");
  for (const bool force : {false, true}) {
    std::vector<std::string> args{"run", "--resume", a.string(), "--set", "time.t_end_us=0.02"};
    if (force) args.push_back("--force");
    const Exit o = run_ibrod(args, d / "o.log");
    EXPECT_EQ(o.code, 2) << o.output;
    EXPECT_THAT(o.output, HasSubstr("belongs to another run"));
  }
  EXPECT_EQ(read_file(a / "summary.json"), summary);
  fs::remove_all(d);
}

// T3-8: two sweeps on one directory called a healthy point FAILED when the other sweep started it
// between this one's look at the point and its start (a check-then-start race). The race made
// certain: the "binary" the sweep starts first lets another process take the point's lock.
TEST(Sweep, APointAnotherProcessStartedMeanwhileIsRunningNotFailed) {
  const fs::path d = fresh_dir("nd2_sweep");
  const fs::path root = d / "sweep_out";
  const driver::Sweep sw = driver::parse_sweep(
      small_config_toml(short_config()) + "\n[sweep]\n\"rod.excess_link\" = [1]\n", "s.toml", d);
  ASSERT_EQ(sw.points.size(), 1u);
  const fs::path point = driver::SweepDir{root}.run(sw.points[0].name);
  const fs::path holder_pid = d / "holder.pid";
  const fs::path fake = d / "ibrod-racing";
  {
    std::ofstream f(fake);
    f << "#!/bin/sh\n"
         "# another process takes the point first (and holds its lock), then the start goes on\n"
         "mkdir -p '"
      << point.string()
      << "'\n"
         "flock -n '"
      << (point / "ibrod.lock").string()
      << "' sleep 60 &\n"
         "echo $! > '"
      << holder_pid.string()
      << "'\n"
         "sleep 0.5\n"
         "exec '" IBROD_BINARY "' \"$@\"\n";
  }
  fs::permissions(fake, fs::perms::owner_all);
  driver::SweepOptions opt;
  opt.output_root = root;
  opt.binary = fake.string();
  opt.handle_signals = false;
  opt.log = nullptr;
  const driver::SweepReport rep = driver::run_sweep(sw, opt);
  EXPECT_EQ(rep.failed, 0);
  EXPECT_EQ(rep.running, 1);
  const std::string pid = read_file(holder_pid);
  if (!pid.empty()) ::kill(std::stoi(pid), SIGTERM);
  fs::remove_all(d);
}

// T3-17: an extension of an implicit run whose rows are counted in steps is not bit for bit the
// longer run (its last step was cut to land on the old end): it says so.
TEST(Extension, OfAnImplicitRunNotOnASimulatedTimeScheduleWarnsThatItIsNotBitwise) {
  const fs::path d = fresh_dir("nd2_ext");
  config::Config c = short_config();
  c.time_scheme = "implicit";
  c.time_dt_ns = 1;
  c.time_t_end_us = 0.0105;
  c.output_every_steps = 4;
  const fs::path by_steps = finished_run(d, c, "by_steps");
  const Exit e =
      run_ibrod({"run", "--resume", by_steps.string(), "--set", "time.t_end_us=0.02"}, d / "e.log");
  EXPECT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("is not bit for bit the uninterrupted longer run"));
  // rows every 0.0025 µs with the old end on a multiple: bitwise, no warning
  c.output_every_us = 0.0025;
  c.time_t_end_us = 0.01;
  const fs::path in_time = finished_run(d, c, "in_time");
  const Exit f =
      run_ibrod({"run", "--resume", in_time.string(), "--set", "time.t_end_us=0.02"}, d / "f.log");
  EXPECT_EQ(f.code, 0) << f.output;
  EXPECT_THAT(f.output, HasSubstr("extending the run"));
  EXPECT_THAT(f.output, Not(HasSubstr("not bit for bit")));
  fs::remove_all(d);
}
