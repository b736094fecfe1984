// Odd inputs to `ibrod run` (issue 13 items 7 and 9): CONFIG paths that are not a readable
// regular file, control characters in --set, huge values echoed in messages, messages that must
// name the right key, and a grid larger than the memory the process may allocate.
#include <sys/stat.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <new>

#include "../../app/exit_status.hpp"
#include "bounded_run.hpp"

using namespace ibrod::test;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(OddInputs, ConfigPathsThatAreNotReadableFilesExit2WithTheReason) {
  const fs::path d = fresh_dir("odd_paths");
  const fs::path fifo = d / "fifo.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  fs::create_directories(d / "dir.toml");
  const struct {
    std::string path, reason;
  } cases[] = {
      {(d / "dir.toml").string(), "it is a directory"},
      {"", "the path is empty"},
      {fifo.string(), "not a regular file"},  // opening it would block forever
      {"/dev/null", "not a regular file"},
      {(d / "missing.toml").string(), "does not exist"},
  };
  for (const char* cmd : {"run", "check"}) {
    for (const auto& c : cases) {
      std::vector<std::string> args{cmd, c.path};
      if (std::string(cmd) == "run") args.insert(args.end(), {"-o", (d / "out").string()});
      const BoundedExit e = run_bounded(args, d / "log", 10);
      EXPECT_FALSE(e.hung) << cmd << " '" << c.path << "'";
      EXPECT_EQ(e.code, 2) << cmd << " '" << c.path << "'\n" << e.output;
      EXPECT_THAT(e.output, HasSubstr(c.reason)) << cmd << " '" << c.path << "'";
      EXPECT_THAT(e.output, Not(HasSubstr("resolved configuration"))) << "defaults were used";
    }
  }
  EXPECT_FALSE(fs::exists(d / "out"));
  fs::remove_all(d);
}

TEST(OddInputs, AnUnreadableConfigSaysPermissionDenied) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files whatever their mode";
  const fs::path d = fresh_dir("odd_perm");
  const fs::path f = d / "secret.toml";
  std::ofstream(f) << "[grid]\nn = 16\n";
  fs::permissions(f, fs::perms::none);
  const BoundedExit e = run_bounded({"check", f.string()}, d / "log", 10);
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("Permission denied"));
  fs::remove_all(d);
}

TEST(OddInputs, ControlCharactersInSetValuesAreRefused) {
  const fs::path d = fresh_dir("odd_ctl");
  // before: TOML read "v = 16" and a second key on the next line, and the rest was dropped
  for (const std::string& set :
       std::vector<std::string>{"grid.n=16\nrod.base_pairs=8", "grid.n=16\n", "grid.n=\t16",
                                "grid.n=16\x01", "grid.n=1\r6"}) {
    const BoundedExit e = run_bounded({"check", "--set", set}, d / "log", 10);
    EXPECT_EQ(e.code, 2) << e.output;
    EXPECT_THAT(e.output, HasSubstr("control characters")) << e.output;
    EXPECT_THAT(e.output, HasSubstr("grid.n")) << e.output;
  }
  fs::remove_all(d);
}

TEST(OddInputs, EchoedValuesAreCapped) {
  const fs::path d = fresh_dir("odd_long");
  const std::string huge(1 << 20, 'a');
  std::ofstream(d / "huge.toml") << "[grid]\nn = \"" << huge << "\"\n";
  BoundedExit e = run_bounded({"check", (d / "huge.toml").string()}, d / "log", 20);
  EXPECT_EQ(e.code, 2);
  EXPECT_THAT(e.output, HasSubstr("grid.n"));
  EXPECT_THAT(e.output, HasSubstr("…"));
  EXPECT_LT(e.output.size(), 2000u) << "a 1 MB value gave a message of " << e.output.size();
  // argv strings are limited to 128 KiB (MAX_ARG_STRLEN): a 100 KB key and value
  const std::string long_value(100000, '7');
  for (const std::string& set :
       std::vector<std::string>{"grid.n=" + long_value, "grid." + huge.substr(0, 100000) + "=1",
                                "grid.n=\"" + long_value}) {
    e = run_bounded({"check", "--set", set}, d / "log", 20);
    EXPECT_EQ(e.code, 2);
    EXPECT_LT(e.output.size(), 2000u) << set.substr(0, 20) << ": " << e.output.size();
  }
  fs::remove_all(d);
}

TEST(OddInputs, MessagesNameTheKeyAtFault) {
  const fs::path d = fresh_dir("odd_key");
  BoundedExit e = run_bounded({"check", "--set", "grid.n.x=1"}, d / "log", 10);
  EXPECT_EQ(e.code, 2);
  EXPECT_THAT(e.output, HasSubstr("unknown key 'grid.n.x'"));  // before: "grid.n = x = 1"
  e = run_bounded({"check", "--set", "steric.diameter_A=100"}, d / "log", 10);
  EXPECT_EQ(e.code, 2);
  EXPECT_THAT(e.output, HasSubstr("steric.diameter_A = 100 is invalid"));  // before: grid.box_A
  // the ring itself too large for the box: the box is named, with the ring's keys
  e = run_bounded({"check", "--set", "grid.box_A=600"}, d / "log", 10);
  EXPECT_EQ(e.code, 2);
  EXPECT_THAT(e.output, HasSubstr("grid.box_A = 600 is invalid"));
  EXPECT_THAT(e.output, HasSubstr("rod.base_pairs"));
  // a sub-key of the one table-valued key still works
  e = run_bounded({"check", "--set", "rod.perturbation_random.seed=7"}, d / "log", 10);
  EXPECT_EQ(e.code, 0) << e.output;
  fs::remove_all(d);
}

// Item 7: before, `run --set grid.n=512` under a 2 GiB address-space limit died with exit 1 and
// "std::bad_alloc"; now it is refused before anything is allocated, naming grid.n and the need.
TEST(OddInputs, AGridLargerThanTheMemoryAllowedIsRefusedBeforeAllocation) {
  if (kAddressSanitizer) GTEST_SKIP() << "an ASan binary cannot start under RLIMIT_AS";
  const fs::path d = fresh_dir("odd_mem");
  const long two_gib = 2L << 30;
  const BoundedExit e = run_bounded({"run", "--set", "grid.n=512", "-o", (d / "out").string()},
                                    d / "log", 60, two_gib);
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("grid.n = 512"));
  EXPECT_THAT(e.output, HasSubstr("MiB"));
  EXPECT_THAT(e.output, HasSubstr("RLIMIT_AS"));
  EXPECT_THAT(e.output, Not(HasSubstr("bad_alloc")));
  EXPECT_FALSE(fs::exists(d / "out" / "timeseries.csv"));
  // the same config fits without the limit on any machine with 10 GiB; `check` only warns
  const BoundedExit c = run_bounded({"check", "--set", "grid.n=512"}, d / "log", 20, two_gib);
  EXPECT_EQ(c.code, 0) << c.output;
  EXPECT_THAT(c.output, HasSubstr("# warning: `ibrod run` here would refuse"));
  fs::remove_all(d);
}

TEST(OddInputs, OutOfMemoryIsNeverABareBadAlloc) {
  testing::internal::CaptureStderr();
  const int rc = ibrod::app::report_error(std::bad_alloc());
  const std::string msg = testing::internal::GetCapturedStderr();
  EXPECT_EQ(rc, 3);
  EXPECT_THAT(msg, HasSubstr("out of memory"));
  EXPECT_THAT(msg, HasSubstr("grid.n"));
}
