// The comparison of two runs (analysis/compare.hpp) on constructed series and frames: common
// times of rows written by steps (a sum of Δt) and by simulated time, known maxima and final
// differences (B − A), rows of one run only and undefined values ignored, a rewritten stretch's
// later rows win, the guard rule for shape changes, the verdict against limits, the printed
// summary and the JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/compare.hpp"
#include "core/error.hpp"

namespace ibrod::analysis {
namespace {

using diagnostics::ShapeClass;

ShapeRecord shape_at(double t, ShapeClass cls, int loops) {
  ShapeRecord r;
  r.time_us = t;
  r.shape.cls = cls;
  r.shape.loops = loops;
  return r;
}

/// A series with Wr = w(t), E = e(t), closest approach = d(t) at the given times.
template <class W, class E, class D>
RunSeries series(const std::vector<double>& t, W w, E e, D d) {
  RunSeries s;
  for (double x : t) {
    s.time_us.push_back(x);
    s.writhe.push_back(w(x));
    s.E_total_kT.push_back(e(x));
    s.closest_approach_A.push_back(d(x));
  }
  return s;
}

TEST(Compare, CommonTimesOfRowsByStepsAndByMicroseconds) {
  // A: the explicit scheme's rows every 10 steps of 0.1 ns, its time a running sum of Δt (not
  // exactly k·0.001 µs); B: the implicit scheme's rows every 0.004 µs (output.every_us), which
  // land on the multiples, plus a row 2e-6 µs off a multiple (no match) and one 5e-7 off (match)
  std::vector<double> ta;
  double t = 0;
  for (int step = 0; step <= 200; ++step) {
    if (step % 10 == 0) ta.push_back(t);
    t += 1e-4;
  }
  ASSERT_NE(ta[20], 0.02);  // the sum is off the decimal value by round-off
  ASSERT_NEAR(ta[20], 0.02, 1e-15);
  std::vector<double> tb;
  for (int k = 0; k <= 5; ++k) tb.push_back(0.004 * k);
  tb.push_back(0.021 + 2e-6);
  tb.push_back(0.022 - 5e-7);  // beyond A's last row (0.02)
  const auto pairs = common_times(ta, tb, 1e-6);
  ASSERT_EQ(pairs.size(), 6u);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_EQ(pairs[k].first, 4 * k) << k;
    EXPECT_EQ(pairs[k].second, k) << k;
  }
  // within the tolerance on either side; each row in one pair at most
  const std::vector<double> a{1.0, 2.0, 3.0}, b{1.0 - 5e-7, 1.0 + 5e-7, 2.0 + 2e-6, 3.0 + 9e-7};
  const auto p = common_times(a, b, 1e-6);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0], (std::pair<std::size_t, std::size_t>{0, 0}));
  EXPECT_EQ(p[1], (std::pair<std::size_t, std::size_t>{2, 3}));
}

TEST(Compare, KnownMaximaAndFinalDifferencesOverTheCommonRowsOnly) {
  // A every 0.1 µs, B every 0.25 µs: common rows at 0, 0.5, 1.0, …, 3.0 (7 of them)
  std::vector<double> ta, tb;
  for (int k = 0; k <= 30; ++k) ta.push_back(0.1 * k);
  for (int k = 0; k <= 12; ++k) tb.push_back(0.25 * k);
  const auto wa = [](double x) { return x; };
  const auto ea = [](double x) { return 400 - x; };
  const auto da = [](double) { return 60.0; };
  // B's writhe: A's + 0.3 at 1.5 µs, − 0.2 at 2.5, + 0.05 at 3.0, and + 9 at 0.25 µs, a row A
  // does not have (ignored); its energy + 0.8 kT from 2 µs on, − 1.1 at 0.5; closest approach
  // − 4 Å at 1.0
  RunSeries a = series(ta, wa, ea, da);
  RunSeries b = series(
      tb,
      [&](double x) {
        return wa(x) + (std::abs(x - 1.5) < 1e-9    ? 0.3
                        : std::abs(x - 2.5) < 1e-9  ? -0.2
                        : std::abs(x - 3.0) < 1e-9  ? 0.05
                        : std::abs(x - 0.25) < 1e-9 ? 9.0
                                                    : 0.0);
      },
      [&](double x) {
        return ea(x) + (x > 1.99 ? 0.8 : std::abs(x - 0.5) < 1e-9 ? -1.1 : 0.0);
      },
      [&](double x) { return da(x) - (std::abs(x - 1.0) < 1e-9 ? 4.0 : 0.0); });
  // an undefined writhe at a common row (NaN: an open rod's empty field) is skipped
  a.writhe[5] = std::numeric_limits<double>::quiet_NaN();  // t = 0.5
  const Comparison c = compare_runs(a, b, {}, {});
  EXPECT_EQ(c.rows_a, 31u);
  EXPECT_EQ(c.rows_b, 13u);
  EXPECT_EQ(c.common_rows, 7u);
  EXPECT_NEAR(c.max_abs_dwr, 0.3, 1e-12);
  EXPECT_NEAR(c.max_abs_dwr_time_us, 1.5, 1e-12);
  EXPECT_NEAR(c.max_abs_de_kT, 1.1, 1e-12);
  EXPECT_NEAR(c.max_abs_de_time_us, 0.5, 1e-12);
  EXPECT_NEAR(c.max_abs_dclosest_A, 4.0, 1e-12);
  EXPECT_NEAR(c.max_abs_dclosest_time_us, 1.0, 1e-12);
  EXPECT_NEAR(c.final_time_us, 3.0, 1e-12);
  EXPECT_NEAR(c.final_dwr, 0.05, 1e-12);  // signed, B − A
  EXPECT_NEAR(c.final_de_kT, 0.8, 1e-12);
  EXPECT_FALSE(c.shapes_compared);  // no frames given

  // a run compared with itself: all zero
  const Comparison self = compare_runs(b, b, {}, {});
  EXPECT_EQ(self.common_rows, 13u);
  EXPECT_EQ(self.max_abs_dwr, 0.0);
  EXPECT_EQ(self.max_abs_de_kT, 0.0);
  EXPECT_EQ(self.final_dwr, 0.0);

  // no common time: an error that names both spans
  RunSeries late = a;
  for (double& x : late.time_us) x += 0.01;
  try {
    compare_runs(late, b, {}, {});
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("no common time"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("31 rows"), std::string::npos) << e.what();
  }
}

TEST(Compare, ARewrittenStretchKeepsItsLaterRows) {
  // a run continued from an earlier checkpoint appends rows it had written: the later ones win
  io::CsvTable t;
  t.path = "x/timeseries.csv";
  t.names = {"step", "time_us", "E_total_kT", "writhe", "closest_approach_A"};
  t.columns = {{0, 1, 2, 3, 2, 3, 4},
               {0, 0.1, 0.2, 0.3, 0.2, 0.3, 0.4},
               {10, 9, 8, 7, 8.5, 7.5, 6.5},
               {0, 0.1, 0.2, 0.3, 0.25, 0.35, 0.45},
               {60, 60, 60, 60, 60, 60, 60}};
  const RunSeries s = run_series(t);
  EXPECT_EQ(s.time_us, (std::vector<double>{0, 0.1, 0.2, 0.3, 0.4}));
  EXPECT_EQ(s.writhe, (std::vector<double>{0, 0.1, 0.25, 0.35, 0.45}));
  EXPECT_EQ(s.E_total_kT, (std::vector<double>{10, 9, 8.5, 7.5, 6.5}));
  // a missing column names the file
  t.names[3] = "wr";
  try {
    run_series(t);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("x/timeseries.csv"), std::string::npos) << e.what();
  }
}

TEST(Compare, ShapeDifferencesNearAChangeInEitherRunAreGuarded) {
  // frames every 0.2 µs to 10 µs. A: circle/1, figure-8/2 from 5.0, plectonemic/2 from 7.0.
  // B: circle/1, figure-8/2 from 5.8 (0.8 µs late), plectonemic/2 from 7.0, then plectonemic/3
  // from 9.0 while A stays at 2 loops
  std::vector<ShapeRecord> fa, fb;
  std::vector<double> t;
  for (int k = 0; k <= 50; ++k) {
    const double x = 0.2 * k;
    t.push_back(x);
    fa.push_back(x < 5.0 - 1e-9   ? shape_at(x, ShapeClass::circle, 1)
                 : x < 7.0 - 1e-9 ? shape_at(x, ShapeClass::figure8, 2)
                                  : shape_at(x, ShapeClass::plectonemic, 2));
    fb.push_back(x < 5.8 - 1e-9   ? shape_at(x, ShapeClass::circle, 1)
                 : x < 7.0 - 1e-9 ? shape_at(x, ShapeClass::figure8, 2)
                 : x < 9.0 - 1e-9 ? shape_at(x, ShapeClass::plectonemic, 2)
                                  : shape_at(x, ShapeClass::plectonemic, 3));
  }
  // the changes are dated at the first frame that shows the new shape
  const auto ca = shape_changes(fa), cb = shape_changes(fb);
  ASSERT_EQ(ca.size(), 2u);
  EXPECT_NEAR(ca[0], 5.0, 1e-12);
  EXPECT_NEAR(ca[1], 7.0, 1e-12);
  ASSERT_EQ(cb.size(), 3u);
  EXPECT_NEAR(cb[0], 5.8, 1e-12);
  EXPECT_NEAR(cb[2], 9.0, 1e-12);

  const RunSeries s = series(
      t, [](double) { return 0.0; }, [](double) { return 1.0; }, [](double) { return 1.0; });
  const auto flagged = [](const Comparison& c, FrameFlag f) {
    std::vector<double> times;
    for (const auto& fr : c.frames)
      if (fr.flag == f) times.push_back(std::round(fr.time_us * 10) / 10);
    return times;
  };
  // guard 0.5 µs: 5.0–5.6 differ, each within 0.5 of A's change at 5.0 or B's at 5.8; 9.0–9.4
  // within 0.5 of B's change at 9.0; 9.6–10.0 are mismatches
  CompareOptions opt;
  opt.guard_us = 0.5;
  Comparison c = compare_runs(s, s, fa, fb, opt);
  EXPECT_TRUE(c.shapes_compared);
  EXPECT_EQ(c.frames.size(), 51u);
  EXPECT_EQ(flagged(c, FrameFlag::guarded),
            (std::vector<double>{5.0, 5.2, 5.4, 5.6, 9.0, 9.2, 9.4}));
  EXPECT_EQ(flagged(c, FrameFlag::mismatch), (std::vector<double>{9.6, 9.8, 10.0}));
  EXPECT_EQ(c.shape_guarded, 7u);
  EXPECT_EQ(c.shape_mismatches, 3u);
  EXPECT_EQ(c.frames[26].class_a, ShapeClass::figure8);  // t = 5.2
  EXPECT_EQ(c.frames[26].class_b, ShapeClass::circle);
  // guard 0.1 µs: only the frames at a change (5.0, 9.0) are guarded
  opt.guard_us = 0.1;
  c = compare_runs(s, s, fa, fb, opt);
  EXPECT_EQ(flagged(c, FrameFlag::guarded), (std::vector<double>{5.0, 9.0}));
  EXPECT_EQ(flagged(c, FrameFlag::mismatch),
            (std::vector<double>{5.2, 5.4, 5.6, 9.2, 9.4, 9.6, 9.8, 10.0}));
  // guard 1 µs: everything is within a guard
  opt.guard_us = 1.0;
  c = compare_runs(s, s, fa, fb, opt);
  EXPECT_EQ(c.shape_mismatches, 0u);
  EXPECT_EQ(c.shape_guarded, 10u);

  // only frames at common times are compared: B's frames every 0.4 µs, at every other time of
  // A's; its changes date from its own frames (the figure-8 first at 6.0, 3 loops at 9.2)
  std::vector<ShapeRecord> sparse;
  for (std::size_t k = 0; k < fb.size(); k += 2) sparse.push_back(fb[k]);
  opt.guard_us = 0.5;
  c = compare_runs(s, s, fa, sparse, opt);
  EXPECT_EQ(c.frames.size(), 26u);
  ASSERT_EQ(c.changes_b.size(), 3u);
  EXPECT_NEAR(c.changes_b[0], 6.0, 1e-12);
  EXPECT_EQ(flagged(c, FrameFlag::guarded), (std::vector<double>{5.2, 5.6, 9.2, 9.6}));
  EXPECT_EQ(flagged(c, FrameFlag::mismatch), (std::vector<double>{10.0}));
}

TEST(Compare, VerdictAgainstTheLimits) {
  const std::vector<double> t{0, 1, 2};
  const RunSeries a = series(
      t, [](double x) { return x; }, [](double) { return 100.0; }, [](double) { return 50.0; });
  const RunSeries b = series(
      t, [](double x) { return x + 0.1 * x; }, [](double x) { return 100.0 + 0.3 * (2 - x); },
      [](double) { return 50.0; });
  std::vector<ShapeRecord> fa{shape_at(0, ShapeClass::circle, 1),
                              shape_at(2, ShapeClass::circle, 1)};
  std::vector<ShapeRecord> fb{shape_at(0, ShapeClass::circle, 1),
                              shape_at(2, ShapeClass::figure8, 2)};
  CompareOptions opt;
  opt.guard_us = 0.5;
  const Comparison c = compare_runs(a, b, fa, fb, opt);
  EXPECT_NEAR(c.max_abs_dwr, 0.2, 1e-12);
  EXPECT_NEAR(c.max_abs_de_kT, 0.6, 1e-12);
  EXPECT_NEAR(c.final_de_kT, 0.0, 1e-12);
  EXPECT_EQ(c.shape_guarded, 1u);  // B changes at 2: within the guard of its own change
  EXPECT_EQ(c.shape_mismatches, 0u);

  // no limit: no verdict, whatever the numbers
  EXPECT_TRUE(compare_failures(c, {}).empty());
  CompareLimits lim;
  lim.max_dwr = 0.25;
  lim.max_final_de_kT = 0.5;
  EXPECT_TRUE(compare_failures(c, lim).empty());
  lim.max_de_kT = 0.5;  // max |dE| 0.6 at t = 0
  auto f = compare_failures(c, lim);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NE(f[0].find("--max-de 0.5"), std::string::npos) << f[0];
  lim = {};
  lim.max_dwr = 0.1;
  f = compare_failures(c, lim);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NE(f[0].find("0.2 at t = 2 us > --max-dwr 0.1"), std::string::npos) << f[0];

  // a shape mismatch fails any limit: with no guard, B's change at 2 is one
  opt.guard_us = 0;
  const std::vector<ShapeRecord> late{shape_at(0, ShapeClass::circle, 1),
                                      shape_at(1.5, ShapeClass::figure8, 2),
                                      shape_at(2, ShapeClass::figure8, 2)};
  const Comparison m = compare_runs(a, b, fa, late, opt);
  EXPECT_EQ(m.shape_mismatches, 1u);
  lim = {};
  lim.max_dwr = 1;
  f = compare_failures(m, lim);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NE(f[0].find("t = 2 us"), std::string::npos) << f[0];
  // an undefined maximum (no writhe: open rods) fails its limit
  RunSeries open = a;
  for (double& w : open.writhe) w = std::numeric_limits<double>::quiet_NaN();
  const Comparison o = compare_runs(open, open, {}, {});
  EXPECT_TRUE(std::isnan(o.max_abs_dwr));
  EXPECT_EQ(compare_failures(o, lim).size(), 1u);
  // both runs have frames, but none at a common time: the shapes were not checked
  const std::vector<ShapeRecord> off{shape_at(0.5, ShapeClass::circle, 1)};
  const Comparison apart = compare_runs(a, b, fa, off, CompareOptions{});
  EXPECT_FALSE(apart.shapes_compared);
  EXPECT_EQ(compare_failures(apart, lim).size(), 1u);
}

TEST(Compare, SummaryTableAndJson) {
  const std::vector<double> t{0, 1, 2};
  const RunSeries a = series(
      t, [](double x) { return x; }, [](double) { return 100.0; }, [](double) { return 50.0; });
  const RunSeries b = series(
      t, [](double x) { return 1.5 * x; }, [](double x) { return 100.0 - x; },
      [](double) { return 49.0; });
  // a frame at 1.5 µs in both runs, where neither wrote a row: "-" in the table, null in JSON
  const std::vector<ShapeRecord> fa{shape_at(0, ShapeClass::circle, 1),
                                    shape_at(1.5, ShapeClass::circle, 1),
                                    shape_at(2, ShapeClass::circle, 1)};
  const std::vector<ShapeRecord> fb{shape_at(0, ShapeClass::circle, 1),
                                    shape_at(1.5, ShapeClass::circle, 1),
                                    shape_at(2, ShapeClass::toroidal, 3)};
  const Comparison c = compare_runs(a, b, fa, fb, CompareOptions{});
  EXPECT_EQ(compare_summary(c),
            "compare: common_rows=3 common_frames=3 max_dWr=1 at t=2 max_dE_kT=2 at t=2 "
            "final_t=2 final_dWr=1 final_dE_kT=-2 max_dclosest_A=1 at t=0 shape_mismatches=0 "
            "guarded=1");
  const std::string table = compare_table(c);
  EXPECT_NE(table.find("circle/1"), std::string::npos) << table;
  EXPECT_NE(table.find("toroidal/3"), std::string::npos) << table;
  EXPECT_NE(table.find("guard"), std::string::npos) << table;
  EXPECT_NE(table.find("       1.5         -         -"), std::string::npos) << table;
  CompareLimits lim;
  lim.max_dwr = 0.5;
  const auto failures = compare_failures(c, lim);
  const auto j = nlohmann::json::parse(compare_json(c, lim, failures));
  EXPECT_EQ(j["common_rows"], 3);
  EXPECT_DOUBLE_EQ(j["max_abs_dWr"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["final_dE_total_kT"].get<double>(), -2.0);
  EXPECT_EQ(j["passed"], false);
  EXPECT_EQ(j["limits"]["max_dwr"], 0.5);
  EXPECT_TRUE(j["limits"]["max_de_kT"].is_null());
  ASSERT_EQ(j["frames"].size(), 3u);
  EXPECT_TRUE(j["frames"][1]["writhe_a"].is_null());
  EXPECT_EQ(j["frames"][2]["class_b"], "toroidal");
  EXPECT_EQ(j["frames"][2]["loops_b"], 3);
  EXPECT_EQ(j["frames"][2]["flag"], "guarded");
  // without limits: passed is null
  EXPECT_TRUE(nlohmann::json::parse(compare_json(c, {}, {}))["passed"].is_null());
}

}  // namespace
}  // namespace ibrod::analysis
