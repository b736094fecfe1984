// `ibrod compare RUN_A RUN_B` end to end (issue 24 item 4) on two tiny real runs (16³, 100 bp,
// ΔLk = 2, 20 ns; about 0.3 s each): the explicit scheme with rows every 20 steps against the
// implicit scheme with rows every 0.004 µs. A run against itself: every difference zero, exit 0.
// Against the other: the numbers equal those computed here from the two timeseries.csv, exit 1
// under a tight --max-dwr and 0 under a loose one. Bad input (a missing directory, file or
// trajectory; no common time): exit 2 naming it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/run_dir.hpp"
#include "run_helpers.hpp"

using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

std::vector<std::string> tiny_run(const fs::path& out) {
  return {"run",
          "--set",
          "grid.n=16",
          "--set",
          "grid.box_A=200",
          "--set",
          "rod.base_pairs=100",
          "--set",
          "rod.excess_link=2",
          "--set",
          "time.t_end_us=0.02",
          "--set",
          "run.threads=1",
          "--set",
          "run.fftw_measure=false",
          "-o",
          out.string()};
}

/// The columns of a CSV file with a header row, read here independently of io::CsvTable.
struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  std::vector<double> col(const std::string& name) const {
    std::size_t k = 0;
    while (k < names.size() && names[k] != name) ++k;
    std::vector<double> v;
    for (const auto& r : rows) v.push_back(r.at(k));
    return v;
  }
};

Table read_table(const fs::path& p) {
  std::istringstream in(read_file(p));
  Table t;
  std::string line, f;
  std::getline(in, line);
  for (std::istringstream h(line); std::getline(h, f, ',');) t.names.push_back(f);
  while (std::getline(in, line)) {
    std::vector<double> r;
    for (std::istringstream s(line); std::getline(s, f, ',');) r.push_back(std::stod(f));
    t.rows.push_back(r);
  }
  return t;
}

nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(read_file(p)); }

}  // namespace

TEST(CompareCli, ARunAgainstItselfAndAgainstTheImplicitScheme) {
  const fs::path root = fresh_dir("compare");
  const fs::path a = root / "explicit", b = root / "implicit";
  auto args = tiny_run(a);
  args.insert(args.end(),
              {"--set", "output.every_steps=20", "--set", "output.frame_every_steps=40"});
  Exit e = run_ibrod(args, root / "a.log");
  ASSERT_EQ(e.code, 0) << e.output;
  args = tiny_run(b);
  args.insert(args.end(), {"--set", "time.scheme=\"implicit\"", "--set", "time.dt_ns=0.4", "--set",
                           "output.every_us=0.004", "--set", "output.frame_every_us=0.004"});
  e = run_ibrod(args, root / "b.log");
  ASSERT_EQ(e.code, 0) << e.output;

  // ---- a run against itself: all zero, every row common, exit 0
  e = run_ibrod({"compare", a.string(), a.string(), "--max-dwr", "0", "--max-de", "0", "--json",
                 (root / "self.json").string()},
                root / "self.log");
  EXPECT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("compare: common_rows=11 common_frames=6 max_dWr=0 at t=0 "
                                  "max_dE_kT=0 at t=0 final_t=0.02 final_dWr=0 final_dE_kT=0 "
                                  "max_dclosest_A=0 at t=0 shape_mismatches=0 guarded=0"));
  EXPECT_THAT(e.output, HasSubstr("compare: PASS"));
  nlohmann::json j = read_json(root / "self.json");
  EXPECT_EQ(j["common_rows"], 11);
  for (const char* k : {"max_abs_dWr", "max_abs_dE_total_kT", "max_abs_dclosest_approach_A",
                        "final_dWr", "final_dE_total_kT"})
    EXPECT_EQ(j[k].get<double>(), 0.0) << k;
  EXPECT_EQ(j["passed"], true);
  ASSERT_EQ(j["frames"].size(), 6u);
  for (const auto& f : j["frames"]) {
    EXPECT_EQ(f["class_a"], f["class_b"]);
    EXPECT_EQ(f["flag"], "same");
  }

  // ---- explicit (rows every 0.002 µs) against implicit (every 0.004 µs), no limit: exit 0
  e = run_ibrod({"compare", a.string(), b.string(), "--json", (root / "ab.json").string()},
                root / "ab.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("class/loops_A"));  // the table
  EXPECT_THAT(e.output, HasSubstr("circle/1"));
  j = read_json(root / "ab.json");

  // the same numbers from the two timeseries.csv, computed here
  const Table ta = read_table(a / "timeseries.csv"), tb = read_table(b / "timeseries.csv");
  const auto t_a = ta.col("time_us"), t_b = tb.col("time_us");
  const auto w_a = ta.col("writhe"), w_b = tb.col("writhe");
  const auto e_a = ta.col("E_total_kT"), e_b = tb.col("E_total_kT");
  const auto d_a = ta.col("closest_approach_A"), d_b = tb.col("closest_approach_A");
  ASSERT_EQ(t_a.size(), 11u);
  ASSERT_EQ(t_b.size(), 6u);
  std::size_t common = 0;
  double max_dwr = 0, max_de = 0, max_dd = 0, final_dwr = 0, final_de = 0, t_dwr = 0;
  for (std::size_t i = 0; i < t_a.size(); ++i)
    for (std::size_t k = 0; k < t_b.size(); ++k)
      if (std::abs(t_a[i] - t_b[k]) <= 1e-6) {
        ++common;
        if (std::abs(w_b[k] - w_a[i]) > max_dwr) {
          max_dwr = std::abs(w_b[k] - w_a[i]);
          t_dwr = t_a[i];
        }
        max_de = std::max(max_de, std::abs(e_b[k] - e_a[i]));
        max_dd = std::max(max_dd, std::abs(d_b[k] - d_a[i]));
        final_dwr = w_b[k] - w_a[i];
        final_de = e_b[k] - e_a[i];
      }
  EXPECT_EQ(common, 6u);  // every implicit row lands on an explicit one
  EXPECT_EQ(j["common_rows"], common);
  EXPECT_GT(max_dwr, 1e-7);  // the schemes differ (measured 3.1e-5)
  EXPECT_GT(max_de, 1e-3);   // (measured 0.14 kT)
  EXPECT_DOUBLE_EQ(j["max_abs_dWr"].get<double>(), max_dwr);
  EXPECT_DOUBLE_EQ(j["max_abs_dWr_time_us"].get<double>(), t_dwr);
  EXPECT_DOUBLE_EQ(j["max_abs_dE_total_kT"].get<double>(), max_de);
  EXPECT_DOUBLE_EQ(j["max_abs_dclosest_approach_A"].get<double>(), max_dd);
  EXPECT_DOUBLE_EQ(j["final_dWr"].get<double>(), final_dwr);
  EXPECT_DOUBLE_EQ(j["final_dE_total_kT"].get<double>(), final_de);
  EXPECT_NEAR(j["final_time_us"].get<double>(), 0.02, 1e-12);
  EXPECT_TRUE(j["passed"].is_null());
  EXPECT_EQ(j["frames"].size(), 6u);  // frames every 0.004 µs in both
  EXPECT_EQ(j["shape_mismatches"], 0);

  // a tight --max-dwr: exit 1, and the failure says by how much; a loose one: exit 0
  char tight[32], loose[32];
  std::snprintf(tight, sizeof tight, "%.3g", max_dwr / 2);
  std::snprintf(loose, sizeof loose, "%.3g", max_dwr * 2);
  e = run_ibrod({"compare", a.string(), b.string(), "--max-dwr", tight, "-q"}, root / "tight.log");
  EXPECT_EQ(e.code, 1) << e.output;
  EXPECT_THAT(e.output, HasSubstr("compare: FAIL: max |dWr| = "));
  EXPECT_THAT(e.output, HasSubstr(std::string("> --max-dwr ") + tight));
  EXPECT_THAT(e.output, ::testing::Not(HasSubstr("class/loops_A")));  // -q: no table
  e = run_ibrod({"compare", a.string(), b.string(), "--max-dwr", loose, "--max-final-de", "1"},
                root / "loose.log");
  EXPECT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("compare: PASS"));

  // ---- bad input: exit 2, naming what is missing
  e = run_ibrod({"compare", a.string(), (root / "nowhere").string()}, root / "bad1.log");
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr((root / "nowhere").string()));
  // no trajectory: named through io::RunDir (whatever the file is called)
  const fs::path c = root / "no_frames";
  fs::copy(a, c, fs::copy_options::recursive);
  const fs::path traj = ibrod::io::RunDir(c).trajectory();
  fs::remove(traj);
  e = run_ibrod({"compare", a.string(), c.string()}, root / "bad2.log");
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr(traj.string()));
  // no common time: every row of a copy moved by 0.001 µs
  const fs::path d = root / "shifted";
  fs::copy(a, d, fs::copy_options::recursive);
  {
    std::ostringstream out;
    out << "step,time_us,E_total_kT,writhe,closest_approach_A\n";
    for (std::size_t i = 0; i < t_a.size(); ++i)
      out << i << "," << t_a[i] + 0.001 << "," << e_a[i] << "," << w_a[i] << "," << d_a[i] << "\n";
    std::ofstream(d / "timeseries.csv") << out.str();
  }
  e = run_ibrod({"compare", a.string(), d.string()}, root / "bad3.log");
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("no common time"));
  EXPECT_THAT(e.output, HasSubstr((d / "timeseries.csv").string()));
  fs::remove(d / "timeseries.csv");
  e = run_ibrod({"compare", d.string(), a.string()}, root / "bad4.log");
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr((d / "timeseries.csv").string()));
  fs::remove_all(root);
}
